"""A measured elevation record from the command line: `mbcontrol simulate SCENE --wave
elevation --eta FILE` (mbcontrol.waves.from_record) runs, its JSON names the record (file,
hash, samples) and its numbers are those of the same wave simulated in Python; its default
duration is the record's; `design` takes the record and prints a re-run command that
reproduces its simulation; --wave elevation without --eta (or --eta with another wave) is a
usage error, exit 2, found before any model is built; a malformed file is bad input, exit 1,
one line naming the file and the line."""
import dataclasses
import hashlib
import json

import numpy as np
import pytest

from mbcontrol.cli import commands, main
from mbcontrol.waves import from_record, irregular

SHIPPED = "tests/waves/data/sphere_record.csv"


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """120 s of a JONSWAP sea (Hs 0.5 m, Tp 4 s) at 4 Hz, a header and a comment: 4 s so that a
    60 s run holds, after its ramp (2 Tz, 6.3 s), 13 peak periods, over the 10 a sea's
    statistics need (stats.min_periods)."""
    sea = dataclasses.replace(irregular(0.5, 4.0, seed=11, duration=120.0), ramp_time=0.0)
    t = np.arange(480) * 0.25
    path = tmp_path_factory.mktemp("record") / "probe.csv"
    path.write_text("# wave probe at the origin\ntime_s, eta_m\n" + "".join(
        f"{a:.2f}, {b:.6f}\n" for a, b in zip(t, sea.elevation(t))))
    return path


def test_simulate_runs_a_record_and_reports_it(record, capsys):
    code = main(["simulate", "sphere", "--wave", "elevation", "--eta", str(record),
                 "--duration", "60", "--dt", "0.01", "--json"])
    captured = capsys.readouterr()
    result = json.loads(captured.out)
    assert code == 0 and result["valid"], result["invalid_reasons"]
    wave = result["wave"]
    assert wave["type"] == "record" and wave["source"] == "probe.csv"
    assert wave["sha256"] == hashlib.sha256(record.read_bytes()).hexdigest()
    assert (wave["samples"], wave["dt_s"], wave["duration_s"]) == (480, 0.25, 120.0)
    assert result["duration_s"] == 60.0
    # the record starts mid-sea: ramped over 2 Tz, and the note says so on stderr
    assert wave["ramp_s"] > 0 and "does not start at rest" in captured.err
    # the CLI built the wave Python builds from the file with the hydro data's band (the
    # sphere's 0.05..12 rad/s): the same heave to round-off
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    plant = build_plant("sphere")
    band = (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))
    ds = simulate(plant, from_record(record, data_band=band), duration=60.0, dt=0.01)
    window = ds["heave"].where(ds["time"] >= result["window_start_s"], drop=True)
    assert result["dofs"]["heave"]["std"] == pytest.approx(float(window.std()), rel=1e-12)


def test_a_record_runs_its_own_length_by_default_and_repeats_when_asked(capsys):
    assert main(["simulate", "sphere", "--wave", "elevation", "--eta", SHIPPED, "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["duration_s"] == 300.0      # 1500 samples at 0.2 s
    assert "repeats" not in captured.err
    assert main(["simulate", "sphere", "--wave", "elevation", "--eta", SHIPPED,
                 "--duration", "450", "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["wave"]["repeats"] == 1.5
    assert "the record repeats 1.5 times" in captured.err


def test_design_takes_a_record_and_its_rerun_reproduces_it(tmp_path, capsys):
    """On the OSWEC, whose BEM data hold radiation damping over their whole band (the sphere's
    WAMIT file has none above 11.6 rad/s, where a record's noise makes the bound infinite)."""
    sea = dataclasses.replace(irregular(1.0, 10.0, seed=2, duration=200.0), ramp_time=0.0)
    t = np.arange(800) * 0.25
    path = tmp_path / "oswec.txt"
    path.write_text("".join(f"{a:.2f} {b:.5f}\n" for a, b in zip(t, sea.elevation(t))))
    assert main(["design", "oswec", "--controller", "passive", "--wave", "elevation",
                 "--eta", str(path), "--bounds", "off", "--json"]) == 0
    designed = json.loads(capsys.readouterr().out)
    assert designed["wave"]["type"] == "record" and designed["wave"]["source"] == "oswec.txt"
    command = designed["simulate_command"].split()
    assert command[3:7] == ["--wave", "elevation", "--eta", str(path)] and "--repeat" not in command
    assert main(command[1:] + ["--json"]) == 0
    again = json.loads(capsys.readouterr().out)
    # the same wave, steps and law, its damping printed to 6 digits (a relative change of at
    # most 5e-6, to which the power near its optimum is insensitive): measured 9e-10
    assert again["ptos"]["pto"]["mean_power_W"] == pytest.approx(
        designed["metrics"]["mean_power_W"], rel=1e-6)


@pytest.mark.parametrize("words, says", [
    (["simulate", "sphere", "--wave", "elevation"], "--wave elevation needs --eta FILE"),
    (["design", "sphere", "--controller", "passive", "--wave", "elevation"],
     "--wave elevation needs --eta FILE"),
    (["simulate", "sphere", "--eta", SHIPPED], "expected --wave elevation, got --wave regular"),
    (["simulate", "sphere", "--wave", "jonswap", "--hs", "1", "--tp", "8", "--eta", SHIPPED],
     "expected --wave elevation, got --wave jonswap"),
    (["simulate", "sphere", "--wave", "elevation", "--eta", SHIPPED, "--repeat", "100"],
     "--repeat does not apply to --wave elevation"),
    (["codesign", "wavebot", "--vary", "r2=0.2,0.3", "--wave", "elevation", "--eta", SHIPPED],
     "codesign rebuilds its wave per case"),
], ids=["simulate without --eta", "design without --eta", "--eta with the default wave",
        "--eta with jonswap", "--repeat", "codesign"])
def test_a_record_flag_out_of_place_is_a_usage_error(words, says, capsys, monkeypatch):
    def no_model(*args, **kwargs):
        raise AssertionError("a usage error is found before any model is built")
    monkeypatch.setattr(commands, "_plant", no_model)
    with pytest.raises(SystemExit) as stop:
        main(words)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and says in err and "usage:" in err, err


def test_a_malformed_record_is_bad_input_named_in_one_line(tmp_path, capsys):
    path = tmp_path / "probe.csv"
    lines = open(SHIPPED).read().splitlines()
    lines[9] = "1.2, 0.0l2"                  # line 10: a typed letter l for a digit 1
    path.write_text("\n".join(lines) + "\n")
    assert main(["simulate", "sphere", "--wave", "elevation", "--eta", str(path)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"mbcontrol: error: {path}: line 10, column 2")
    assert "'0.0l2' is not a number" in err
