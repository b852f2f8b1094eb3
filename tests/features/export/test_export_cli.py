"""`mbcontrol export`: the issue's two commands, their JSON contract, their FMUs accepted by
fmpy's validator and co-simulated by fmpy against the Python run."""
import json
from pathlib import Path

import pytest

from mbcontrol.cli import main

fmpy = pytest.importorskip("fmpy")
from fmpy.validation import validate_fmu  # noqa: E402


@pytest.mark.parametrize("controller", ["reactive", "mpc"])
def test_export_sphere_json_contract_and_checks(controller, tmp_path, capsys):
    code = main(["export", "sphere", "--controller", controller, "--wave", "jonswap", "--hs", "2",
                 "--tp", "9", "--duration", "120", "--out", str(tmp_path), "--json"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert set(report) >= {"fmus", "c_library", "closed_loop_check", "step_time_us"}
    assert set(report["step_time_us"]) >= {"median", "p99", "max"}
    assert set(report["closed_loop_check"]) >= {"max_rel_force_error", "mean_power_rel_error"}
    for path in report["fmus"].values():
        assert Path(path).is_file() and validate_fmu(path) == []
    assert Path(report["c_library"]).is_file()
    check = report["closed_loop_check"]
    assert check["max_rel_force_error"] <= 1e-6 and check["mean_power_rel_error"] <= 1e-6
    assert check["fmu"]["max_rel_force_error"] <= 1e-6      # fmpy ran both FMUs
    assert report["origin"] == "designed"                   # tuned as `design` tunes it
    # the compared run's physics verdict travels with it: the reactive run holds; the MPC
    # drives the sphere's relative heave past its draft (4.8 m against 3.3 m, as `design`
    # would say too), so its mean power is marked, while the export still matches it
    assert check["python_run_valid"] is (controller == "reactive")
    assert bool(check["python_run_invalid_reasons"]) is (controller == "mpc")
    assert report["step_time_us"]["median"] > 0


def test_export_refuses_nmpc_with_the_reason(tmp_path, capsys):
    code = main(["export", "sphere", "--controller", "nmpc", "--wave", "regular", "--height",
                 "1", "--period", "8", "--set", "horizon_s=8", "--out", str(tmp_path)])
    assert code != 0 and "IPOPT" in capsys.readouterr().err
