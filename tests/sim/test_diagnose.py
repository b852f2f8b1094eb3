"""Divergence diagnosis (mbcontrol.sim.diagnose): an unstable closed loop is named as the
cause, with its pole; a step too large for the integrator is still blamed on the step."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers import make
from mbcontrol.controllers.impedance import closed_loop_stability
from mbcontrol.errors import SimulationError
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate
from mbcontrol.sim.diagnose import closed_loop_poles, unstable

from tests.helpers.kernel_fits import judged_by_kernel


@pytest.fixture(scope="module")
def rm3():
    return build_plant("rm3")


def test_unstable_reactive_loop_is_named_not_the_step(rm3):
    """rm3 with u = -(1e6 v - 3.1e6 x): the negative spring beats the float's relative
    restoring and the loop is unstable. The error names the controller and the pole; the
    pole is python-control's on the linearised plant (controllers.impedance, an independent
    path: +0.72560 1/s both ways; the message prints 4 significant digits, hence 1e-4), and
    no smaller dt is recommended (the old message's remedy)."""
    stable, margin = closed_loop_stability(rm3, 1e6, -3.1e6)
    assert not stable
    band = (float(rm3.hydro.omega[0]), float(rm3.hydro.omega[-1]))
    wave = waves.from_args("jonswap", hs=2.0, tp=9.0, seed=0, data_band=band, duration=120.0)
    with pytest.raises(SimulationError) as info:
        simulate(rm3, wave, duration=120.0, dt=0.05,
                 controller=make("reactive", damping=1e6, stiffness=-3.1e6))
    message = str(info.value)
    assert "closed loop with controller 'reactive' is unstable" in message
    assert "smaller dt" not in message
    pole = float(message.split("pole at ")[1].split(" ")[0])
    assert pole == pytest.approx(-margin, rel=1e-4)


def test_closed_loop_poles_of_a_stable_damper_are_stable(rm3):
    """The same Jacobian path with a damper alone (1.2e6 N s/m): no pole in the right
    half-plane, and the loop's slowest decay equals python-control's margin (round-off)."""
    law = make("reactive", damping=1.2e6, stiffness=0.0)
    law.reset(rm3)
    p = rm3.params(pto__damping=0.0, pto__stiffness=0.0)
    closed, open_ = closed_loop_poles(rm3, law.casadi_law(rm3), p)
    assert unstable(closed).size == 0 and unstable(open_).size == 0
    margin = closed_loop_stability(rm3, 1.2e6, 0.0)[1]
    assert -np.max(closed.real) == pytest.approx(margin, rel=1e-6)


def test_a_step_too_large_is_still_blamed_on_the_step():
    """The kernel-judged sphere fit's fastest radiation pole (-16.7 1/s) makes RK4 unstable at
    dt = 0.2 s (|lambda dt| > 2.78) under a stable damper: the linear check finds the loop stable
    and the rerun at 0.1 s does not diverge, so the remedy stays a smaller dt."""
    sphere = build_plant(judged_by_kernel("sphere"))
    with pytest.raises(SimulationError, match="smaller dt") as info:
        simulate(sphere, waves.regular(1.0, 8.0), duration=60.0, dt=0.2,
                 controller=make("passive", damping=5e5))
    assert "closed loop" not in str(info.value)
