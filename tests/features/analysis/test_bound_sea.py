"""The constrained bound in a sea on the full periodic grid (issue 19 item 4), against
references that do not come from the code under test: the complex-conjugate optimum written
from the BEM arrays by hand, a saturating reactive controller simulated in the time domain
over a periodic steady state, Clarabel (cvxpy) on the same QP, and more freedom never
lowering an optimum. A 120 s sea (Tp 6 s) on the sphere keeps every QP under a second.
"""
import math

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis.bounds import PseudoSpectralProblem
from mbcontrol.analysis.box_qp import solve_box_qp
from mbcontrol.analysis.constrained import constrained_figure
from mbcontrol.plant import build_plant

SEA = waves.irregular(2.5, 6.0, seed=1, duration=60.0)        # 120 s repeat, 75 components
FORCE_MAX, STROKE_MAX = 5e5, 1.0           # N, m: tight, so that the force saturates


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


def _heave(da):
    return da.sel(radiating_dof="sphere__Heave", influenced_dof="sphere__Heave").values


def test_wide_grid_without_limits_is_the_complex_conjugate_sum(sphere):
    """The extra frequencies carry no wave, so with limits that never bind the optimum is
    sum a^2 |F_e|^2 / (8 B), the heave impedance from the BEM arrays by hand."""
    data = sphere.hydro.data
    w = data.omega.values
    B = _heave(data.radiation_damping)
    F = data.excitation_force.sel(influenced_dof="sphere__Heave").isel(wave_direction=0).values
    F_e = np.interp(SEA.omega, w, F.real) + 1j * np.interp(SEA.omega, w, F.imag)
    reference = np.sum(SEA.amplitude**2 * np.abs(F_e)**2 / (8 * np.interp(SEA.omega, w, B)))
    problem = PseudoSpectralProblem(sphere, SEA, omega_max=float(w[-1]))
    assert problem.omega.size > 3 * SEA.omega.size            # measured 229 against 75
    r = problem.solve(1e12, 1e6, "IPM")
    assert r.status == "optimal"
    # measured 1.3e-10 (the linear interpolation of the data is the same on both sides)
    assert r.mean_power == pytest.approx(reference, rel=1e-6)
    assert r.certified_power == pytest.approx(reference, rel=1e-6)
    assert r.certified_power >= r.mean_power * (1 - 1e-12)
    # the force puts nothing where the sea has no wave: measured 1e-7 of the largest
    wave_bins = np.isin(np.rint(problem.omega / SEA.d_omega), np.rint(SEA.omega / SEA.d_omega))
    F_k = np.abs(r.force_coefficients)
    assert F_k[~wave_bins].max() < 1e-5 * F_k.max()


def test_interior_point_matches_clarabel(sphere):
    """The dense interior point (solver "IPM") and Clarabel on the same wide-grid QP."""
    problem = PseudoSpectralProblem(sphere, SEA, omega_max=4.0)
    ipm = problem.solve(FORCE_MAX, STROKE_MAX, "IPM")
    clarabel = problem.solve(FORCE_MAX, STROKE_MAX)
    assert ipm.status == "optimal" and clarabel.status == "optimal"
    # measured 1e-9 apart; the certificate is above both to round-off
    assert ipm.mean_power == pytest.approx(clarabel.mean_power, rel=1e-6)
    assert ipm.certified_power >= max(ipm.mean_power, clarabel.mean_power) * (1 - 1e-8)
    # and on a small random QP with a flat direction (h = 0 nowhere but tiny)
    rng = np.random.default_rng(1)
    h = rng.uniform(0, 2, 40) + 1e-9
    q, C, d = rng.normal(size=40) * 3, rng.normal(size=(90, 40)), 0.3 * rng.normal(size=90)
    r = solve_box_qp(h, q, C, d, -np.ones(90), np.ones(90))
    assert r.status == "optimal"
    assert r.dual_bound <= r.objective <= r.dual_bound + 1e-8 * abs(r.objective)
    assert np.all(np.abs(C @ r.z + d) <= 1 + 1e-8)


def test_bound_monotone_in_the_grid(sphere):
    """Adding frequencies to the force's grid can only raise the optimum."""
    top = float(sphere.hydro.omega[-1])
    powers = [PseudoSpectralProblem(sphere, SEA, omega_max=w).solve(
        FORCE_MAX, STROKE_MAX, "IPM").certified_power for w in (None, 3.0, 6.0, top)]
    assert np.all(np.diff(powers) >= -1e-8 * powers[-1])
    assert powers[-1] > powers[0] * 1.001          # the gaps and harmonics are worth something


def test_saturating_controller_does_not_beat_the_bound(sphere):
    """A reactive law saturated at FORCE_MAX, simulated on the plant over two repeat periods:
    its mean over the second (a periodic steady state, as the bound's) stays below the wide
    grid's bound with the force limit alone (the law has no stroke limit)."""
    from mbcontrol.analysis.metrics import step_power
    from mbcontrol.controllers import make
    from mbcontrol.controllers.reactive import reactive_tuning
    damping, stiffness, _ = reactive_tuning(sphere, SEA)
    period = 2 * np.pi / SEA.d_omega
    ds = __import__("mbcontrol.sim", fromlist=["simulate"]).simulate(
        sphere, SEA, duration=2 * period, dt=0.01,
        controller=make("reactive", damping=damping, stiffness=stiffness, force_max=FORCE_MAX))
    t, P = step_power(ds, "pto")
    second = t >= period - 1e-9
    simulated = float(np.mean(P[second]))
    saturated = np.mean(np.abs(ds["pto__force"].values) >= FORCE_MAX * (1 - 1e-9))
    assert saturated > 0.1                     # a saturating force indeed: measured 14 %
    wide = PseudoSpectralProblem(sphere, SEA, omega_max=float(sphere.hydro.omega[-1]))
    bound = wide.solve(FORCE_MAX, np.inf, "IPM").certified_power
    assert simulated <= bound * (1 + 1e-3)


def test_design_keys_say_what_the_figure_is(sphere):
    """constrained_kind: a bound for a regular wave (whole periods on both sides), a reference
    in a sea (design scores a window, the bound a whole repeat period)."""
    regular = waves.regular(2.5, 9.6664)
    out = constrained_figure(sphere, regular, "pto", 2e6, 4.0, harmonics=18)
    assert out["constrained_kind"] == "bound" and out["constrained_W"] > 0
    capped = constrained_figure(sphere, regular, "pto", 2e6, 4.0, harmonics=5)
    assert capped["constrained_kind"] == "reference"
    sea = constrained_figure(sphere, SEA, "pto", FORCE_MAX, STROKE_MAX)
    assert sea["constrained_kind"] == "reference"
    assert sea["window_s"] == [pytest.approx(SEA.ramp_time), pytest.approx(120.0)]
    assert math.isfinite(sea["window_share"]) and sea["constrained_components"] > 200
