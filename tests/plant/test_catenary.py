"""Quasi-static catenary mooring line (mbcontrol.plant.catenary) against references that do not come
from the code under test: MoorPy's catenary solver, the inextensible catenary in closed form
(parametrised by its vertex, not by the tensions), a numerical integration of the line's
differential equations, finite differences, and CasADi's compiled code against its own
interpreter. Every tolerance comment gives the reference and the value measured."""
from __future__ import annotations

import math
import shutil
import subprocess

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad

from mbcontrol.errors import SceneError
from mbcontrol.plant import CatenaryLine, solve_catenary

# (XF m, ZF m, L m, EA N, w N/m). OC3-Hywind's line (Jonkman 2010) at rest, a compliant line,
# a fully suspended one, one 0.12 % short of taut, one stretched 2 % taut.
GEOMETRIES = {
    "seabed": (848.67, 250.0, 902.2, 384.243e6, 698.094),
    "compliant": (100.0, 40.0, 130.0, 1e7, 200.0),
    "suspended": (420.0, 300.0, 520.0, 1e9, 700.0),
    "nearly_taut": (400.0, 299.0, 500.0, 1e9, 700.0),
    "taut": (600.0, 200.0, 620.0, 5e8, 500.0),
}
STATUS = {"seabed": "seabed contact", "compliant": "seabed contact", "suspended": "suspended",
          "nearly_taut": "suspended", "taut": "taut"}


def oc3_line(**kw) -> CatenaryLine:
    return CatenaryLine("oc3", anchor=(853.87, 0.0, 320.0), fairlead=(5.2, 0.0, 70.0),
                        length=902.2, EA=384.243e6, weight=698.094, **kw)


@pytest.fixture(scope="module")
def oc3():
    line = oc3_line(excursion=20.0)
    return line, line.force_table()


# ------------------------------------------------------------------------- exact solver
@pytest.mark.parametrize("case", GEOMETRIES)
@pytest.mark.parametrize("friction", [0.0, 0.7])
def test_against_moorpy(case, friction, monkeypatch):
    monkeypatch.setenv("PYTHONBREAKPOINT", "0")       # MoorPy calls breakpoint() on odd input
    from moorpy.Catenary import catenary
    XF, ZF, L, EA, w = GEOMETRIES[case]
    ours = solve_catenary(XF, ZF, L, EA, w, friction=friction)
    anchor_H, anchor_V, _, _, info = catenary(XF, ZF, L, EA, w, CB=friction, Tol=1e-12)
    assert ours.status == STATUS[case]
    # MoorPy: measured relative differences <= 8.3e-11 (suspended), <= 5e-14 otherwise
    assert ours.H == pytest.approx(info["HF"], rel=1e-9)
    assert ours.V == pytest.approx(info["VF"], rel=1e-9)
    assert ours.H_anchor == pytest.approx(anchor_H, rel=1e-9, abs=1e-9 * ours.H)
    assert ours.V_anchor == pytest.approx(anchor_V, rel=1e-9, abs=1e-9 * ours.V)
    # lying length: measured <= 8e-13 m
    assert ours.lying_length == pytest.approx(info["LBot"], abs=1e-9)


@pytest.mark.parametrize("method", ["newton", "bracket"])
@pytest.mark.parametrize("anchor_x, lying", [(50.0, 0.0), (0.0, 120.0)])
def test_inextensible_closed_form(anchor_x, lying, method):
    """Catenary z = a cosh(x/a) through x = anchor_x (or touching down at the vertex after
    `lying` m on the seabed) to x = 400 m: tensions H = w a, V = w a sinh(x/a)."""
    w, a, x_f = 500.0, 300.0, 400.0
    hanging = a * (math.sinh(x_f / a) - math.sinh(anchor_x / a))
    XF, ZF = x_f - anchor_x + lying, a * (math.cosh(x_f / a) - math.cosh(anchor_x / a))
    sol = solve_catenary(XF, ZF, hanging + lying, 1e18, w, method=method)   # EA -> infinity
    assert sol.status == ("suspended" if lying == 0.0 else "seabed contact")
    # closed form: measured relative differences <= 4e-12 (H), 2e-12 (V, V_anchor)
    assert sol.H == pytest.approx(w * a, rel=1e-10)
    assert sol.V == pytest.approx(w * a * math.sinh(x_f / a), rel=1e-10)
    assert sol.V_anchor == pytest.approx(w * a * math.sinh(anchor_x / a), abs=1e-10 * sol.V)
    assert sol.lying_length == pytest.approx(lying, abs=1e-8)   # measured 5e-10 m


@pytest.mark.parametrize("case", GEOMETRIES)
def test_shape_integrates_to_the_fairlead(case):
    """Integrate dx/ds = H/T + H/EA, dz/ds = V(s)/T + V(s)/EA along the hanging part
    (V(s) = V_A + w s), starting where the stretched lying part ends: reaches (XF, ZF)."""
    XF, ZF, L, EA, w = GEOMETRIES[case]
    sol = solve_catenary(XF, ZF, L, EA, w)
    H, V_A, lying = sol.H, sol.V_anchor, sol.lying_length

    def along(s, vertical):
        V = V_A + w * s
        return (V if vertical else H) * (1.0 / math.hypot(H, V) + 1.0 / EA)
    hanging = L - lying
    x = lying * (1.0 + H / EA) + quad(along, 0.0, hanging, args=(False,), epsabs=0,
                                      epsrel=1e-13)[0]
    z = quad(along, 0.0, hanging, args=(True,), epsabs=0, epsrel=1e-13)[0]
    # quadrature: measured position errors <= 1.9e-12 of L
    assert x == pytest.approx(XF, abs=1e-10 * L)
    assert z == pytest.approx(ZF, abs=1e-10 * L)
    # equilibrium of the hanging part: V - V_A is its weight (measured 2.2e-16 relative);
    # H is the same at both ends
    assert sol.V - sol.V_anchor == pytest.approx(w * (L - lying), rel=1e-12)
    assert sol.H_anchor == sol.H


def test_statuses_and_limits():
    w, EA, L = 200.0, 1e7, 130.0
    # slack: hangs vertically over L_h (ZF = L_h + w L_h^2 / (2 EA)), the rest lies slack
    slack = solve_catenary(30.0, 40.0, L, EA, w)
    L_h = (math.sqrt(1.0 + 2.0 * w * 40.0 / EA) - 1.0) * EA / w
    assert (slack.status, slack.H, slack.iterations) == ("slack", 0.0, 0)
    assert slack.V == pytest.approx(w * L_h, rel=1e-11)             # measured 1.4e-13
    assert slack.lying_length == pytest.approx(L - L_h, rel=1e-12)
    # just past the slack reach: tiny H, V continuous with the slack value
    past = solve_catenary(L - L_h + 1e-4, 40.0, L, EA, w)
    assert past.status == "seabed contact" and 0.0 < past.H < 1e-5 * past.V   # 1.6e-7
    assert past.V == pytest.approx(w * L_h, rel=1e-5)               # measured 1.6e-7
    # all on the seabed (ZF = 0): slack up to L, then stretched, H = EA (XF/L - 1)
    assert solve_catenary(120.0, 0.0, L, EA, w).status == "slack"
    flat = solve_catenary(L * (1.0 + 1e-6), 0.0, L, EA, w)
    assert (flat.status, flat.V) == ("taut", 0.0)
    assert flat.H == pytest.approx(EA * 1e-6, rel=1e-9)             # measured 1.2e-10
    # vertical line clear of the seabed: V = w L/2 + EA (ZF - L)/L (weight + stretch)
    vertical = solve_catenary(0.0, 131.0, L, EA, w)
    assert vertical.status == "taut" and vertical.H == 0.0
    assert vertical.V == pytest.approx(w * L / 2.0 + EA / L, rel=1e-12)   # measured 0
    # ... and the general solver, a micrometre off vertical: measured 1.9e-14 relative
    assert solve_catenary(1e-6, 131.0, L, EA, w).V == pytest.approx(vertical.V, rel=1e-10)
    # taut: chord 2.01 % longer than L, "taut-out" past the strain limit
    taut = solve_catenary(*GEOMETRIES["taut"])
    assert taut.status == "taut" and taut.chord_strain == pytest.approx(0.0201, abs=1e-4)
    assert taut.strain == pytest.approx(taut.tension / 5e8)
    assert solve_catenary(*GEOMETRIES["taut"], strain_limit=0.02).status == "taut-out"


@pytest.mark.parametrize("case", GEOMETRIES)
def test_bracketing_fallback_agrees(case):
    newton = solve_catenary(*GEOMETRIES[case])
    bracket = solve_catenary(*GEOMETRIES[case], method="bracket")
    # measured relative differences <= 8.3e-11 (Newton stops at 1e-11 L in position)
    assert bracket.H == pytest.approx(newton.H, rel=1e-8)
    assert bracket.V == pytest.approx(newton.V, rel=1e-8)
    assert bracket.iterations > newton.iterations


@pytest.mark.parametrize("r", [(5.2, 0.0, 70.0), (-10.0, 12.0, 80.0), (15.0, -8.0, 55.0)])
def test_stiffness_matches_finite_differences(r):
    line = oc3_line()
    r = np.array(r)
    K = line.stiffness(r)
    h = 1e-2
    K_fd = np.column_stack([-(line.force(r + h * e)[0] - line.force(r - h * e)[0]) / (2 * h)
                            for e in np.eye(3)])
    # central differences: measured max difference 3.5e-7 of max |K|
    assert np.max(np.abs(K - K_fd)) < 1e-5 * np.max(np.abs(K))
    # conservative, so symmetric: measured asymmetry <= 7e-17 of max |K|
    assert np.allclose(K, K.T, rtol=0, atol=1e-12 * np.max(np.abs(K)))
    # at rest (fairlead on the x axis) the sideways stiffness is the pendulum's H / XF
    if r[1] == 0.0:
        sol = line.solve(r)
        assert K[1, 1] == pytest.approx(sol.H / line.offsets(r)[0], rel=1e-12)


# ------------------------------------------------------------------------- CasADi Function
def test_force_function_accuracy_and_direction(oc3):
    line, table = oc3
    assert (table.n_grid, table.newton_steps) == (21, 3)
    assert table.error < 1e-8                       # measured 1.1e-9 at 4 points per cell
    # 300 random positions in the envelope: measured max 3.8e-10 of the rest tension
    assert line.table_error(table.function) < 1e-8
    F, T = (np.array(v).ravel() for v in table.function(line.fairlead))
    exact, tension = line.force()
    assert F[0] > 0.0 and F[2] > 0.0                # toward the anchor (+x) and down (+z)
    assert np.allclose(F, exact, rtol=1e-9) and T[0] == pytest.approx(tension, rel=1e-9)


def test_force_function_jacobian_is_the_stiffness(oc3):
    line, table = oc3
    r = ca.SX.sym("r", 3)
    F, T = table.function(r)                         # SX in, SX out: a call node to the table
    assert isinstance(F, ca.SX) and isinstance(T, ca.SX)
    jac = ca.Function("jacobian_F", [r], [ca.jacobian(F, r)])
    rng = np.random.default_rng(1)
    for _ in range(5):
        p = np.array(line.fairlead) + rng.uniform(-14.0, 14.0, 3)
        K = line.stiffness(p)
        # implicit differentiation of the exact solve: measured max difference 5.8e-11 of |K|
        assert np.max(np.abs(-np.array(jac(p)) - K)) < 1e-8 * np.max(np.abs(K))


def test_slack_zone_is_exact():
    line = CatenaryLine("slack", anchor=(90.0, 0.0, 50.0), fairlead=(0.0, 0.0, 5.0),
                        length=140.0, EA=5e8, weight=1000.0, excursion=15.0)
    fun = line.force_function()
    p = np.array([5.0, 3.0, 10.0])                  # closer to the anchor: deeper in slack
    assert line.solve(p).status == "slack"
    F = np.array(fun(p)[0]).ravel()
    assert F[0] == 0.0 and F[1] == 0.0
    assert F[2] == pytest.approx(line.force(p)[0][2], rel=1e-14)    # w L_h, same formula


def test_vertical_tether():
    """Fairlead right above the anchor (XF = 0 at rest): the smoothed direction stays finite."""
    line = CatenaryLine("tether", anchor=(0.0, 0.0, 50.0), fairlead=(0.0, 0.0, 5.0),
                        length=44.5, EA=2e7, weight=300.0, excursion=0.3)
    assert line.solve().status == "taut"
    table = line.force_table()
    assert table.error < 1e-8                         # measured 8.3e-10
    F = np.array(table.function(line.fairlead)[0]).ravel()
    assert np.all(np.isfinite(F)) and abs(F[0]) < 1e-6 * F[2]
    r = ca.SX.sym("r", 3)
    jac = ca.Function("jacobian_F", [r], [ca.jacobian(table.function(r)[0], r)])
    K = line.stiffness()
    # lateral stiffness of a vertical line (H/XF -> dH/dXF): measured 1e-12 relative
    assert np.allclose(-np.array(jac(line.fairlead)), K, rtol=1e-9, atol=1e-9 * K[2, 2])


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
def test_codegen_compiles_and_matches(oc3, tmp_path):
    line, table = oc3
    r = ca.SX.sym("r", 3)
    F, T = table.function(r)
    # embed in a larger SX graph, as the plant does: two lines and the Jacobian
    F2, _ = table.function(r + ca.DM([1.0, 2.0, 0.5]))
    plant = ca.Function("mooring_plant", [r], [F + F2, T, ca.jacobian(F, r)])
    generator = ca.CodeGenerator("mooring_plant.c", {"with_header": False})
    generator.add(plant)
    source = tmp_path / "mooring_plant.c"
    source.write_text(generator.dump())
    library = tmp_path / "mooring_plant.so"
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", str(source), "-o", str(library), "-lm"],
                   check=True, capture_output=True)
    compiled = ca.external("mooring_plant", str(library))
    rng = np.random.default_rng(2)
    for _ in range(5):
        p = np.array(line.fairlead) + rng.uniform(-10.0, 10.0, 3)
        for a, b in zip(compiled(p), plant(p)):
            # C against CasADi's interpreter: measured max relative difference 0
            assert np.allclose(np.array(a), np.array(b), rtol=1e-12, atol=0)


def test_force_table_warns_when_it_cannot_meet_the_tolerance():
    line = oc3_line(excursion=20.0, n_grid=11, newton_steps=0)
    with pytest.warns(RuntimeWarning, match=r"mooring 'oc3': force table error .* \(11 x 11 grid"):
        table = line.force_table(tolerance=1e-12, max_grid=11, max_steps=1)
    assert table.newton_steps == 1 and table.error > 1e-12   # the better of 0 and 1 steps


# ------------------------------------------------------------------------- bad input
def test_bad_lines_raise_scene_errors():
    ok = {"anchor": (400.0, 0.0, 50.0), "fairlead": (0.0, 0.0, 5.0), "length": 500.0,
          "EA": 1e9, "weight": 700.0}
    far = (math.sqrt(612.0**2 - 45.0**2), 0.0, 50.0)        # 612 m from the fairlead
    cases = [
        ({"length": -3.0}, r"mooring 'm1': length is -3 m; expected a positive number"),
        ({"EA": 0.0}, r"mooring 'm1': EA is 0 N; expected a positive number"),
        ({"weight": -1.0}, r"mooring 'm1': weight is -1 N/m; expected a positive number"),
        ({"friction": -0.1}, r"friction is -0.1; expected a positive number or 0"),
        ({"EA": float("nan")}, r"mooring 'm1': EA is nan; expected a finite number"),
        ({"anchor": (1.0, 2.0)}, r"anchor is \(1.0, 2.0\); expected 3 finite numbers"),
        ({"anchor": (0.0, 0.0, 2.0)},
         r"anchor \(0, 0, 2\) is not below the fairlead \(0, 0, 5\)"),
        ({"anchor": far}, (r"mooring 'm1': anchor \(610.343, 0, 50\) is 612 m from the "
                           r"fairlead, beyond the line's reach 500 m x \(1 \+ 0.1 strain "
                           r"limit\)")),
        ({"excursion": 60.0}, (r"excursion is 60.0 m; expected a number between 0 and the "
                               r"fairlead height above the anchor 45 m")),
        ({"n_grid": 3}, r"n_grid is 3; expected an integer >= 6"),
    ]
    for change, message in cases:
        with pytest.raises(SceneError, match=message):
            CatenaryLine("m1", **{**ok, **change})


def test_bad_solver_input_raises_scene_errors():
    with pytest.raises(SceneError, match=r"mooring 'x': XF is -1; expected a finite number >= 0"):
        solve_catenary(-1.0, 40.0, 130.0, 1e7, 200.0, name="x")
    with pytest.raises(SceneError, match=r"mooring 'catenary': weight is 0; expected a finite "
                                         r"number > 0"):
        solve_catenary(100.0, 40.0, 130.0, 1e7, 0.0)
    with pytest.raises(SceneError, match=r"ZF is -5; expected a finite number >= 0 \(fairlead "
                                         r"not below the anchor\)"):
        solve_catenary(100.0, -5.0, 130.0, 1e7, 200.0)
