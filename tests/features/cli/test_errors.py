"""What the command line does with an error: bad input (mbcontrol's own error types) is one
line naming what was wrong and exit status 1; anything else is a bug and keeps its
traceback, instead of being reported as bad input."""
import pytest

from mbcontrol import cli
from mbcontrol.cli import commands
from mbcontrol.errors import ControllerError, InputError, MbcontrolError, UnknownName, WaveError


@pytest.mark.parametrize("error", [ControllerError("mpc: dt_s = 0: expected > 0"),
                                   WaveError("--hs -1: expected a height >= 0"),
                                   InputError("--duration 0: expected > 0"),
                                   UnknownName("sphere: unknown parameter 'mass'; known: pto__damping")])
def test_bad_input_is_one_line_and_status_1(monkeypatch, capsys, error):
    def run(args):
        raise error
    monkeypatch.setattr(commands, "run_models", run)
    monkeypatch.setattr(cli, "run_models", run)
    assert cli.main(["models"]) == 1
    err = capsys.readouterr().err
    assert err == f"mbcontrol: error: {error.args[0]}\n"      # no quotes around a KeyError's text
    assert isinstance(error, MbcontrolError) and isinstance(error, (ValueError, KeyError))


@pytest.mark.parametrize("bug", [ValueError("shapes (3,) and (4,) not aligned"), KeyError("x")])
def test_a_bug_keeps_its_traceback(monkeypatch, bug):
    def run(args):
        raise bug
    monkeypatch.setattr(commands, "run_models", run)
    monkeypatch.setattr(cli, "run_models", run)
    with pytest.raises(type(bug)):
        cli.main(["models"])
