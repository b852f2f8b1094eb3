"""The annual-energy budget's added terms, each against a hand computation or a Monte-Carlo:
scene parameters (mass, drag, efficiency), linear against nonlinear, the resource from a buoy
record (monthly blocks against a synthetic resource of known variance), shares."""
import dataclasses
import math
import warnings

import numpy as np
import pytest
import xarray as xr

from mbcontrol.analysis import law_responses
from mbcontrol.analysis.metrics import electrical_power
from mbcontrol.errors import SceneError
from mbcontrol.plant import build_plant
from mbcontrol.scene import Drag, Uncertain, load_scene, scene_uncertainty
from mbcontrol.studies.sweep import budget as bud
from mbcontrol.studies.sweep.resource import Resource, block_spread
from mbcontrol.studies.sweep.scene_parameters import (BORGMAN, _rms_velocity,
                                                      efficiency_gradients, moved_plant,
                                                      relative_gradients)
from mbcontrol.studies.sweep.spectral import expected_power, sea_components
from mbcontrol.studies.sweep.terms import nonlinear_component, nonlinear_difference
from mbcontrol.waves import SeaState

H = 8766 / 1e6


@pytest.fixture(scope="module")
def sphere():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = build_plant(load_scene("sphere"))
    wave, _ = sea_components(plant, SeaState(2.0, 9.0, weight=1.0), 300.0)
    return plant, wave, {"pto": (2.0e5, 0.0)}


def test_mass_term_matches_a_monte_carlo_of_linear_theory(sphere):
    """u from the sensitivity (central differences) against the spread of linear theory's
    power over 300 sampled masses (2 % normal): equal within 3 standard errors of the
    Monte-Carlo's std (1 / sqrt(2 N))."""
    plant, wave, gains = sphere
    m0 = plant.scene.bodies[0].mass
    item = Uncertain("sphere.mass", "mass", "sphere", None, m0, 0.02 * m0, "normal")
    power = expected_power(plant, wave, gains)
    g = relative_gradients(plant, [wave], [gains], [item], params=None, skip=[False])
    u = bud.parameters([1.0], g * power, [[item.std ** 2]], ["sphere.mass"], "")["std_MWh"]
    rng = np.random.default_rng(1)
    n = 300
    samples = [H * expected_power(moved_plant(plant, item, m), wave, gains)
               for m in rng.normal(m0, item.std, n)]
    mc = float(np.std(samples, ddof=1))
    assert u == pytest.approx(mc, rel=3 / math.sqrt(2 * n))
    assert u > 0.001 * H * power        # a 2 % mass moves the power: the test can fail


def test_quadratic_drag_uses_the_rms_velocity_of_linear_theory(sphere):
    """Borgman: d ln P / d c = sqrt(8 / pi) sigma_v d ln P / d b; sigma_v from the body's
    heave output equals the PTO's velocity (law_responses, another path) on the sphere."""
    plant, wave, gains = sphere
    scene = dataclasses.replace(plant.scene, drags=(Drag("d", "sphere", {"Heave": 1e4}, {}),))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dragged = build_plant(scene, plant.hydro, radiation=False)
    quad = Uncertain("d.coefficients.Heave", "drag_quadratic", "d", "Heave", 1e4, 1e3, "normal")
    lin = dataclasses.replace(quad, kind="drag_linear", nominal=0.0)
    sigma = _rms_velocity(dragged, wave, gains, None, quad)
    V = law_responses(plant, wave.omega, gains)["pto"][0]
    a = np.asarray(wave.amplitude)
    assert sigma == pytest.approx(math.sqrt(np.sum(0.5 * a ** 2 * np.abs(V) ** 2)), rel=1e-9)
    g_q, g_l = relative_gradients(dragged, [wave], [gains], [quad, lin], params=None,
                                  skip=[False])[0]
    assert g_l < 0                     # more damping on the hull: less power to the PTO
    assert g_q == pytest.approx(BORGMAN * sigma * g_l, rel=1e-12)


def test_efficiency_gradient_against_differences_of_the_electrical_power():
    """d P_e / d eta from mean P and mean |P| equals a central difference of the metric's
    own electrical power (eta P+ and P- / eta) on a record that returns power."""
    t = np.linspace(0, 100, 20001)
    p = 3e4 + 5e4 * np.sin(0.7 * t)                # W: absorbs mostly, returns some
    eta, h = 0.85, 1e-6
    item = Uncertain("pto.efficiency", "efficiency", "pto", None, eta, 0.02, "normal")
    g = efficiency_gradients([item], {"pto": np.array([p.mean()])},
                             {"pto": np.array([np.abs(p).mean()])}, {"pto": eta})[0, 0]
    fd = (electrical_power(p, eta + h).mean() - electrical_power(p, eta - h).mean()) / (2 * h)
    assert g == pytest.approx(fd, rel=1e-6)


def test_linear_against_nonlinear_is_summed_over_seas():
    """Two seas, two seeds: sea 0 escalated in both seeds, sea 1 in none; u = H |sum w d|."""
    dims = ("sea", "seed")
    ds = xr.Dataset({"nonlinear_model": (dims, [[True, True], [False, False]]),
                     "mean_power_W": (dims, [[90.0, 110.0], [50.0, 50.0]]),
                     "mean_power_W__linear": (dims, [[130.0, 150.0], [np.nan, np.nan]])})
    diff, why = nonlinear_difference(ds, np.array([False, False]))
    assert diff.tolist() == [40.0, 0.0] and "1 seas ran both" in why
    row = nonlinear_component([0.25, 0.75], diff, why, np.ones(2))
    assert row["std_MWh"] == pytest.approx(H * 0.25 * 40.0)
    none, reason = nonlinear_difference(xr.Dataset({"mean_power_W": (dims, [[1.0]])}), [False])
    assert none is None and "only one model ran" in reason


def test_month_blocks_recover_a_known_interannual_variance():
    """A synthetic site of two seas (0 and P W): each month's share of the second sea drawn
    independently (sd s); a year's annual energy is the mean of its 12 months, variance
    (H P s)^2 / 12. The month-block estimator's variance, averaged over 4000 synthetic
    years, equals it within 3 standard errors."""
    rng = np.random.default_rng(7)
    P, s, trials = 1e5, 0.08, 4000
    power = np.array([0.0, P])
    truth = (H * P * s) ** 2 / 12
    estimates = []
    for _ in range(trials):
        q = np.clip(rng.normal(0.5, s, 12), 0, 1)
        months = {f"1996-{m + 1:02d}": np.array([1 - q[m], q[m]]) for m in range(12)}
        values = [H * np.sum(w * power) for w in months.values()]
        estimates.append(block_spread(values, "month")[0] ** 2)
    estimates = np.array(estimates)
    assert estimates.mean() == pytest.approx(truth, abs=3 * estimates.std() / math.sqrt(trials))
    # the budget's row: the relative spread times the site's energy, said to be an estimate
    row = bud.resource_blocks(Resource("month", months, {}, ("b.txt",)), power, 400.0)
    assert row["std_MWh"] == pytest.approx(
        block_spread(values, "month")[0] / np.mean(values) * 400.0)
    assert "ESTIMATED from 12 monthly blocks" in row["source"]


def test_shares_sum_to_one_and_split_by_parameter():
    rows = [bud.component("a", "A", "quadrature", 3.0, dof=10),
            bud.parameters([1.0], [[2.0, -1.0]], np.diag([1.0, 4.0]), ["m", "eta"], "x"),
            bud.absent("b", "B", "linear", "none here")]
    _, table = bud.combine(100.0, rows)
    shares = [r["share_of_variance"] for r in table["components"] if r["std_MWh"] is not None]
    assert sum(shares) == pytest.approx(1.0, abs=1e-12)
    by = table["components"][1]["share_of_variance_by_parameter"]
    assert sum(by.values()) == pytest.approx(table["components"][1]["share_of_variance"])
    assert table["components"][1]["std_MWh"] == pytest.approx(H * math.sqrt(4 + 4))


SCENE = """
name = "u"
[[body]]
name = "b"
mass = 1000.0
inertia = [1, 1, 1]
cog = [0, 0, 0]
hydro = false
[[joint]]
name = "j"
type = "prismatic"
parent = "ground"
child = "b"
axis = [0, 0, 1]
point = [0, 0, 0]
[[pto]]
name = "p"
joint = "j"
efficiency = 0.9
[[drag]]
body = "b"
[drag.linear]
Heave = 100.0
"""


@pytest.mark.parametrize("table, expected", [
    ('parameter = "b.mass"\nstd = "2 %"', ("mass", 20.0)),
    ('parameter = "b.mass"\nstd = "30 kg"', ("mass", 30.0)),
    ('parameter = "p.efficiency"\ndistribution = "uniform"\nhalf_width = 0.03',
     ("efficiency", 0.03 / math.sqrt(3))),
    ('parameter = "b_drag.linear.Heave"\nstd = "10 %"', ("drag_linear", 10.0)),
    ('parameter = "b_drag.coefficients.Heave"\nstd = 5', ("drag_quadratic", 5.0))])
def test_scene_tables_are_read(tmp_path, table, expected):
    path = tmp_path / "u.toml"
    path.write_text(SCENE + "[[uncertainty]]\n" + table + "\n")
    (item,) = scene_uncertainty(load_scene(path))
    assert item.kind == expected[0]
    assert item.std == pytest.approx(expected[1], rel=1e-12)


@pytest.mark.parametrize("table, words", [
    ('parameter = "c.mass"\nstd = "2 %"', "b.mass"),
    ('parameter = "b.mass"\nstd = "2 %"\nhalf_width = 3', "takes std, not half_width"),
    ('parameter = "b_drag.coefficients.Heave"\nstd = "2 %"', "of a value of 0"),
    ('parameter = "b.mass"\nstd = -3', "positive"),
    ('parameter = "b_drag.linear.Up"\nstd = 1', "DOF 'Up'"),
    ('parameter = "b.mass"', "std: missing")])
def test_bad_tables_are_refused_naming_the_field(tmp_path, table, words):
    path = tmp_path / "u.toml"
    path.write_text(SCENE + "[[uncertainty]]\n" + table + "\n")
    with pytest.raises(SceneError, match="uncertainty\\[0\\]") as err:
        load_scene(path)
    assert words in str(err.value)
