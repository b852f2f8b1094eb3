"""`mbcontrol sweep`: the --json contract, the figure, and clear errors."""
import json

import pytest

from mbcontrol.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_sweep_json_contract_and_annual_energy(capsys, tmp_path):
    seas = tmp_path / "seas.csv"
    seas.write_text("Hm0,Tp,weights,weights_2001,weights_2002\n1.0,8,0.5,0.6,0.4\n"
                    "2.0,10,0.3,0.2,0.4\n3.0,12,0.2,0.2,0.2\n")
    png = tmp_path / "sweep.png"
    # 150 s: a 2 Tp ramp and 10 peak periods of the longest sea (12 s), as a valid result needs
    code, out, err = run(capsys, "sweep", "sphere", "--seas", str(seas), "--duration", "150",
                         "--dt", "0.1", "--workers", "0", "--width", "10", "--plot", str(png),
                         "--json")
    assert code == 0, err
    s = json.loads(out)
    assert set(s) >= {"model", "cases", "computed", "reused", "wall_time_s", "seas",
                      "weighted_mean_power_W", "annual_energy_MWh", "valid_cases",
                      "invalid_cases", "invalid", "failed_cases", "failed", "notes",
                      "annual_energy_coverage",
                      "annual_energy_unchecked_MWh", "provenance"}
    assert s["invalid_cases"] == 0 and s["annual_energy_coverage"] == 1.0
    assert set(s["provenance"]) >= {"version", "scene_sha256", "hydro_sha256",
                                    "radiation_sha256", "controller", "settings"}
    assert (s["model"], s["cases"], s["computed"], s["reused"]) == ("sphere", 3, 3, 0)
    rows = s["seas"]
    assert [(r["hs"], r["tp"], r["weight"]) for r in rows] == [(1.0, 8.0, 0.5), (2.0, 10.0, 0.3),
                                                                (3.0, 12.0, 0.2)]
    for r in rows:
        assert r["mean_power_W"] > 0
        assert r["capture_width_m"] == pytest.approx(r["mean_power_W"] / r["energy_flux_W_per_m"])
        assert r["capture_width_ratio"] == pytest.approx(r["capture_width_m"] / 10)
    # each sea's power against its own simulate() run, the flux against the JONSWAP flux in
    # the scene's water: computed here, not read back from the sweep
    from mbcontrol import waves
    from mbcontrol.analysis import summary
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    from mbcontrol.waves import energy_flux
    plant = build_plant("sphere")
    omega = plant.hydro.omega
    for r in rows:
        wave = waves.irregular(r["hs"], r["tp"], seed=0, duration=150.0,
                               data_band=(float(omega[0]), float(omega[-1])))
        own = summary(simulate(plant, wave, duration=150.0, dt=0.1), plant)
        assert r["mean_power_W"] == pytest.approx(own["ptos"]["pto"]["mean_power_W"], rel=1e-9)
        water = plant.scene.water                  # the device's water: rho 1000 for sphere
        assert r["energy_flux_W_per_m"] == pytest.approx(
            energy_flux(r["hs"], r["tp"], depth=water.depth, rho=water.rho, g=water.g), rel=1e-9)
    weighted = sum(r["weight"] * r["mean_power_W"] for r in rows)
    assert s["weighted_mean_power_W"] == pytest.approx(weighted)
    assert s["annual_energy_MWh"] == pytest.approx(weighted * 8766 / 1e6)
    assert png.stat().st_size > 20_000
    # error bars: the scene's linear damper gives each sea its spectral scatter, and the
    # annual energy an interval with its budget (the resource term from the two years)
    assert all(r["spectral_cv"] > 0 and r["effective_samples"] > 1 for r in rows)
    lo, hi = s["annual_energy_ci95_MWh"]
    assert lo < s["annual_energy_MWh"] < hi
    parts = {c["component"]: c for c in s["annual_energy_budget"]["components"]}
    assert set(parts) == {"statistical", "model", "radiation_fit", "linear_vs_nonlinear",
                          "parameters", "scene_parameters", "resource"}
    assert parts["resource"]["std_MWh"] > 0 and parts["model"]["absent"]
    assert parts["linear_vs_nonlinear"]["absent"] and parts["scene_parameters"]["absent"]
    assert sum(c["share_of_variance"] or 0 for c in parts.values()) == pytest.approx(1.0)
    assert "annual_electrical_energy_MWh" not in s          # an ideal PTO: electrical = absorbed


def test_sweep_vary_gives_lists(capsys):
    code, out, err = run(capsys, "sweep", "sphere", "--hs", "1", "--tp", "9", "--duration", "110",
                         "--dt", "0.1", "--workers", "0", "--vary", "pto__damping=2e5,5e5",
                         "--json")
    assert code == 0, err
    row = json.loads(out)["seas"][0]
    assert len(row["mean_power_W"]) == 2 and row["weight"] is None


@pytest.mark.parametrize("argv, message", [
    (["--hs", "1"], "--hs needs --tp"),
    (["--hs", "1", "--tp", "8", "--vary", "no_such=1,2"], "--vary no_such: not a scene parameter"),
    (["--hs", "1", "--tp", "8", "--vary", "pto__damping=a,b"], "expected NAME=v1,v2"),
    (["--hs", "1", "--tp", "8", "--controller", "nope"], "--controller nope: expected one of"),
])
def test_sweep_errors_are_clear(capsys, argv, message):
    code, _, err = run(capsys, "sweep", "sphere", "--workers", "0", *argv)
    assert code == 1 and message in err


def test_sweep_set_takes_words_and_records_the_forecast(capsys):
    # the complaint: --set forecast=ar failed (values parsed as numbers only); the
    # forecast the cases ran with is in the provenance, causal unless asked
    # (60 s: the settings are what is checked; too short for valid statistics, as it says)
    base = ["sweep", "sphere", "--hs", "1", "--tp", "8", "--controller", "mpc", "--duration",
            "60", "--dt", "0.1", "--workers", "0", "--json", "--allow-invalid"]
    code, out, err = run(capsys, *base, "--set", "forecast=ar")
    assert code == 0, err
    settings = json.loads(out)["provenance"]["settings"]
    assert settings["forecast"] == "ar" and settings["oracle"] is False
    code, out, err = run(capsys, *base, "--set", "forecast=known")
    assert code == 0, err
    settings = json.loads(out)["provenance"]["settings"]
    assert settings["oracle"] is True and "upper bound" in settings["label"]


def test_a_bare_damped_law_warns_that_it_absorbs_nothing(capsys):
    """The issue's case: `--controller reactive` with no settings ran at damping 0 and
    stiffness 0 and reported 0.0 W everywhere, "valid", silently. It still runs as given (the
    documented choice), and says so on stderr and in the summary's notes; with a damping
    given, or the damping varied, it says nothing."""
    argv = ("sweep", "sphere", "--hs", "1", "--tp", "8", "--duration", "96", "--dt", "0.1",
            "--workers", "0", "--json", "--controller", "reactive")
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    s = json.loads(out)
    assert s["seas"][0]["mean_power_W"] == 0.0
    assert "absorbs no power" in err and "absorbs no power" in s["notes"][0]
    for extra in (("--set", "damping=2e5"), ("--vary", "damping=1e5,2e5")):
        code, out, err = run(capsys, *argv, *extra)
        assert code == 0 and "absorbs no power" not in err + out


def test_simulate_with_a_bare_damped_law_warns(capsys):
    code, _, err = run(capsys, "simulate", "sphere", "--controller", "passive", "--wave",
                       "regular", "--height", "1", "--period", "8", "--duration", "96")
    assert code == 0 and "controller 'passive' with damping 0 absorbs no power" in err


def test_design_tunes_every_sea_and_reports_its_bound(capsys, tmp_path):
    """`sweep --design`: each sea's reactive law is the one `design` tunes for that sea (the
    same tuner called directly on the same wave), its power is at most the bound inside the
    same envelope (+1 %), the share is reported, and a bare reactive law no longer warns.
    A rerun from the store computes nothing and reports the same settings."""
    from mbcontrol import build_plant, load_scene, waves
    from mbcontrol.studies.design import design_for_sea
    argv = ("sweep", "rm3", "--hs", "1.5", "3.5", "--tp", "9", "--duration", "300", "--dt", "0.1",
            "--workers", "0", "--controller", "reactive", "--design", "--store",
            str(tmp_path / "store"), "--json")
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    s = json.loads(out)
    assert "absorbs no power" not in err + out
    assert s["valid_cases"] == 2 and s["provenance"]["settings"]["designed_per_sea"] is True
    plant = build_plant(load_scene("rm3"))
    omega = plant.hydro.omega
    for row in s["seas"]:
        wave = waves.irregular(row["hs"], row["tp"], seed=0, duration=300.0,
                               data_band=(float(omega[0]), float(omega[-1])))
        direct = design_for_sea(plant, wave, "reactive")
        assert row["settings"]["damping"] == pytest.approx(direct["settings"]["damping"], rel=1e-9)
        assert row["settings"]["stiffness"] == pytest.approx(direct["settings"]["stiffness"],
                                                             rel=1e-9)
        assert row["bound_W"] == pytest.approx(direct["bound_W"], rel=1e-6)
        assert 0 < row["mean_power_W"] <= 1.01 * row["bound_W"]
        assert row["percent_of_bound"] == pytest.approx(100 * row["mean_power_W"] / row["bound_W"])
        assert row["inside_envelope"] is True
        assert row["meets_robustness_floors"] is direct["robustness"]["meets"]
    code, again, err = run(capsys, *argv)
    assert code == 0, err
    again = json.loads(again)
    assert again["computed"] == 0 and [r["settings"] for r in again["seas"]] == [
        r["settings"] for r in s["seas"]]


def test_design_needs_a_controller_with_a_tuner(capsys):
    code, _, err = run(capsys, "sweep", "sphere", "--hs", "1", "--tp", "8", "--workers", "0",
                       "--design")
    assert code == 1 and "--design tunes a controller for each sea" in err


def test_json_output_is_only_json_whatever_c_code_prints(capfd):
    """qpOASES reports an infeasible QP on the process's standard output whatever its print
    level, which broke `sweep --controller mpc --json` (a JSON reader got the error lines
    first). Under --json such writes go to standard error; the JSON alone to standard out."""
    import os

    from mbcontrol.cli import _stdout_for_json_only
    with _stdout_for_json_only():
        os.write(1, b"->ERROR: Premature homotopy termination\n")
        print('{"json": true}')
    out, err = capfd.readouterr()
    assert json.loads(out) == {"json": True}
    assert "homotopy" in err and "homotopy" not in out


def test_a_designed_mpc_runs_on_the_sweeps_step(capsys):
    """The MPC designed for a sea has a period of Tp / 40 (0.225 s at Tp 9 s), not a whole
    number of the sweep's 0.05 s steps: every Humboldt Bay case failed that way until the
    period was rounded to whole steps."""
    # (60 s: the design and the step are what is checked; too short for valid statistics)
    code, out, err = run(capsys, "sweep", "sphere", "--hs", "1.5", "--tp", "9", "--duration",
                         "60", "--dt", "0.05", "--workers", "0", "--controller", "mpc",
                         "--design", "--json", "--allow-invalid")
    assert code == 0, err
    s = json.loads(out)
    assert s["failed_cases"] == 0, s["failed"]
    period = s["seas"][0]["settings"]["dt_s"]
    steps = period / 0.05
    assert steps == pytest.approx(round(steps)) and abs(period - 9.0 / 40) <= 0.025 + 1e-12
    assert s["seas"][0]["settings"]["horizon_s"] == 9.0


def test_a_sweep_with_invalid_cases_exits_3_and_says_what_to_do(capsys):
    """Exit status 3 as `simulate` for an invalid result (0 with --allow-invalid); the text
    names the case, its reason and, once, the remedy; no JSON key names in it."""
    # Hs 16 m at Tp 9 s: below breaking (18 m), far beyond the sphere's linear range
    argv = ["sweep", "sphere", "--hs", "1", "16", "--tp", "9", "--controller", "passive",
            "--set", "damping=2e5", "--duration", "108", "--workers", "0"]
    code, out, _ = run(capsys, *argv)
    assert code == 3
    assert "INVALID Hs 16 m, Tp 9 s, seed 0: body 'sphere': significant relative heave" in out
    assert out.count("remedy: the model that covers large motions") == 1 and "'invalid'" not in out
    code, out, _ = run(capsys, *argv, "--allow-invalid")
    assert code == 0 and "INVALID Hs 16 m" in out


def test_frequency_domain_sweep_speaks_the_time_domain_format(capsys, tmp_path):
    """--domain frequency: the --json keys of the time-domain sweep, its table with a bound
    column, and its power matrix figure; nothing simulated."""
    seas = tmp_path / "seas.csv"
    seas.write_text("Hm0,Tp,weights\n1.0,8,0.5\n2.0,10,0.3\n3.0,12,0.2\n")
    code, out, err = run(capsys, "sweep", "sphere", "--seas", str(seas), "--domain", "frequency",
                         "--controller", "passive", "--set", "damping=4e5", "--json")
    assert code == 0, err
    s = json.loads(out)
    assert set(s) >= {"model", "cases", "computed", "reused", "wall_time_s", "seas",
                      "weighted_mean_power_W", "annual_energy_MWh", "valid_cases",
                      "invalid_cases", "invalid", "failed_cases", "failed", "notes",
                      "annual_energy_coverage", "annual_energy_unchecked_MWh", "provenance"}
    assert s["domain"] == "frequency" and s["law"] == {"pto": {"damping": 4e5, "stiffness": 0.0}}
    assert all(r["conjugate_bound_W"] > r["mean_power_W"] > 0 for r in s["seas"])
    png = tmp_path / "fd.png"
    code, out, err = run(capsys, "sweep", "sphere", "--seas", str(seas), "--domain", "frequency",
                         "--plot", str(png))
    assert code == 0 and png.stat().st_size > 10_000, err
    assert "seas in the frequency domain" in out and "bound kW" in out
    assert "annual energy" in out


@pytest.mark.parametrize("argv, message", [
    (["--controller", "latching"], "needs a linear law: the latching law is not linear"),
    (["--controller", "passive", "--design"], "--design with --domain frequency: not built"),
    (["--seeds", "3"], "--seeds with --domain frequency: not built"),
    (["--nonlinear", "always"], "--nonlinear with --domain frequency: not built"),
    (["--controller", "reactive", "--set", "damping=1e5", "--set", "stiffness=-5e6"],
     "statically unstable"),
])
def test_frequency_domain_refuses_what_linear_theory_does_not_describe(capsys, argv, message):
    code, out, err = run(capsys, "sweep", "sphere", "--hs", "1", "--tp", "8", "--domain",
                         "frequency", *argv)
    assert code != 0 and message in err, err


def test_both_domains_agree_in_moderate_seas_within_a_records_scatter(capsys):
    """(c) --domain both, the sphere's scene damper in two moderate seas, 300 s records at dt
    0.1 s: per sea linear theory equals the time-domain sweep's own expected power (its
    per-sea path, `spectral.expected_power`) to 1e-9, and the simulated power agrees with it
    within 3 x spectral_cv + 1 %: spectral_cv is the relative standard deviation of one
    record's mean power about linear theory's (the deterministic-amplitude sea's random
    phases; `analysis.power_statistics`, about 2-3 % here), the 1 % the radiation fit the
    simulation steps against the BEM data (the sphere's radiation_tol 0.01)."""
    code, out, err = run(capsys, "sweep", "sphere", "--hs", "1.5", "2.5", "--tp", "8.5",
                         "--domain", "both", "--duration", "300", "--dt", "0.1", "--workers",
                         "0", "--json")
    assert code == 0, err
    s = json.loads(out)
    assert s["domain"] == "both" and s["frequency_domain"]["failed_cases"] == 0
    for r in s["seas"]:
        assert r["frequency_domain_power_W"] == pytest.approx(r["expected_power_W"], rel=1e-9)
        assert r["relative_difference"] == pytest.approx(
            r["mean_power_W"] / r["frequency_domain_power_W"] - 1, rel=1e-12)
        assert abs(r["relative_difference"]) <= 3 * r["spectral_cv"] + 0.01, r
    code, out, err = run(capsys, "sweep", "sphere", "--hs", "1.5", "--tp", "8.5", "--domain",
                         "both", "--duration", "300", "--dt", "0.1", "--workers", "0")
    assert code == 0 and "TD/FD-1" in out, err
