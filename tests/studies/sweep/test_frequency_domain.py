"""The frequency-domain sweep (`mbcontrol.studies.sweep.frequency_domain`) against references
computed another way: the per-sea path the time-domain sweep already uses for linear theory
(`spectral.expected_power` and `analysis.multiport_bound` on each sea's own wave), a
hand-written heave oscillator from the BEM file, the energy flux of `waves.site_energy_flux`,
and a Froude-scaled device built from scaled BEM data."""
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from mbcontrol.errors import InputError
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.studies.sweep import frequency_sweep, froude_seas, sea_powers
from mbcontrol.studies.sweep.frequency_domain import linear_gains, sea_energy_fluxes
from mbcontrol.studies.sweep.runner import sea_wave
from mbcontrol.studies.sweep.spectral import expected_power
from mbcontrol.waves import SeaState, read_seas, site_energy_flux

ROOT = Path(__file__).resolve().parents[3]
SITES = ROOT.parent / "shared" / "data" / "sites"
HYDRO = ROOT / "models" / "sphere_hydro.nc"
needs_sites = pytest.mark.skipif(not SITES.exists(), reason="site data not found")


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


@pytest.fixture(scope="module")
def rm3():
    return build_plant("rm3")


# moderate seas, one whose 20 Tp (320 s) exceeds the 300 s records: its own frequency grid
SEAS = [SeaState(1.0, 7.3), SeaState(2.5, 9.1, 2.0), SeaState(1.5, 12.7, 1.0),
        SeaState(3.0, 16.0)]


@pytest.mark.parametrize("model, controller, settings", [
    ("sphere", None, {}), ("sphere", "reactive", {"damping": 3e5, "stiffness": -2e5}),
    ("rm3", "passive", {"damping": 8e5}), ("rm3", "reactive", {"damping": 1e6, "stiffness": -5e4}),
])
def test_every_sea_at_once_equals_the_per_sea_path(model, controller, settings, sphere, rm3):
    """(a) the vectorised powers and bounds against each sea's own wave (the time-domain
    sweep's, `runner.sea_wave`) through `spectral.expected_power` and `multiport_bound`."""
    from mbcontrol.analysis import multiport_bound
    plant = {"sphere": sphere, "rm3": rm3}[model]
    gains = linear_gains(plant, controller, settings, None)
    out = sea_powers(plant, SEAS, gains, duration=300.0)
    assert out["groups"] == 2 and out["reasons"] == [None] * len(SEAS)
    for k, sea in enumerate(SEAS):
        wave = sea_wave(plant, sea, 300.0)
        assert out["power_W"][k] == pytest.approx(expected_power(plant, wave, gains), rel=1e-9)
        assert out["bound_W"][k] == pytest.approx(multiport_bound(plant, wave).power, rel=1e-9)
        assert 0 < out["power_W"][k] < out["bound_W"][k]


def test_a_heave_damper_equals_the_hand_written_oscillator(sphere):
    """(b) the sphere with the scene's damper c: sum over the sea's components of
    0.5 c |V|^2 a^2, a^2 = 2 S dw scaled to Hs, with V = i w F / (-w^2 (m + A) + i w (B + c) + K)
    from the BEM file's own A, B, F and C33 (linear interpolation) and the scene's mass."""
    from mbcontrol.waves import jonswap_spectrum
    data = xr.open_dataset(HYDRO)
    w_bem = data["omega"].values
    A = data["added_mass"].values[:, 0, 0]
    B = data["radiation_damping"].values[:, 0, 0]
    F = data["excitation_force"].sel(complex="re").values[0, :, 0] \
        + 1j * data["excitation_force"].sel(complex="im").values[0, :, 0]
    K = float(data["hydrostatic_stiffness"].values[0, 0])
    scene = load_scene("sphere")
    m, c = scene.bodies[0].mass, scene.ptos[0].damping
    seas = [SeaState(1.0, 6.3), SeaState(2.0, 8.7), SeaState(1.5, 11.2, 1.0)]
    duration = 400.0
    out = sea_powers(sphere, seas, {"pto": (c, 0.0)}, duration=duration)
    for k, sea in enumerate(seas):
        d_w = 2 * math.pi / max(duration, 20 * sea.tp)
        wp = 2 * math.pi / sea.tp
        lo, hi = max(0.3 * wp, w_bem[0]), min(4.0 * wp, w_bem[-1])
        w = np.arange(math.ceil(lo / d_w), math.floor(hi / d_w) + 1) * d_w
        a2 = 2 * jonswap_spectrum(w, sea.hs, sea.tp, sea.gamma) * d_w
        a2 *= sea.hs ** 2 / 16 / (a2.sum() / 2)            # 4 sqrt(m0) = Hs on the grid
        Fw = np.interp(w, w_bem, F.real) + 1j * np.interp(w, w_bem, F.imag)
        Z = -w ** 2 * (m + np.interp(w, w_bem, A)) + 1j * w * (np.interp(w, w_bem, B) + c) + K
        V = 1j * w * Fw / Z
        assert out["power_W"][k] == pytest.approx(np.sum(0.5 * c * np.abs(V) ** 2 * a2),
                                                  rel=1e-9)


@needs_sites
@pytest.mark.parametrize("site, gamma", [("pacwave_cluster_32.csv", 3.3),
                                         ("humboldt_bay_rmp.csv", 1.0)])
def test_energy_flux_as_the_time_domain_sweep_gives_it(site, gamma):
    """J of every sea (deep water: one flux per spectral shape, scaled by Hs^2 Tp) against
    `waves.site_energy_flux` sea by sea, the time-domain sweep's."""
    seas = read_seas(SITES / site, gamma)
    J = sea_energy_fluxes(seas, math.inf, 1000.0, 9.81)
    ref = [site_energy_flux(s, math.inf, 1000.0, 9.81) for s in seas]
    np.testing.assert_allclose(J, ref, rtol=1e-12)


@needs_sites
def test_site_summary_has_the_time_domain_keys(sphere):
    """The summary a user's tooling reads: the time-domain sweep's keys (tests/cli/test_sweep.py
    lists them), the annual energy as weights x powers x 8766 h, capture width P / J."""
    seas = read_seas(SITES / "pacwave_cluster_32.csv")
    ds, s = frequency_sweep("sphere", seas, plant=sphere, width=10.0)
    assert set(s) >= {"model", "cases", "computed", "reused", "wall_time_s", "seas",
                      "weighted_mean_power_W", "annual_energy_MWh", "valid_cases",
                      "invalid_cases", "invalid", "failed_cases", "failed", "notes",
                      "annual_energy_coverage", "annual_energy_unchecked_MWh", "provenance"}
    assert s["domain"] == "frequency" and s["cases"] == 32 and s["failed_cases"] == 0
    power = np.array([r["mean_power_W"] for r in s["seas"]])
    weights = np.array([r["weight"] for r in s["seas"]])
    assert s["annual_energy_MWh"] == pytest.approx(np.sum(power * weights) * 8766 / 1e6)
    for r in s["seas"]:
        assert r["capture_width_m"] == pytest.approx(r["mean_power_W"] / r["energy_flux_W_per_m"])
        assert r["capture_width_ratio"] == pytest.approx(r["capture_width_m"] / 10.0)
        assert r["percent_of_conjugate_bound"] == pytest.approx(
            100 * r["mean_power_W"] / r["conjugate_bound_W"])
    from mbcontrol.studies.sweep import power_matrix
    assert float(power_matrix(ds).max()) == pytest.approx(power.max())


def test_laws_linear_theory_cannot_describe_are_refused(sphere):
    with pytest.raises(InputError, match="needs a linear law: the latching law is not linear"):
        linear_gains(sphere, "latching", {}, None)
    with pytest.raises(InputError, match="statically unstable"):   # K33 = 0.77e6 N/m
        linear_gains(sphere, "reactive", {"damping": 1e5, "stiffness": -5e6}, None)
    with pytest.raises(InputError, match="short-crested"):
        sea_powers(sphere, [SeaState(1.0, 8.0, spread=0.3)], {"pto": (1e5, 0.0)},
                   duration=300.0)


def test_a_sea_outside_the_data_has_no_power_and_is_listed(sphere):
    """As the time-domain sweep's case fails there (`waves.irregular` raises): a sea past the
    data's band (4 wp = 0.042 rad/s below its 0.05) and one steeper than a wave can be (5 m
    over the 6.2 m wavelength of 2 s)."""
    seas = [SeaState(1.0, 8.0, weight=0.5), SeaState(1.0, 600.0, weight=0.3),
            SeaState(5.0, 2.0, weight=0.2)]
    _, s = frequency_sweep("sphere", seas, plant=sphere)
    assert s["failed_cases"] == 2 and s["valid_cases"] == 1
    assert "outside the hydro data's band" in s["failed"][0]["reasons"]
    assert "steeper than a wave can be" in s["failed"][1]["reasons"]
    assert [r["mean_power_W"] is None for r in s["seas"]] == [False, True, True]
    assert s["annual_energy_coverage"] == pytest.approx(0.5)


def _froude_sphere(folder, scale: float) -> str:
    """The sphere `scale` times larger: its BEM data and scene scaled by Froude similarity
    (frequencies s^-1/2, A and masses s^3, B s^2.5, excitation and C33 s^2, lengths s,
    inertias s^5, PTO damping s^2.5); the path of its scene."""
    data = xr.open_dataset(HYDRO).load()
    data = data.assign_coords(omega=data["omega"].values / math.sqrt(scale))
    for name, power in (("added_mass", 3), ("added_mass_zero", 3), ("added_mass_inf", 3),
                        ("radiation_damping", 2.5), ("hydrostatic_stiffness", 2),
                        ("excitation_force", 2), ("displaced_volume", 3), ("cog", 1),
                        ("center_of_buoyancy", 1), ("reference_point", 1), ("source_cog", 1),
                        ("waterplane_area", 2)):
        data[name] = data[name] * scale ** power
    data.to_netcdf(folder / "sphere_big_hydro.nc")
    base = load_scene("sphere")
    body, pto = base.bodies[0], base.ptos[0]
    z = 2.0 * scale
    (folder / "sphere_big.toml").write_text(f"""name = "sphere_big"
[water]
rho = 1000.0
g = 9.81
depth = inf
[hydro]
file = "sphere_big_hydro.nc"
radiation_tol = 0.01
dofs = ["Heave"]
[[body]]
name = "sphere"
mass = {body.mass * scale ** 3!r}
inertia = [{2.6e6 * scale ** 5!r}, {2.6e6 * scale ** 5!r}, {2.6e6 * scale ** 5!r}]
cog = [0.0, 0.0, {z!r}]
[[joint]]
name = "heave"
type = "prismatic"
parent = "ground"
child = "sphere"
point = [0.0, 0.0, {z!r}]
axis = [0.0, 0.0, 1.0]
[[pto]]
name = "pto"
joint = "heave"
damping = {pto.damping * scale ** 2.5!r}
""")
    return str(folder / "sphere_big.toml")


def test_froude_scaling_of_a_device_built_from_scaled_bem_data(sphere, tmp_path):
    """A sphere 4 times larger, built from Froude-scaled BEM data: its power and bound at the
    scaled seas are 4^3.5 times the original's at `froude_seas`' (records 2 times longer), to
    1e-9; the hull-size example (benchmarks/hull_site_example.py) rests on this."""
    scale = 4.0
    big = build_plant(load_scene(_froude_sphere(tmp_path, scale)))
    seas = [SeaState(2.0 * scale, 8.3 * 2), SeaState(1.0 * scale, 11.1 * 2, 1.0)]
    mine = sea_powers(big, seas, linear_gains(big, None, {}, None), duration=600.0)
    small = sea_powers(sphere, froude_seas(seas, scale), linear_gains(sphere, None, {}, None),
                       duration=300.0)
    np.testing.assert_allclose(mine["power_W"], scale ** 3.5 * small["power_W"], rtol=1e-9)
    np.testing.assert_allclose(mine["bound_W"], scale ** 3.5 * small["bound_W"], rtol=1e-9)
