"""The defaults registry (mbcontrol/defaults.py): one value per key, overridable in order
set() > environment > built-in, and the functions that take their defaults from it."""
import json

import numpy as np
import pytest

from mbcontrol import defaults
from mbcontrol.cli import main


@pytest.fixture(autouse=True)
def _clean():
    defaults.reset()
    yield
    defaults.reset()


def test_order_set_over_environment_over_built_in(monkeypatch):
    assert defaults.get("sim.dt") == 0.01 and defaults.source("sim.dt") == "built-in"
    monkeypatch.setenv("MBCONTROL_SIM_DT", "0.002")
    assert defaults.get("sim.dt") == 0.002 and defaults.source("sim.dt") == "MBCONTROL_SIM_DT"
    defaults.set("sim.dt", 0.005)
    assert defaults.get("sim.dt") == 0.005 and defaults.source("sim.dt") == "set"
    defaults.reset("sim.dt")
    assert defaults.get("sim.dt") == 0.002
    with defaults.override(sim_method="dopri5"):
        assert defaults.get("sim.method") == "dopri5"
    assert defaults.get("sim.method") == "rk4"


def test_bad_values_name_the_variable_or_key(monkeypatch):
    monkeypatch.setenv("MBCONTROL_SIM_DT", "fast")
    with pytest.raises(ValueError, match="MBCONTROL_SIM_DT='fast': expected a float"):
        defaults.get("sim.dt")
    with pytest.raises(KeyError, match="unknown default 'sim.step'.*sim.dt"):
        defaults.get("sim.step")
    with pytest.raises(TypeError, match="'sim.method': expected a str"):
        defaults.set("sim.method", 4)


def test_cache_folder_and_quiet_keep_their_historical_variables(monkeypatch, tmp_path):
    from mbcontrol.cache import cache_dir
    from mbcontrol.console import progress_bar
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path / "c"))
    assert cache_dir() == tmp_path / "c" and cache_dir().is_dir()
    monkeypatch.setenv("MBCONTROL_QUIET", "1")
    assert progress_bar(total=3).disable
    monkeypatch.setenv("MBCONTROL_QUIET", "0")
    assert defaults.get("log.quiet") is False


def test_simulate_takes_its_step_and_method_from_the_registry():
    from mbcontrol import build_plant, waves
    from mbcontrol.analysis import simulate_checked as simulate   # the checked Dataset
    plant = build_plant("sphere")
    wave = waves.regular(1.0, 9.0)
    with defaults.override(sim_dt=0.1, sim_method="rk3"):   # stable below 0.15 s
        with pytest.warns(RuntimeWarning, match="before its statistics window would start"):
            ds = simulate(plant, wave, duration=5.0)      # 5 s: still inside the 18 s ramp
    assert ds.attrs["dt_s"] == 0.1 and ds.attrs["method"] == "rk3"
    assert np.allclose(np.diff(ds.time), 0.1)
    with pytest.warns(RuntimeWarning, match="simulate at least 108 s"):
        ds = simulate(plant, wave, duration=5.0, dt=0.05)     # an argument wins
    assert ds.attrs["dt_s"] == 0.05 and ds.attrs["method"] == "rk4"


def test_cli_lists_every_key_and_its_help_shows_the_value_in_force(capsys, monkeypatch):
    assert main(["defaults", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["key"] for r in rows] == defaults.keys()
    assert {"key", "value", "unit", "source", "env", "doc"} <= set(rows[0])
    monkeypatch.setenv("MBCONTROL_SWEEP_DT", "0.1")
    with pytest.raises(SystemExit):
        main(["sweep", "--help"])
    assert "default 0.1 s: 'sweep.dt'" in capsys.readouterr().out.replace("\n", " ")


def test_the_radiation_tolerance_has_one_default():
    """The radiation fit's tolerance was written in five places with two values (0.01, 0.02);
    every entry point now takes 'hydro.radiation_tol' when none is given."""
    import inspect

    from mbcontrol.hydro import fit_radiation, fit_radiation_columns
    from mbcontrol.scene.model import HydroSettings
    for fit in (fit_radiation, fit_radiation_columns):
        assert inspect.signature(fit).parameters["tol"].default is None
    assert HydroSettings().radiation_tol == defaults.get("hydro.radiation_tol") == 0.01
    with defaults.override(hydro_radiation_tol=0.03):
        assert HydroSettings().radiation_tol == 0.03


def test_progress_bars_only_where_a_person_watches(monkeypatch):
    """A bar redrawn with carriage returns garbles a CI log or a file: on a terminal (or in a
    notebook's kernel) only."""
    import io
    import sys

    from mbcontrol.console import progress_bar

    class Terminal(io.StringIO):
        def isatty(self):
            return True
    monkeypatch.delitem(sys.modules, "ipykernel", raising=False)
    monkeypatch.setenv("MBCONTROL_QUIET", "0")
    monkeypatch.setattr(sys, "stderr", io.StringIO())
    assert progress_bar(total=3).disable
    monkeypatch.setattr(sys, "stderr", Terminal())
    bar = progress_bar(total=3, file=sys.stderr)
    assert not bar.disable
    bar.close()


def test_the_design_margins_are_defaults_and_set_the_tuners_floor(capsys):
    """design.gain_margin_min and design.phase_margin_min_deg: listed, and the robust
    tuner's least |1 + L| follows from them (s = 1 - 1/gm or 2 sin(pm / 2), the larger)."""
    import math

    from mbcontrol.controllers.robustness import STABILITY_ROOM, floors, stability_floor
    assert main(["defaults"]) == 0
    listing = capsys.readouterr().out
    assert "design.gain_margin_min" in listing and "design.phase_margin_min_deg" in listing
    assert floors() == {"gain_margin": 2.0, "phase_margin_deg": 30.0}
    s = 2 * math.sin(math.radians(15))                       # 0.5176 > 1 - 1/2
    assert stability_floor() == pytest.approx(s * STABILITY_ROOM, rel=1e-12)
    assert 1 / (1 - stability_floor()) >= 2 and 2 * math.degrees(
        math.asin(stability_floor() / 2)) >= 30
    with defaults.override(design_gain_margin_min=4.0):      # 0.75 > 2 sin 15 deg
        assert stability_floor() == pytest.approx(0.75 * STABILITY_ROOM, rel=1e-12)
    with defaults.override(design_gain_margin_min=0.5):
        with pytest.raises(ValueError, match="design.gain_margin_min"):
            stability_floor()


# The result-shaping constants moved into the registry (issue 59), with the values they had
# as module constants: `mbcontrol defaults` lists each, unchanged.
MOVED = {"validity.power_allowance": 0.10, "validity.energy_tolerance": 0.05,
         "linearize.equilibrium_share": 1e-6, "mooring.mpm_hours": 3.0,
         "mooring.slack_fraction": 0.02, "sim.energy_margin": 2.0,
         "plant.imbalance_tol": 0.10, "plant.equilibrium_warn": 1e-6,
         "hydro.bem_asymmetry_tol": 1e-2, "identify.alpha": 0.05, "identify.kappa": 0.3,
         "identify.correlation_limit": 0.95, "identify.condition_limit": 1e6,
         "identify.structure_tie": 0.01, "design.bound_tolerance": 0.01,
         "design.max_harmonics": 25, "design.settle_time_constants": 12,
         "design.coulomb_share": 0.98, "fidelity.steps_per_period": 200,
         "fidelity.signal_floor": 1e-3, "fidelity.freeze_threshold": 1e-3,
         "waves.breaking_steepness": 1 / 7, "sweep.direction_step": 0.017453292519943295,
         "resource.min_hours_year": 2880, "resource.min_hours_month": 168,
         "sweep.cluster": "auto", "sweep.start": "forkserver", "compile.cc": "",
         "validity.angle_max": 0.5235987755982988, "validity.draft_factor": 1.0,
         "envelope.share": 0.9, "design.rate_reversals_per_period": 5}


def test_moved_constants_are_listed_with_their_values(capsys, monkeypatch):
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv("MBCONTROL_SWEEP_CLUSTER", raising=False)
    monkeypatch.delenv("MBCONTROL_SWEEP_START", raising=False)
    assert main(["defaults", "--json"]) == 0
    rows = {r["key"]: r for r in json.loads(capsys.readouterr().out)}
    for key, value in MOVED.items():
        assert rows[key]["value"] == value and type(rows[key]["value"]) is type(value), key
        assert rows[key]["source"] == "built-in" and rows[key]["doc"], key


def test_moved_constants_are_read_at_call_time():
    """defaults.override changes what the functions compute, with no module reloaded."""
    from mbcontrol.studies.identify.calibration import scale, score_text
    assert scale(2.0, -10.0) == pytest.approx(2.0 * np.hypot(1, 3.0))
    with defaults.override(identify_kappa=0.6):
        assert scale(2.0, -10.0) == pytest.approx(2.0 * np.hypot(1, 6.0))
        assert "(0.6 * d ln a" in score_text()
    assert "(0.3 * d ln a" in score_text()


def test_moved_envelope_constants_are_read_at_call_time():
    """The envelope's share and the validity limits (issue 59): an override reaches the
    excursion ratios and the MPC's peak share without a module reloaded."""
    from mbcontrol.analysis import peak_share
    from mbcontrol.studies.design.envelope_gain import excursion_ratios
    excursions = {"float": {"relative_heave_significant": 2.0, "relative_heave_limit_m": 4.0,
                            "pitch_significant": 0.2}}
    assert peak_share() == 0.45
    assert excursion_ratios(excursions) == {"float relative heave": 0.5,
                                            "float pitch": 0.2 / (np.pi / 6)}
    with defaults.override(envelope_share=0.6, validity_draft_factor=2.0,
                           validity_angle_max=0.4):
        assert peak_share() == 0.3
        assert excursion_ratios(excursions) == {"float relative heave": 0.25,
                                                "float pitch": 0.5}
    assert peak_share() == 0.45


def test_the_cli_quiet_flag_sets_the_default_not_the_environment(monkeypatch):
    import os
    monkeypatch.delenv("TQDM_DISABLE", raising=False)
    assert main(["-q", "defaults"]) == 0
    assert "TQDM_DISABLE" not in os.environ and defaults.source("log.quiet") == "built-in"
