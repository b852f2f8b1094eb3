"""PTO limits: force saturation in every linear controller and constrained tuning (sphere).

The 10 m heaving hemisphere (`sphere`, force_max 2 MN in its scene) in the regular wave H 2.5 m,
T 9.6664 s, where complex-conjugate control asks for a 6.5 MN force amplitude and an 11.4 m
stroke: saturation is certain to act. References independent of the code under test: the
clip of the linear law written out here, the same run through simulate's compiled law and
through its Python loop (round-off apart), the stroke-limited optimum of a regular wave
derived below, a Monte Carlo of random-phase records for the sea-state statistics, and
simulation of each tuning. Measured values in the comments are from one run on this machine.
"""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis import electrical_power, pto_metrics
from mbcontrol.controllers import make
from mbcontrol.controllers.impedance import fd_statistics, intrinsic_impedance
from mbcontrol.controllers.latching import Declutching, Latching, steady_mean_power
from mbcontrol.controllers.limits import force_limits
from mbcontrol.controllers.passive import Passive, optimal_damping
from mbcontrol.controllers.reactive import Reactive, reactive_tuning
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

T = 9.6664            # s
LIMIT = 2.0e6         # N, the sphere scene's force_max
FULL_SCALE = (1e3, 1e7)  # N s/m: optimal_damping's default bounds are for tank models


@pytest.fixture(scope="module")
def plant():
    return build_plant("sphere")


@pytest.fixture(scope="module")
def wave():
    return waves.regular(2.5, T)


@pytest.fixture(scope="module")
def matched(plant, wave):
    """Complex-conjugate (damping, stiffness): 49.2 kN s/m, -573 kN/m."""
    return reactive_tuning(plant, wave)[:2]


class PythonPath:
    """The same controller without its CasADi law: simulate runs it in its Python loop."""

    def __init__(self, inner):
        self.inner, self.name, self.period = inner, inner.name, inner.period

    def reset(self, plant):
        self.inner.reset(plant)

    def __call__(self, t, y):
        return self.inner(t, y)

    def casadi_law(self, plant):
        return None

    def describe(self):
        return self.inner.describe()


def run(plant, wave, controller, periods=6, dt=0.01):
    return simulate(plant, wave, duration=periods * wave.period, dt=dt, controller=controller)


def test_reactive_saturates_alike_compiled_and_in_python(plant, wave, matched):
    c, k = matched
    compiled = run(plant, wave, Reactive(c, k))              # default: the scene's 2 MN
    python = run(plant, wave, PythonPath(Reactive(c, k)))
    for ds in (compiled, python):
        F, x, v = (ds[f"pto__{s}"].values for s in ("force", "position", "velocity"))
        # the law reads the state at each step's start: F is the clipped law at every sample
        np.testing.assert_allclose(F, np.clip(-(c * v + k * x), -LIMIT, LIMIT), rtol=1e-12,
                                   atol=1e-6)
        assert np.abs(F).max() == pytest.approx(LIMIT, rel=1e-12)
        # measured: saturated at 43 % of the samples after the first period
        assert np.mean(np.abs(F[ds.time.values > T]) >= LIMIT * (1 - 1e-12)) > 0.3
    # one computation in two places: agree to round-off (the position is ~2 m)
    np.testing.assert_allclose(python.pto__position.values, compiled.pto__position.values,
                               atol=1e-9)
    assert compiled.attrs["controller"] == python.attrs["controller"]
    assert list(compiled.attrs["controller"]["force_max"]) == [2000000.0]
    # without the limit the same law reaches 5.4 MN in 3 periods (6.5 MN in steady state)
    free = run(plant, wave, Reactive(c, k, force_max=np.inf), periods=3)
    assert np.abs(free.pto__force.values).max() > 2 * LIMIT


def test_passive_latching_declutching_saturate(plant, wave):
    limit = 2.0e5                                         # N, below all three's demand
    damper = run(plant, wave, Passive(883e3, force_max=limit), periods=3)
    F, v = damper.pto__force.values, damper.pto__velocity.values
    np.testing.assert_allclose(F, np.clip(-883e3 * v, -limit, limit), rtol=1e-12, atol=1e-6)
    assert np.abs(F).max() == pytest.approx(limit, rel=1e-12)   # demand 500 kN amplitude
    for controller in (Latching(89e3, 2.6, force_max=limit),
                       Declutching(1.7e6, 1.0, force_max={"pto": limit})):
        ds = run(plant, wave, controller, periods=4)
        F = np.abs(ds.pto__force.values)
        assert F.max() <= limit * (1 + 1e-12)
        # reached: the brake / the 1.7 MN s/m damper want more (measured 46 %, 56 % of samples)
        assert np.mean(F >= limit * (1 - 1e-12)) > 0.01
        assert controller.describe()["force_max"] == [limit]


def test_force_max_forms(plant, wave, matched):
    assert force_limits(plant).tolist() == [LIMIT]                     # scene's
    assert force_limits(plant, 5.0).tolist() == [5.0]
    assert force_limits(plant, {"pto": 7.0}).tolist() == [7.0]
    assert force_limits(plant, np.inf).tolist() == [np.inf]
    with pytest.raises(KeyError, match="unknown PTO"):
        force_limits(plant, {"nope": 1.0})
    with pytest.raises(ValueError, match="> 0"):
        force_limits(plant, 0.0)
    c, k = matched
    y = np.zeros(len(plant.outputs))
    y[plant.outputs.index("pto__position")] = -100.0      # law demands -(k x) = -57 MN
    for limit, expected in ((None, -LIMIT), (np.inf, k * 100.0), (1e3, -1e3)):
        controller = make("reactive", damping=c, stiffness=k, force_max=limit)
        controller.reset(plant)
        law = controller.casadi_law(plant)
        assert float(law(y)) == pytest.approx(expected, rel=1e-12)
        assert controller(0.0, y)[0] == pytest.approx(expected, rel=1e-12)
        assert controller.describe()["force_max"] == [None if limit == np.inf else
                                                      (limit or LIMIT)]


def test_stroke_limited_regular_wave_is_the_analytic_optimum(plant, wave):
    """With only a stroke limit s, P = c |F a|^2 / 2 / (R^2 + X^2) (R = Re Z_i + c, X = Im Z_i
    - k / omega) is largest on the limit R^2 + X^2 = D^2, D = |F a| / (omega s), at the largest
    c: X = 0 (the reactance still cancelled) and c = D - Re Z_i, P = c (omega s)^2 / 2."""
    s = 1.0                                                # m, vs 11.4 m unconstrained
    w, a = wave.omega[0], wave.amplitude[0]
    Z, F = intrinsic_impedance(plant, wave.omega)
    D = abs(F[0] * a) / (w * s)
    c, k, power = reactive_tuning(plant, wave, stroke_max=s)
    # measured 1.0691 MN s/m, -573.35 kN/m, 225.8 kW
    assert c == pytest.approx(D - Z[0].real, rel=1e-4)
    assert k == pytest.approx(w * Z[0].imag, rel=1e-4)
    assert power == pytest.approx(0.5 * (D - Z[0].real) * (w * s) ** 2, rel=1e-6)
    # verified on the nonlinear plant, unsaturated (1 MN peak < 2 MN): measured amplitude
    # 0.9975 m (the radiation fit), power 225.3 kW
    ds = run(plant, wave, Reactive(c, k), periods=15)
    amplitude = 0.5 * np.ptp(ds.pto__position.values[ds.time.values > 10 * T])
    assert s * 0.99 < amplitude <= s
    assert steady_mean_power(ds, "pto", T, 10) == pytest.approx(power, rel=0.01)


def test_force_limited_tunings_hold_without_saturation(plant, wave):
    """The tuning, not the clip, keeps the force: simulated with force_max = inf."""
    limit = 1.0e6
    c, k, power = reactive_tuning(plant, wave, force_max=limit)
    ds = run(plant, wave, Reactive(c, k, force_max=np.inf), periods=15)
    m = pto_metrics(ds, "pto", 10 * T)
    # measured: 995.6 kN (predicted 1 MN, on the limit), 378.4 kW (predicted 379.9 kW)
    assert 0.99 * limit < m["max_force"] <= limit
    assert steady_mean_power(ds, "pto", T, 10) == pytest.approx(power, rel=0.01)
    # a damper whose optimum (883 kN s/m) needs a 500 kN amplitude, held to 300 kN
    c_p, p_p = optimal_damping(plant, wave, bounds=FULL_SCALE, force_max=3e5)
    c_free, p_free = optimal_damping(plant, wave, bounds=FULL_SCALE)
    assert c_p < c_free and p_p < p_free
    ds = run(plant, wave, Passive(c_p, force_max=np.inf), periods=15)
    assert 0.99 * 3e5 < pto_metrics(ds, "pto", 10 * T)["max_force"] <= 3e5


def test_no_limit_gives_the_unconstrained_optimum(plant, wave, matched):
    # the constrained search with infinite limits lands on complex-conjugate control
    c, k, _ = reactive_tuning(plant, wave, force_max=np.inf, stroke_max=np.inf)
    assert c == pytest.approx(matched[0], rel=1e-3) and k == pytest.approx(matched[1], rel=1e-3)
    sea = waves.irregular(2.5, 8.0, seed=1)
    free = reactive_tuning(plant, sea)
    inf = reactive_tuning(plant, sea, force_max=np.inf, stroke_max=np.inf)
    # measured 254,467.486 vs 254,467.486 W, damping 88,870 vs 88,873 N s/m
    assert inf[2] >= free[2] * (1 - 1e-6)
    _, p_p = optimal_damping(plant, sea, bounds=FULL_SCALE, force_max=np.inf)
    assert p_p == pytest.approx(optimal_damping(plant, sea, bounds=FULL_SCALE)[1], rel=1e-6)


def test_sea_state_statistics_match_random_phase_records(plant):
    """fd_statistics against 400 records of the same sea with random phases (600 s each)."""
    sea = waves.irregular(2.5, 8.0, seed=1, duration=600.0)
    Z, F = intrinsic_impedance(plant, sea.omega)
    c, k, _ = reactive_tuning(plant, sea, efficiency=0.7)     # measured 325 kN s/m, -424 kN/m
    stats = fd_statistics(Z, F, sea, c, k, efficiency=0.7, exceedance=0.1)
    V = F * sea.amplitude / (Z + c - 1j * k / sea.omega)
    X = V / (1j * sea.omega)
    U = -(c * V + k * X)
    n, index = 12000, np.rint(sea.omega / sea.d_omega).astype(int)   # 0.05 s samples
    phases = np.exp(1j * np.random.default_rng(0).uniform(0, 2 * np.pi, (400, index.size)))

    def record(amplitudes):     # Re sum A_j exp(i (omega_j t + phi_j)) over one repeat period
        spectrum = np.zeros((400, n), complex)
        spectrum[:, index] = amplitudes * phases
        return n * np.fft.ifft(spectrum, axis=1).real
    x, v, u = record(X), record(V), record(U)
    p = -u * v
    # over a whole repeat period the mean power is exact for any phases
    np.testing.assert_allclose(p.mean(axis=1), stats["power_W"], rtol=1e-9)
    # the Gaussian E|P| split: measured 89,469 W vs 89,463 +- 3 W (Monte Carlo)
    assert float(electrical_power(p, 0.7).mean()) == pytest.approx(float(stats["electrical_W"]),
                                                                   rel=1e-3)
    # Rice's level bounds the chance that a record's peak exceeds it (crossings cluster):
    # measured 2.75 % of records for the stroke, 2.25 % for the force, at exceedance 10 %
    for series, peak in ((x, stats["stroke_peak"]), (u, stats["force_peak"])):
        share = np.mean(np.abs(series).max(axis=1) > peak)
        assert 0.005 < share <= 0.1


def test_describe_reports_saturation(plant):
    for controller in (Passive(1.0), Reactive(1.0, -1.0), Latching(1.0, 1.0),
                       Declutching(1.0, 1.0)):
        assert controller.describe()["force_max"] is None       # before reset: unknown
        controller.reset(plant)
        described = controller.describe()
        assert described["force_max"] == [LIMIT] and "force_max" in described["saturation"]
