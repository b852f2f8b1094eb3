"""Nonlinear hydrostatics and Froude-Krylov forces in the plant (mbcontrol.plant.nonlinear), on
the catalogue's R = 5 m hemisphere in heave (tests/plant/sphere_nonlinear.toml: the same WAMIT
data and PTO as models/sphere.toml, with [hydro] hydrostatics = froude_krylov = "nonlinear").

References: the linear plant (small waves: the nonlinear plant must reduce to it, its linear
Froude-Krylov part removed from the BEM excitation exactly); the spherical cap's closed-form
potential (a free decay from 2 m); the published OES Task 10 comparison (Wendt et al. 2019,
J. Mar. Sci. Eng. 7(11):379: two nonlinear codes 4-18 % below the linear codes for the floating
sphere in heave with a linear damper, H/(g T^2) = 0.01, T = 8-11 s); the panel path against
the analytic path (two independent integrations of the same pressure). The surface integrals
themselves are checked against closed forms in tests/hydro/mesh/test_panels.py and
tests/features/hydro/test_axisymmetric_fk.py, the wave field against direct sums in
tests/waves/test_local_field.py.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol import sim, waves
from mbcontrol.errors import SceneError, WaveError
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene

SCENE = str((Path(__file__).resolve().parents[2] / "plant" / "sphere_nonlinear.toml"))
PTO_DAMPING = 1.0e6      # N s/m: the body then moves well apart from the wave (RAO 0.5-0.7)


@pytest.fixture(scope="module")
def plants():
    return build_plant(SCENE), build_plant("sphere")


def first_harmonic(ds, period: float, periods: int = 10) -> float:
    """Heave amplitude at the wave's frequency over the last `periods` periods (m)."""
    t, z = ds["time"].values, ds["heave"].values
    keep = t > t[-1] - periods * period
    return 2 * abs(np.mean(z[keep] * np.exp(-2j * math.pi / period * t[keep])))


def heave_rao(plant, height, period, damping=PTO_DAMPING):
    ds = sim.simulate(plant, waves.regular(height, period), duration=30 * period, dt=0.01,
                      params=plant.params(pto__damping=damping))
    return first_harmonic(ds, period) / (height / 2)


def test_small_waves_give_the_linear_plants_response(plants):
    nonlinear, linear = plants
    # 2 cm at 8 s: the response of the two plants differs only by their hydrostatic stiffness
    # (the cap's rho g pi R^2 against the file's C33: 1.1e-4) and mass (0.03 %); measured 7e-5
    for period in (5.0, 8.0):
        ratio = heave_rao(nonlinear, 0.02, period) / heave_rao(linear, 0.02, period)
        assert ratio == pytest.approx(1.0, abs=5e-4)


def test_a_small_irregular_sea_gives_the_linear_plants_record(plants):
    nonlinear, linear = plants
    sea = waves.irregular(0.05, 8.0, seed=3)
    a, b = (sim.simulate(p, sea, duration=200, dt=0.01)["heave"].values for p in plants)
    assert np.sqrt(np.mean((a - b) ** 2)) < 2e-3 * np.sqrt(np.mean(b ** 2))


def test_steep_waves_fall_below_the_linear_model_as_published(plants):
    nonlinear, linear = plants
    # H/(g T^2) = 0.01. Published (OES Task 10): the nonlinear codes 4-18 % below the linear ones
    # at 8-11 s. The PTO damping of that study is not in our sources: with 1e6 N s/m, measured
    # -7.4, -9.5, -12.0, -15.1 %, growing with the period (the relative motion grows) as
    # published; with the catalogue's 2e5 N s/m the sphere follows the wave and the two agree
    # to 0.6 %
    drops = []
    for period in (8.0, 9.0, 10.0, 11.0):
        height = 0.01 * 9.81 * period ** 2
        drops.append(1 - heave_rao(nonlinear, height, period) / heave_rao(linear, height, period))
    assert all(0.04 <= d <= 0.18 for d in drops), drops
    assert np.all(np.diff(drops) > 0)


def test_a_nonlinear_decay_stores_the_caps_energy(plants):
    nonlinear, _ = plants
    # lifted 2 m out of the water: U = rho g pi (R^2 z0^2 / 2 - z0^4 / 12), the exact cap
    # potential (tests/features/cli/test_decay.py has the same for large_angle); 10 % above the linear
    # 1/2 rho g pi R^2 z0^2 would be wrong by z0^2/(6 R^2) = 2.7 %
    z0, rho, g, radius = -2.0, 1000.0, 9.81, 5.0
    x0 = nonlinear.x0()
    x0[nonlinear.states.index("heave")] = z0
    ds = sim.simulate(nonlinear, None, duration=20, dt=0.01, x0=x0)
    stored = rho * g * math.pi * (radius ** 2 * z0 ** 2 / 2 - z0 ** 4 / 12)
    # the mass is rho (2/3) pi R^3 rounded to the gram: 2.6e-9 of the weight's work
    assert float(ds["energy"][0]) == pytest.approx(stored, rel=1e-8)
    t = ds["time"].values
    taken = np.trapezoid(ds["pto__power"].values + ds["radiated_power"].values, t)
    left = float(ds["energy"][-1])
    assert taken + left == pytest.approx(stored, rel=2e-3)


def test_the_panel_path_agrees_with_the_analytic_path():
    scene = load_scene(SCENE)
    coarse = dataclasses.replace(scene, hydro=dataclasses.replace(
        scene.hydro, nonlinear_path="panels", nonlinear_panel_size=2.0))   # 104 points
    analytic, panels = build_plant(scene), build_plant(coarse)
    assert panels.pressure[0].path == "panels" and panels.pressure[0].model.n < 150
    period = 9.0
    height = 0.01 * 9.81 * period ** 2
    a, b = (heave_rao(p, height, period) for p in (analytic, panels))
    # two integrations of the same pressure: exact caps and closed-form volume integrals under
    # a locally flat surface, against surface points under the exact incident surface.
    # Measured panels / analytic - 1: 104 points -1.7 %, 208 -1.2 %, 384 -0.9 % (second order
    # in the panel size, converging to about -0.7 %: the analytic path's flat-waterline
    # approximation, 1-2 % of the heave force in tests/features/hydro/test_axisymmetric_fk.py)
    assert b == pytest.approx(a, rel=0.025)
    assert b < a


def test_froude_krylov_alone_is_refused(tmp_path):
    text = open(load_scene(SCENE).path).read()
    path = tmp_path / "sphere_fk_only.toml"
    path.write_text(text.replace('hydrostatics = "nonlinear"', 'hydrostatics = "linear"')
                    .replace('"sphere_hydro.nc"', f'"{load_scene("sphere").hydro.file}"'))
    with pytest.raises(SceneError, match=r"froude_krylov.*hydrostatics = \\?\"nonlinear\\?\""):
        load_scene(str(path))


def test_seas_the_field_was_not_built_for_are_refused(plants):
    nonlinear, _ = plants
    with pytest.raises(WaveError, match="nonlinear_direction"):
        sim.simulate(nonlinear, waves.regular(1.0, 8.0, direction=0.5), duration=10, dt=0.01)
    spread = waves.irregular(1.0, 8.0, seed=1, spreading=waves.Spreading(
        "cos2s", 0.0, math.radians(30.0)))
    with pytest.raises(WaveError, match="long-crested"):
        sim.simulate(nonlinear, spread, duration=10, dt=0.01)


def test_a_body_past_its_field_is_invalid(plants):
    from mbcontrol.analysis import assess
    nonlinear, _ = plants
    sea = waves.regular(0.01 * 9.81 * 81, 9.0)
    ds = sim.simulate(nonlinear, sea, duration=120, dt=0.01,
                      params=nonlinear.params(pto__damping=PTO_DAMPING))
    used = float(ds["sphere__field_range"].max())
    assert 0.1 < used < 1.0                      # a heave-only sphere in a steep wave: inside
    verdict = assess(ds, nonlinear, sea)
    assert verdict["checks"]["sphere__field_range"] == pytest.approx(used)
    assert not any("nonlinear incident field" in r for r in verdict["invalid_reasons"])
    # the same record as if the sphere had gone 20 % past the deepest the series cover
    ds["sphere__field_range"] = ds["sphere__field_range"] * (1.2 / used)
    verdict = assess(ds, nonlinear, sea)
    assert not verdict["valid"]
    assert any("left the region its nonlinear incident field covers" in r and
               "nonlinear_reach" in r for r in verdict["invalid_reasons"])


def test_the_fidelity_search_can_take_the_pressure_linear():
    from mbcontrol.plant import Fidelity, plant_for
    linear = plant_for(SCENE, Fidelity(pressure="linear"))
    assert linear.wave_rows == 0 and linear.scene.hydro.froude_krylov == "linear"
    assert Fidelity(pressure="linear").label() == "pressure=linear"
    a, b = (heave_rao(p, 0.02, 8.0) for p in (linear, build_plant("sphere")))
    assert a == pytest.approx(b, rel=5e-4)       # the catalogue sphere but for its mass


def test_sweeps_do_not_take_linear_theory_for_the_scatter_of_a_nonlinear_plant(plants):
    # the spectral estimate of a sea's power scatter is linear theory: with nonlinear pressure
    # a sweep needs seeds for it (--seeds 2 or more), as for a nonlinear law
    from mbcontrol.studies.sweep.spectral import law_gains
    nonlinear, linear = plants
    gains, why = law_gains(nonlinear, "passive", {"damping": 1e6})
    assert gains is None and "hydrostatics" in why
    assert law_gains(linear, "passive", {"damping": 1e6})[0] is not None
