"""Result guards (mbcontrol.analysis.validity, .ports): the multiport complex-conjugate bound
against a hand-written impedance and a brute-force optimum, the windowed bound against a
direct time synthesis, and the verdicts: physical runs pass, corrupted or out-of-range ones
fail with their reasons, in the summary, the Dataset, the figure and the CLI's exit status."""
import json
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize

from mbcontrol import build_plant, defaults, load_scene, waves
from mbcontrol.analysis import summary
from mbcontrol.analysis.ports import multiport_bound, port_responses, window_mean_power
from mbcontrol.analysis.validity import assess
from mbcontrol.sim import simulate

from tests.helpers.sphere_reference import heave_impedance


@pytest.fixture(scope="module")
def rm3():
    return build_plant(load_scene("rm3"))


def _sea(plant, hs, tp, duration, seed=0):
    omega = plant.hydro.omega
    return waves.irregular(hs, tp, seed=seed, duration=duration,
                           data_band=(float(omega[0]), float(omega[-1])))


def test_multiport_bound_of_one_heaving_body_is_the_hand_written_one():
    # the heaving sphere's Z_i = B + i(w(m + A) - K/w) written by hand from the BEM arrays
    # (exp(+i w t)); the optimum sum a^2 |F|^2 / (8 B). Tolerance: both interpolate the BEM
    # grid linearly (the hand version A, B and Re/Im F separately): 0.1 %
    plant = build_plant(load_scene("sphere"))
    sea = _sea(plant, 2.5, 8.0, 600.0)
    Z, F = heave_impedance(plant, sea.omega)
    by_hand = float(np.sum(sea.amplitude ** 2 * np.abs(F) ** 2 / (8 * Z.real)))
    assert multiport_bound(plant, sea).power == pytest.approx(by_hand, rel=1e-3)


def test_multiport_optimum_of_two_ptos_is_the_brute_force_optimum():
    # raft3: two hinge PTOs on one raft. At each frequency the absorbed power
    # P(F) = -1/2 Re F^H (Y F + h) is maximised numerically over the four real force
    # components (BFGS from zero), independent of the closed form 1/8 h^H Y_h^-1 h; and the
    # pair beats either PTO alone (the single-port bound with the other PTO idle)
    plant = build_plant(load_scene("raft3"))
    wave = waves.regular(0.02, 1.1)
    names = [p.name for p in plant.scene.ptos]
    Y, H = port_responses(plant, wave.omega, names)
    h = H[0] * wave.amplitude[0] * np.exp(-1j * wave.phase[0])

    def minus_power(x):
        F = x[:2] + 1j * x[2:]
        return 0.5 * np.real(np.conj(F) @ (Y[0] @ F + h))

    scale = np.abs(h).max() / np.abs(Y[0]).max()
    found = minimize(lambda x: minus_power(x * scale), np.zeros(4), method="BFGS",
                     options={"gtol": 1e-12}).fun
    bound = multiport_bound(plant, wave, responses=(Y, H))
    assert bound.power == pytest.approx(-found, rel=1e-6)
    single = max(np.abs(h[i]) ** 2 / (8 * np.real(1 / Y[0, i, i])) for i in range(2))
    assert bound.power > single


def test_windowed_bound_equals_a_direct_time_synthesis(rm3):
    # the closed-form window mean against F(t) V(t) synthesised component by component on a
    # 0.02 s grid (trapezoid): agreement to 1e-4 (the grid's quadrature error)
    sea = _sea(rm3, 2.0, 9.0, 300.0)
    bound = multiport_bound(rm3, sea)
    t = np.arange(30.0, 300.0 + 1e-9, 0.02)
    phasor = np.exp(-1j * np.multiply.outer(t, sea.omega))
    force, velocity = (phasor @ bound.force).real, (phasor @ bound.velocity).real
    direct = -np.trapezoid(np.sum(force * velocity, axis=1), t) / (t[-1] - t[0])
    assert window_mean_power(bound, 30.0, 300.0) == pytest.approx(direct, rel=1e-4)
    # over one whole repeat period of the sea the cross terms between components vanish
    # exactly: the window mean is the spectral sum
    repeat = 2 * np.pi / sea.d_omega
    assert window_mean_power(bound, 0.0, repeat) == pytest.approx(bound.power, rel=1e-9)


@pytest.mark.parametrize("model, hs, tp", [("rm3", 2.0, 9.0), ("sphere", 2.5, 8.0)])
def test_physical_runs_pass(model, hs, tp):
    # the scene's linear PTO in a moderate sea: below the bound, energy balanced, small motions
    plant = build_plant(load_scene(model))
    ds = simulate(plant, _sea(plant, hs, tp, 200.0), duration=200.0, dt=0.05)
    result = summary(ds, plant)
    assert result["valid"] and result["invalid_reasons"] == []
    checks = result["validity"]
    assert 0 < checks["mean_power_W"] < checks["bound_W"]
    assert ds.attrs["valid"] == 1
    assert all(p["valid"] for p in result["ptos"].values())


def test_a_corrupted_result_is_invalid_with_its_reasons(rm3):
    # the same run with a PTO force 50x what the plant applied (what a broken controller
    # record or a mis-scaled export would show): the reported power breaks the bound and the
    # energy balance; both are named
    ds = simulate(rm3, _sea(rm3, 2.0, 9.0, 200.0), duration=200.0, dt=0.05)
    ds["pto__force"] = ds["pto__force"] * 50
    verdict = assess(ds, rm3)
    assert not verdict["valid"]
    text = " ".join(verdict["invalid_reasons"])
    assert "complex-conjugate bound" in text and "energy balance" in text
    checks = verdict["checks"]
    allowance = defaults.get("validity.power_allowance")
    assert checks["mean_power_W"] > (1 + allowance) * max(checks["bound_W"],
                                                          checks["window_bound_W"])
    assert ds.attrs["valid"] == 0 and ds.attrs["invalid_reasons"]


@pytest.fixture(scope="module")
def free_flap_run():
    # OSWEC's flap without PTO damping in a 3 m, 9 s regular wave swings to 35 deg (beyond
    # the 30 deg of linear hydrodynamics); in a 2 m wave to 24 deg (valid)
    plant = build_plant(load_scene("oswec"))
    runs = {}
    for height in (2.0, 3.0):
        ds = simulate(plant, waves.regular(height, 9.0), duration=150.0, dt=0.05,
                      params={"pto__damping": 0.0})
        runs[height] = (ds, summary(ds, plant))
    return plant, runs


def test_motion_beyond_linear_hydrodynamics_is_invalid(free_flap_run):
    _, runs = free_flap_run
    assert runs[2.0][1]["valid"]
    small = runs[2.0][1]["validity"]["excursions"]["flap"]["pitch_significant"]
    assert np.degrees(small) < 30
    ds, result = runs[3.0]
    assert not result["valid"]
    assert any("pitch" in r and "linear hydrodynamics" in r for r in result["invalid_reasons"])
    assert not result["ptos"]["pto"]["valid"]


def test_verdict_survives_netcdf_and_marks_the_figure(free_flap_run, tmp_path):
    from mbcontrol.plotting import INVALID_FACE, time_series
    import xarray as xr

    from mbcontrol.results import save_dataset
    from matplotlib.colors import to_hex
    ds, _ = free_flap_run[1][3.0]
    save_dataset(ds, tmp_path / "run.nc")
    back = xr.load_dataset(tmp_path / "run.nc")
    assert back.attrs["valid"] == 0 and "pitch" in back.attrs["invalid_reasons"]
    fig = time_series(back, ["eta", "pto__power"])
    assert to_hex(fig.axes[0].get_facecolor()) == INVALID_FACE
    assert "INVALID" in fig.axes[0].get_title()


def test_cli_exits_non_zero_on_an_invalid_result(capsys):
    from mbcontrol.cli import main
    args = ["simulate", "oswec", "--wave", "regular", "--height", "3", "--period", "9",
            "--duration", "150", "--dt", "0.05", "--param", "pto__damping=0", "--json"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(args) == 3
        out = json.loads(capsys.readouterr().out)
        assert out["valid"] is False and out["ptos"]["pto"]["invalid_reasons"]
        assert main(args + ["--allow-invalid"]) == 0


def test_every_invalid_reason_says_what_to_do():
    """Each way a result fails (above its wave's bound, energy out of nothing, motions beyond
    linear hydrodynamics) names its remedy after ". Remedy: ", which the CLI prints on a line
    of its own (issue 40: "INVALID ... linear hydrodynamics do not hold there" named none)."""
    from mbcontrol.analysis import split_remedy
    from mbcontrol import defaults
    from mbcontrol.analysis.validity import assess_values
    DRAFT_FACTOR = defaults.get("validity.draft_factor")
    plant = build_plant("sphere")
    wave = waves.regular(1.0, 8.0)
    draft = 3.33                                              # V / A_wp of the hemisphere, m
    verdict = assess_values(
        plant, wave, plant.p0, window=(0.0, 80.0), mean_power_W=1e9,
        energy=(1e6, 3e6, 0.0, 1e6),                          # absorbed 3x the waves' work
        excursions={"sphere": {"relative_heave_limit_m": draft,
                               "relative_heave_significant": 2 * DRAFT_FACTOR * draft,
                               "relative_heave_max": 2 * DRAFT_FACTOR * draft,
                               "relative_heave_share_beyond": 0.5}})
    reasons = verdict["invalid_reasons"]
    assert len(reasons) == 3 and not verdict["valid"]
    for reason, remedy_word in zip(reasons, ("radiation_tol", "--method", "stroke_max")):
        what, remedy = split_remedy(reason)
        assert what and remedy and remedy_word in remedy and ";" not in remedy


def test_large_angle_hydrostatics_in_waves_says_it_is_not_a_consistent_pair():
    """Exact calm-water buoyancy with linear Froude-Krylov forces is inconsistent once motions
    are large: every result in waves says so (a warning, and the INVALID remedy no longer
    recommends it); a free decay, where it is right, does not."""
    import tomllib

    from mbcontrol.analysis.validity import LARGE_ANGLE_IN_WAVES, REMEDIES
    from mbcontrol.scene import catalogue_dir, parse_scene
    from mbcontrol.sim import initial_state
    path = catalogue_dir() / "sphere.toml"
    data = tomllib.loads(path.read_text())
    data["hydro"].update(file=str(catalogue_dir() / "sphere_hydro.nc"), hydrostatics="large_angle")
    data["body"][0]["geometry"] = {"type": "sphere", "radius": 5.0, "center": [0.0, 0.0, 0.0]}
    data["body"][0]["mass"] = 1000.0 * 2 / 3 * np.pi * 5.0 ** 3     # floats at its centre
    plant = build_plant(parse_scene(data, path))
    wave = waves.regular(1.0, 8.0)
    in_waves = assess(simulate(plant, wave, duration=100.0, dt=0.05), plant, wave)
    assert LARGE_ANGLE_IN_WAVES in in_waves["warnings"]
    decay = simulate(plant, None, duration=20.0, dt=0.05,
                     x0=initial_state(plant, {"heave": 0.5}))
    assert LARGE_ANGLE_IN_WAVES not in assess(decay, plant)["warnings"]
    assert "large_angle" not in REMEDIES["range"]


def test_a_spread_sea_is_checked_in_its_own_directions():
    """A short-crested sea's run, checked from its record alone (as `mbcontrol.simulate` checks
    it), meets the bound of the wave it ran in: each component in its own direction, between
    the data's two headings, not the mean direction, which the data do not hold."""
    import math
    plant = build_plant(load_scene("array4"))
    band = (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))
    spread = waves.Spreading("cos2s", math.radians(22.5), math.radians(8), math.radians(22.5))
    sea = waves.irregular(0.05, 1.2, seed=0, duration=40.0, data_band=band, spreading=spread)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(plant, sea, duration=40.0, dt=0.01, audit=False)
    from_record = assess(ds.copy(), plant)
    given = assess(ds.copy(), plant, sea)
    assert from_record["valid"] and from_record["checks"]["bound_W"] > 0
    for key in ("bound_W", "window_bound_W"):
        assert from_record["checks"][key] == given["checks"][key]
    assert np.array_equal(ds["wave_direction"].values, sea.direction)
