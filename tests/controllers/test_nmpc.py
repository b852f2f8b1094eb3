"""Nonlinear MPC (controllers.nmpc) in closed loop on the process plant.

References independent of the controller: the constrained pseudo-spectral bound and the
complex-conjugate bound (mbcontrol.analysis.bounds: linear theory on the BEM data, a QP over periodic
forces), and the same NMPC with a linear prediction model on a plant whose buoyancy is not
linear. Sea state: the issue's regular wave H 2.5 m, T 9.6664 s on the 10 m sphere, limits
2 MN and 4 m; ramp one period (the bounds ignore it). The controller period is T / 40 =
0.2417 s and simulate's step T / 200, so the closed loop is exactly T-periodic once settled
(with a period incommensurate with T, e.g. 0.25 s, the power per wave period wanders by +-3 %
as the sampling phase drifts, and short windows mislead). RK4 in the model: 2 substeps
(0.12 s; the fastest radiation pole, -16.7 1/s, needs <= 0.166 s).
Measured runtime of this file: 47-53 s on 2 shared cores (27-31 s of it the nonlinear case).
"""
import tomllib

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis import complex_conjugate_bound, pseudo_spectral_bound, pto_metrics
from mbcontrol.controllers.nmpc import Nmpc
from mbcontrol.plant import build_plant
from mbcontrol.scene import catalogue_dir, parse_scene
from mbcontrol.sim import simulate

T = 9.6664                                   # s
WAVE = waves.regular(2.5, T, ramp_time=T)
DT_S, DT = T / 40, T / 200                   # s: controller period, simulation step
FORCE_MAX, STROKE_MAX = 2e6, 4.0             # N, m
# the highest harmonic inside the hydro data's band (12 rad/s / 0.65 rad/s = 18.5): the
# constrained optimum's force is not a sinusoid (it saturates), and the bound with the
# fundamental alone (696.7 kW) is not a bound for such forces: NMPC beats it by 8.7 %
HARMONICS = 18


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


@pytest.fixture(scope="module")
def model_gap(sphere):
    """Mean power of complex-conjugate control on the plant over the CC bound: the plant's
    fitted radiation model (1 % fit tolerance) against the BEM data the bounds use. The
    matched damper and spring (c = Re Z_i, k = omega^2 (m + A) - K, from the bound's own
    Thevenin impedance, exp(-i omega t)) are the scene PTO's law, so no controller is
    involved. The fit's error shows as a gap either way: measured 0.9983 (the fit judged per
    frequency in 0.3-2.5 rad/s, issue 20; 1.0013 with the global-norm fit before)."""
    cc = complex_conjugate_bound(sphere, WAVE)
    Z, omega = cc.thevenin.impedance[0], float(WAVE.omega[0])
    params = {"pto__damping": Z.real, "pto__stiffness": -omega * Z.imag}
    ds = simulate(sphere, WAVE, duration=12 * T, dt=DT, params=params)
    power = pto_metrics(ds, "pto", start=9 * T, end=12 * T)["mean_power_W"]
    gap = power / cc.power
    assert abs(gap - 1.0) < 0.005
    return gap


def _run(plant, controller, periods, window):
    """Closed loop over `periods` wave periods; PTO metrics over the last `window` ones."""
    ds = simulate(plant, WAVE, duration=periods * T, dt=DT, controller=controller)
    m = pto_metrics(ds, "pto", start=(periods - window) * T, end=periods * T)
    return ds, m, ds.attrs["controller"]


def test_constrained_sphere_reaches_the_pseudo_spectral_bound(sphere, model_gap):
    """Limits 2 MN (hard) and 4 m (soft), horizon one period (40 steps).

    Measured: mean power 756.8 kW over periods 5-7 (settled from period 4), 1.0003 x the
    18-harmonic pseudo-spectral bound (756.6 kW), within the plant's own difference from linear
    theory (model_gap 0.9983, i.e. 0.17 %); max force 1 999 995 N; max stroke 4.0015 m: 1.5 mm over,
    from prediction error (RK4 at 0.12 s in the model, 0.048 s in the plant), not slack
    (largest applied slack 5e-8 m). Solves: 8.4 IPOPT iterations, ~25 ms median.
    """
    nmpc = Nmpc(WAVE, horizon_s=T, dt_s=DT_S, force_max=FORCE_MAX, stroke_max=STROKE_MAX)
    ds, m, d = _run(sphere, nmpc, periods=7, window=3)
    bound = pseudo_spectral_bound(sphere, WAVE, force_max=FORCE_MAX, stroke_max=STROKE_MAX,
                                  harmonics=HARMONICS).mean_power
    single = pseudo_spectral_bound(sphere, WAVE, force_max=FORCE_MAX,
                                   stroke_max=STROKE_MAX).mean_power
    print(f"nmpc {m['mean_power_W']:.6g} W, bound {bound:.6g} W, ratio "
          f"{m['mean_power_W'] / bound:.5f}, stroke {m['max_stroke']:.5f} m, {d}")
    assert d["failures"] == 0 and "full-state" in d["state"]
    # force: hard, and the applied command is clipped to it, so exactly within
    assert np.abs(ds["u__pto"].values).max() <= FORCE_MAX
    assert m["force_violation"] == 0.0
    # stroke: soft; no slack used (exact penalty), the 1.5 mm is prediction error
    assert d["stroke_slack_max"] < 1e-6
    assert m["max_stroke"] <= STROKE_MAX * (1 + 1e-3)
    # power: at the bound, within the plant's measured difference from linear theory (either way:
    # measured 1.0003 x the bound, against a model gap of 0.9983 for complex-conjugate control)
    assert 0.99 * bound <= m["mean_power_W"] <= (1 + abs(model_gap - 1)) * bound
    assert m["mean_power_W"] > 1.05 * single


def test_unconstrained_long_horizon_approaches_complex_conjugate(sphere, model_gap):
    """No limits, horizon two periods (80 steps): the non-causal optimum needs the future.

    Measured: 0.988 of the complex-conjugate bound (1.343 MW) over periods 7-9, against
    0.924 with a horizon of one period (the force's optimum depends on the excitation's
    future over the radiation memory); max stroke 12.7 m, force 7.2 MN.
    """
    cc = complex_conjugate_bound(sphere, WAVE).power
    nmpc = Nmpc(WAVE, horizon_s=2 * T, dt_s=DT_S, force_max=np.inf, stroke_max=np.inf)
    _, m, d = _run(sphere, nmpc, periods=9, window=2)
    print(f"unconstrained: {m['mean_power_W'] / cc:.5f} of CC, {d}")
    assert d["failures"] == 0
    assert 0.98 * cc <= m["mean_power_W"] <= (1 + abs(model_gap - 1)) * cc


def _sphere_scene(hydrostatics: str):
    """The catalogue sphere with its geometry (sphere R = 5 m, centre on the free surface);
    for large-angle buoyancy the mass is exactly half the sphere's displacement, so that rest
    is an equilibrium (the WAMIT volume is 0.03 % smaller)."""
    path = catalogue_dir() / "sphere.toml"
    data = tomllib.loads(path.read_text())
    data["hydro"]["file"] = str(catalogue_dir() / "sphere_hydro.nc")
    data["hydro"]["hydrostatics"] = hydrostatics
    data["body"][0]["geometry"] = {"type": "sphere", "radius": 5.0, "center": [0.0, 0.0, 0.0]}
    if hydrostatics == "large_angle":
        data["body"][0]["mass"] = 1000.0 * 2 / 3 * np.pi * 5.0 ** 3
    return build_plant(parse_scene(data, path))


def test_nonlinear_buoyancy_needs_the_nonlinear_model():
    """Large motions: at 4 m of heave the sphere's waterplane has shrunk by 64 %, and its
    restoring force is 21 % below the linear K z (cap volume pi (R^2 z - z^3 / 3)). The plant
    has large-angle buoyancy; the same NMPC predicts with it, or with the linear-hydrostatics
    twin (a linear MPC with full-state feedback).

    Measured over periods 4-7 (2 MN, 4 m, horizon one period): nonlinear model 823.3 kW,
    periodic, max stroke 4.0011 m; linear model 713 kW (never settles: 680-800 kW a
    period), max stroke 4.05 m, 5 cm over the soft limit its own predictions respect.
    Nonlinear solves cost ~100 ms (12 iterations; the buoyancy's Hessian) against ~30 ms.
    """
    large, linear = _sphere_scene("large_angle"), _sphere_scene("linear")
    runs = {}
    for name, model in (("nonlinear", large), ("linear", linear)):
        nmpc = Nmpc(WAVE, horizon_s=T, dt_s=DT_S, force_max=FORCE_MAX,
                    stroke_max=STROKE_MAX, model=model)
        _, m, d = _run(large, nmpc, periods=7, window=4)
        runs[name] = m
        print(f"{name} model: {m['mean_power_W']:.6g} W, stroke {m['max_stroke']:.5f} m, "
              f"{d['solve_time_median_s']:.3g} s median, {d['iterations_mean']:.3g} it, "
              f"{d['failures']} failures")
    nl, lin = runs["nonlinear"], runs["linear"]
    assert nl["force_violation"] == 0.0 and lin["force_violation"] == 0.0
    # measured ratio 1.15: the linear prediction mistimes the saturated force
    assert nl["mean_power_W"] >= 1.08 * lin["mean_power_W"]
    # the nonlinear model keeps the stroke within 1.1 mm; the linear one misses it by cm
    assert nl["max_stroke"] <= STROKE_MAX * (1 + 1e-3)
    assert lin["max_stroke"] >= STROKE_MAX + 0.02


def test_solver_failures_keep_the_loop_running(sphere):
    """Failures never stop a simulation: with max_iter = 1 every solve fails and the loop
    runs on with zero force (no plan yet), counted in the results' attrs; after a good plan,
    a failed solve (a non-finite state) applies the plan's next commands in turn."""
    nmpc = Nmpc(WAVE, horizon_s=T, dt_s=DT_S, max_iter=1)
    ds = simulate(sphere, WAVE, duration=2 * T, dt=DT, controller=nmpc)
    d = ds.attrs["controller"]
    assert d["solves"] == 81 and d["failures"] == 81           # 2 T / (T / 40) + the last
    assert d["statuses"] == {"Maximum_Iterations_Exceeded": 81}
    assert d["solve_time_median_s"] > 0
    assert np.all(ds["u__pto"].values == 0.0)

    nmpc = Nmpc(WAVE, horizon_s=T, dt_s=DT_S, rate_max=1e6)
    nmpc.reset(sphere)
    x = sphere.x0()
    x[sphere.states.index("heave")] = 1.0                    # 1 m below rest, at rest
    t = 3 * T
    u0 = nmpc(t, None, x)[0]
    plan = nmpc.plan_force.copy()
    assert u0 == pytest.approx(plan[0], rel=1e-12) and nmpc.failures == 0
    bad = x.copy()
    bad[sphere.states.index("heave__vel")] = np.nan
    u1 = nmpc(t + DT_S, None, bad)[0]
    u2 = nmpc(t + 2 * DT_S, None, bad)[0]
    assert (u1, u2) == pytest.approx((plan[1], plan[2]), rel=1e-12)
    assert nmpc.failures == 2 and nmpc.statuses["non-finite state or forecast"] == 2
    # the plan respects the rate limit, so its shifted commands do too (1 MN/s x 0.24 s)
    assert abs(u1 - u0) <= 1e6 * DT_S * (1 + 1e-9) and abs(u2 - u1) <= 1e6 * DT_S * (1 + 1e-9)
    nmpc(t + 3 * DT_S, None, x)
    assert nmpc.solves == 4 and nmpc.failures == 2
