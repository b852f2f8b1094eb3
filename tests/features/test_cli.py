"""The `mbcontrol` command: help, the catalogue, the --json contracts, and clear errors."""
import json

import pytest

from mbcontrol.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_help_explains_commands(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for command in ("models", "hydro", "simulate", "linearize", "design"):
        assert command in out


def test_models_lists_catalogue(capsys):
    code, out, _ = run(capsys, "models")
    assert code == 0 and "hinged_barge" in out and "hinged_raft" in out


def test_simulate_json_contract(capsys, tmp_path):
    nc = tmp_path / "run.nc"
    code, out, _ = run(capsys, "simulate", "hinged_barge", "--wave", "regular", "--height",
                       "0.02", "--period", "1.0", "--duration", "15", "--dt", "0.005",
                       "--out", str(nc), "--json")
    assert code == 0
    result = json.loads(out)
    assert set(result) >= {"model", "wave", "duration_s", "dt_s", "wall_time_s", "dofs",
                           "bodies", "ptos"}
    assert result["model"] == "hinged_barge" and result["wave"]["type"] == "regular"
    assert set(result["dofs"]) == {"pivot", "hinge"}
    assert set(result["dofs"]["hinge"]) == {"amplitude", "mean", "std", "max_abs"}
    assert {"heave_amplitude_m", "pitch_amplitude_rad"} <= set(result["bodies"]["barge2"])
    assert set(result["ptos"]["hinge_pto"]) >= {"mean_power_W", "mean_electrical_power_W",
                                                "max_force", "f98", "max_stroke", "z98", "papr"}
    assert result["ptos"]["hinge_pto"]["mean_power_W"] > 0       # a damper absorbs
    assert nc.exists()


def test_simulate_with_controller_and_irregular_sea(capsys):
    code, out, _ = run(capsys, "simulate", "hinged_raft", "--wave", "jonswap", "--hs", "0.03",
                       "--tp", "1.1", "--seed", "2", "--duration", "30", "--controller",
                       "passive", "--set", "damping=1.0", "--json")
    assert code == 0
    result = json.loads(out)
    assert result["wave"]["seed"] == 2 and result["wave"]["type"] == "jonswap"
    assert {"raft__Surge", "raft__Heave", "raft__Pitch", "hinge"} == set(result["dofs"])


def test_linearize_json_and_bode(capsys, tmp_path):
    png = tmp_path / "bode.png"
    code, out, _ = run(capsys, "linearize", "hinged_barge", "--bode", str(png), "--json")
    assert code == 0 and png.stat().st_size > 10_000
    info = json.loads(out)
    assert info["stable"] and "u__hinge_pto" in info["inputs"]


def test_errors_are_clear(capsys):
    code, _, err = run(capsys, "simulate", "no_such_model", "--height", "1", "--period", "5")
    assert code == 1 and "not a file and not a catalogue model" in err
    code, _, err = run(capsys, "simulate", "hinged_barge", "--wave", "regular")
    assert code == 1 and "--height and --period" in err
    code, _, err = run(capsys, "simulate", "hinged_barge", "--height", "0.02", "--period", "1",
                       "--controller", "passive", "--set", "damping")
    assert code == 1 and "KEY=VALUE" in err
    # text is taken only by a setting that is text (an MPC's forecast), not by a number
    code, _, err = run(capsys, "simulate", "hinged_barge", "--height", "0.02", "--period", "1",
                       "--controller", "passive", "--set", "damping=1.5x")
    assert code == 1 and "--set damping: expected a number, true/false or none, got '1.5x'" in err
    # booleans and none parse as such (an MPC's soft_stroke, a limit left to the scene)
    # (60 s: the settings are parsed and described; too short to be valid, as it says)
    code, out, err = run(capsys, "simulate", "sphere", "--wave", "jonswap", "--hs", "1",
                         "--tp", "8", "--duration", "60", "--dt", "0.1", "--controller", "mpc",
                         "--set", "soft_stroke=false", "--set", "force_max=none",
                         "--set", "forecast=model", "--json", "--allow-invalid")
    assert code == 0, err
    assert "fewer than the 10" in json.loads(out)["invalid_reasons"][0]
    described = json.loads(out)["controller"]
    assert described["soft_stroke"] is False and described["forecast"] == "model"


def test_design_text_prints_parameters_margins_bounds_and_rerun(capsys):
    code, out, _ = run(capsys, "design", "sphere", "--controller", "reactive", "--wave", "regular",
                       "--height", "2.5", "--period", "9.6664", "--unconstrained", "--bounds", "off",
                       "--aggressive")       # complex-conjugate control, not the margins
    assert code == 0
    assert "damping = " in out and "stiffness = " in out and "force_max = inf" in out
    assert "stable closed loop" in out and "gain margin 1.344 at 0 rad/s" in out
    assert "re-run: mbcontrol simulate sphere --wave regular --height 2.5 --period 9.6664" in out
    assert "--controller reactive --set damping=" in out
    # duration and step without float noise (30 periods of 9.6664 s: 289.992 s)
    rerun = next(line for line in out.splitlines() if "re-run:" in line).split()
    assert rerun[rerun.index("--duration") + 1] == "289.992"


def test_design_errors_are_clear(capsys):
    code, _, err = run(capsys, "design", "sphere", "--controller", "latching", "--wave", "jonswap",
                       "--hs", "2", "--tp", "8")
    assert code == 1 and "design 'latching'" in err and "regular wave" in err
    code, _, err = run(capsys, "design", "sphere", "--controller", "pid", "--height", "2",
                       "--period", "8")
    assert code == 1 and "unknown controller 'pid'" in err and "passive, reactive" in err
    code, _, err = run(capsys, "design", "sphere", "--controller", "passive", "--wave", "none")
    assert code == 1 and "design needs a wave" in err


@pytest.mark.parametrize("model", ["rm3", "sphere", "wavestar"])
def test_simulate_issue3_models(capsys, model):
    """Issue 3: `mbcontrol simulate MODEL --wave regular --height 2.5 --period 8 --json`
    (the tank-scale wavestar in a proportionate wave of its own band)."""
    height, period = ("0.0625", "1.412") if model == "wavestar" else ("2.5", "8")
    code, out, _ = run(capsys, "simulate", model, "--wave", "regular", "--height", height,
                       "--period", period, "--duration", "100", "--json")   # 2 T ramp + 10 T
    assert code == 0
    result = json.loads(out)
    pto = next(iter(result["ptos"].values()))
    assert pto["mean_power_W"] > 0 and pto["max_stroke"] > 0       # a damper absorbs


@pytest.mark.parametrize("model, scene_param", [("raft3", None), ("array4", None), ("flap_pair", None),
                                                ("barge_chain", None), ("barge_chain", "N=2")])
@pytest.mark.parametrize("sea", ["regular", "jonswap"])
def test_simulate_issue4_models(capsys, model, scene_param, sea):
    """Issue 4: every new catalogue model runs from the CLI in regular and irregular waves
    (tank scale: H 4 cm, T 1.2 s; Hs 4 cm, Tp 1.2 s; 2.5 s for the flaps), every PTO absorbing."""
    period = "2.5" if model == "flap_pair" else "1.2"      # FOSWEC-like seas are longer
    wave = ["--height", "0.04", "--period", period] if sea == "regular" else ["--hs", "0.04", "--tp", period]
    extra = ["--scene-param", scene_param] if scene_param else []
    code, out, _ = run(capsys, "simulate", model, "--wave", sea, *wave, "--duration", "30", "--json", *extra)
    assert code == 0
    result = json.loads(out)
    assert len(result["ptos"]) == {"raft3": 2, "array4": 4, "flap_pair": 2}.get(
        model, 1 if scene_param == "N=2" else 3)
    for pto in result["ptos"].values():
        assert pto["mean_power_W"] > 0 and pto["max_stroke"] > 0


def test_fidelity_command_reports_the_choice(capsys, tmp_path):
    code, out, _ = run(capsys, "fidelity", "sphere", "--wave", "jonswap", "--hs", "2.5",
                       "--tp", "9.67", "--tol", "0.01", "--duration", "120",
                       "--out", str(tmp_path / "fidelity.nc"))
    assert code == 0 and "fidelity for sphere" in out and "chosen" in out
    assert (tmp_path / "fidelity.nc").stat().st_size > 0


def test_first_use_messages_name_the_file_and_the_settings(capsys, tmp_path):
    garbage = tmp_path / "garbage.toml"
    garbage.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe binary")
    code, _, err = run(capsys, "simulate", str(garbage), "--height", "1", "--period", "5")
    assert code == 1 and str(garbage) in err and "not a text scene file" in err
    assert "codec" not in err
    code, _, err = run(capsys, "simulate", "hinged_barge", "--height", "0.02", "--period", "1",
                       "--controller", "passive", "--set", "dampin=3")
    assert code == 1 and "has no setting 'dampin'" in err
    assert "damping, period, force_max" in err and "__init__" not in err


def test_simulate_warns_of_an_unstable_sampled_loop_and_exits_3(capsys):
    # flap_pair's reactive law held over 0.1 s: the spring's hold removes more damping than
    # the law adds (tests/controllers/test_sampled.py has the discrete-time reference)
    with pytest.warns(RuntimeWarning, match="sampled at 0.1 s .*UNSTABLE"):
        code, out, err = run(capsys, "simulate", "flap_pair", "--wave", "regular", "--height",
                             "0.01", "--period", "2.5", "--duration", "20", "--dt", "0.005",
                             "--controller", "reactive", "--set", "damping=4.872", "--set",
                             "stiffness=234.4", "--set", "period=0.1", "--json")
    assert code == 3
    assert json.loads(out)["valid"] is False and "sampled control loop" in err


def test_the_toolboxs_warnings_read_as_sentences():
    import os

    from mbcontrol.cli.messages import format_warning
    ours = os.path.join(os.sep, "x", "mbcontrol", "cli", "commands.py")
    assert format_warning("it diverges", RuntimeWarning, ours, 95) == \
        "mbcontrol: warning: it diverges\n"
    theirs = os.path.join(os.sep, "x", "numpy", "lib.py")
    assert "RuntimeWarning" in format_warning("overflow", RuntimeWarning, theirs, 1)


def test_a_warning_raised_from_two_places_is_said_once(capsys):
    """Issue 58: the same warning from two places (a plant built twice, a fit read back) was
    printed twice; a command says it once, and the next command says it again."""
    import warnings

    from mbcontrol.cli import main
    from mbcontrol.cli.messages import said_once
    said = []
    show = said_once(lambda message, *rest, **kw: said.append(str(message)))
    for line in (10, 20, 30):
        show(RuntimeWarning("the fit misses its tolerance"), RuntimeWarning, "store.py", line)
    show(RuntimeWarning("another"), RuntimeWarning, "store.py", 10)
    assert said == ["the fit misses its tolerance", "another"]
    before = warnings.showwarning
    with pytest.raises(SystemExit):
        main(["--version"])
    assert warnings.showwarning is before              # the caller's hook comes back


def test_version_and_python_m(capsys):
    import subprocess
    import sys
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.startswith("mbcontrol 0.")
    out = subprocess.run([sys.executable, "-m", "mbcontrol", "models"], capture_output=True,
                         text=True, check=True).stdout
    assert "sphere" in out and "rm3" in out


def test_models_name_describes_parameters_units_and_controllers(capsys):
    """`models NAME` lists what can be set: plant parameters with defaults and units (checked
    against the scene's own values), and every registered controller with its settings."""
    import inspect

    from mbcontrol.controllers import REGISTRY
    assert main(["models", "flume_section", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    p = info["parameters"]
    assert p["sway_rig__viscous"] == {"default": 8.7, "unit": "N s/m"}
    assert p["roll_rig__viscous"]["unit"] == "N m s/rad"
    assert p["viscous__Roll"]["unit"] == "N m s^2/rad^2"
    assert p["sway_springs__stiffness_y"] == {"default": 60.0, "unit": "N/m"}
    assert all(v["unit"] for v in p.values()), p
    assert set(info["controllers"]) == set(REGISTRY)
    assert list(info["controllers"]["reactive"]) == list(inspect.signature(REGISTRY["reactive"]).parameters)
    assert info["scene_parameters"] == {"sway_extra_mass": 0.0, "axle_mass": 0.05}
    assert main(["models", "sphere"]) == 0
    text = capsys.readouterr().out
    assert "pto__damping" in text and "N s/m" in text and "force_max 2e+06 N, stroke_max 4 m" in text


@pytest.mark.parametrize("command", ["simulate", "design"])
def test_help_names_every_registered_controller(capsys, command):
    from mbcontrol.controllers import REGISTRY
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = capsys.readouterr().out
    assert all(name in text for name in REGISTRY), text


def test_simulate_text_gives_units(capsys):
    code, out, err = run(capsys, "simulate", "hinged_barge", "--wave", "regular", "--height",
                         "0.02", "--period", "1.0", "--duration", "12")   # 2 T ramp + 10 T
    assert code == 0, err
    line = next(l for l in out.splitlines() if "hinge_pto:" in l)
    assert " W, max force " in line and " N m, max stroke " in line and line.endswith(" rad")


def test_quiet_and_verbose(tmp_path):
    """Status lines go through the 'mbcontrol' logger: shown by default (a cold cache
    compiles), hidden by -q along with the progress bars; -v is accepted."""
    import os
    import subprocess
    import sys
    args = ["simulate", "sphere", "--height", "1", "--period", "8", "--duration", "96"]

    def stderr(*flags, cache):
        env = {**os.environ, "MBCONTROL_CACHE": str(tmp_path / cache)}
        env.pop("MBCONTROL_QUIET", None)
        return subprocess.run([sys.executable, "-m", "mbcontrol", *flags, *args], env=env,
                              capture_output=True, text=True, check=True).stderr

    assert "mbcontrol: compiling sphere: 512 rk4 steps per call" in stderr(cache="a")
    quiet = stderr("-q", cache="b")
    assert "compiling" not in quiet and "step/s" not in quiet
    assert "mbcontrol: compiling sphere: 512 rk4 steps per call" in stderr("-v", cache="c")
