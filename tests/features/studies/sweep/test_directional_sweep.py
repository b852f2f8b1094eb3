"""Sweeps over short-crested seas: a seas file's direction and spread (or --spread for all) reach
each case's wave, the spectral path reports the expected power weighted over directions, and a
long-crested sea keeps the case key it had before seas carried a direction."""
import json
import math

import pytest

from mbcontrol.cli import main
from mbcontrol.studies.sweep import sweep
from mbcontrol.studies.sweep.cases import Case
from mbcontrol.studies.sweep.runner import sea_wave
from mbcontrol.studies.sweep.spectral import expected_power
from mbcontrol.waves import SeaState, read_seas


def test_long_crested_case_keeps_its_key():
    # the key /work/main computed for this case before SeaState had direction and spread
    # (commit 6809f9e): stores made then are still found
    case = Case("oswec", SeaState(1.5, 9.0, 3.3, 0.25), 0, (), (0, 0), duration=300.0,
                dt=0.05, method="rk4")
    assert case.key == "e1bb5335513cd24b9af6"
    spread = Case("oswec", SeaState(1.5, 9.0, 3.3, 0.25, spread=0.5), 0, (), (0, 0),
                  duration=300.0, dt=0.05, method="rk4")
    assert spread.key != case.key


def test_seas_file_spread_reaches_the_wave_and_the_spectral_power(tmp_path):
    path = tmp_path / "seas.csv"
    path.write_text("Hm0,Tp,weights,direction,spread\n1.0,9.0,0.6,15,30\n1.0,9.0,0.4,0,0\n")
    seas = read_seas(path)
    ds, result = sweep("oswec", seas, workers=0, duration=200.0, dt=0.1, controller="passive",
                       settings={"damping": 3e6}, progress=False)
    rows = result["seas"]
    assert rows[0]["spread_deg"] == pytest.approx(30.0) and rows[0]["direction_deg"] == \
        pytest.approx(15.0) and rows[0]["spreading"] == "cos2s"
    from mbcontrol.plant import build_plant
    plant = build_plant("oswec")
    wave = sea_wave(plant, seas[0], 200.0)
    assert wave.directional and wave.settings["mean_direction_rad"] == pytest.approx(
        math.radians(15.0)) and wave.settings["sector_rad"] == pytest.approx(math.pi)
    # the row's expected power is the spread sea's, weighted over directions
    # (directional.spread_power), not the realisation's nor the long-crested one
    assert rows[0]["expected_power_W"] == pytest.approx(
        expected_power(plant, wave, {"pto": (3e6, 0.0)}), rel=1e-9)
    # the same sea long-crested (row 2 has spread 0) absorbs more: the flap turned from the
    # waves by 15 deg on average, spread 30 deg, sees a smaller surge excitation (~0.8)
    assert rows[1]["expected_power_W"] > 1.1 * rows[0]["expected_power_W"]
    # and so do the simulated records (200 s after the ramp: one record's scatter, 5 %, is
    # well below the 30 % the spread takes)
    assert rows[1]["mean_power_W"] > 1.1 * rows[0]["mean_power_W"]


def test_cli_spread_for_every_sea_and_its_limits(capsys):
    code = main(["sweep", "oswec", "--hs", "1.0", "--tp", "9", "--duration", "200",
                 "--dt", "0.1", "--workers", "0", "--spread", "25", "--spreading", "mitsuyasu",
                 "--controller", "passive", "--set", "damping=3e6", "--json"])
    assert code == 0
    row = json.loads(capsys.readouterr().out)["seas"][0]
    assert row["spread_deg"] == pytest.approx(25.0) and row["spreading"] == "mitsuyasu"
    assert main(["sweep", "oswec", "--hs", "1.0", "--tp", "9", "--spread", "85",
                 "--workers", "0"]) != 0
    assert "--spread 85: expected a directional spread sigma" in capsys.readouterr().err
