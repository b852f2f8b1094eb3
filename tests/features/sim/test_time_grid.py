"""The run covers the duration asked for (sim.methods.time_steps): a dt that does not divide it
ran short without a word (dt 4 s, duration 5 s ran 4 s); now it covers it and says so."""
import math

import pytest

from mbcontrol.errors import InputError
from mbcontrol.sim.methods import time_steps


def test_a_dividing_step_runs_exactly():
    assert time_steps(600.0, 0.05) == 12000        # 600 / 0.05 is 11999.999999999998
    assert time_steps(30 * 1.1, 0.011) == 3000


@pytest.mark.parametrize("duration, dt", [(5.0, 4.0), (35.0, 0.174), (24.0, 2 * math.sqrt(2))])
def test_a_step_that_does_not_divide_covers_the_duration_and_warns(duration, dt):
    with pytest.warns(RuntimeWarning, match="not a whole number of time steps"):
        n = time_steps(duration, dt)
    assert duration <= n * dt < duration + dt


@pytest.mark.parametrize("duration, dt, why", [
    (5.0, 6.0, "longer than the duration"), (0.0, 0.1, "duration > 0"),
    (10.0, -0.1, "dt > 0"), (math.inf, 0.1, "finite"), (10.0, math.nan, "finite")])
def test_an_impossible_grid_is_refused_naming_both_flags(duration, dt, why):
    with pytest.raises(InputError, match=why):
        time_steps(duration, dt)


def test_the_simulate_command_reports_the_time_simulated(capsys):
    import json

    from mbcontrol.cli import main
    # 100 / 0.3 = 333.3 steps: 334 of them, 100.2 s
    with pytest.warns(RuntimeWarning, match=r"simulating 100.2 s \(334 steps\)"):
        code = main(["simulate", "sphere", "--wave", "regular", "--height", "2", "--period",
                     "8", "--dt", "0.3", "--duration", "100", "--allow-invalid", "--json"])
    out, err = capsys.readouterr()
    assert code == 0 and json.loads(out)["duration_s"] == pytest.approx(100.2)
