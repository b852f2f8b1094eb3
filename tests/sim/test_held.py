"""sim.held.HeldStepper: a Python controller's loop through zero-copy buffers gives the states
of the plain loop it replaced, written out here: at each period's start y = plant.h(...)
through CasADi's Python call, the controller's command, then integrators.run_fixed_step over
the period's steps (which pads a short last period to its own chunk length)."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers.latching import Latching
from mbcontrol.plant import build_plant
from mbcontrol.sim import integrators, simulate
from mbcontrol.sim.held import HeldStepper


def _latching(plant):
    controller = Latching(4.9181e4, 2.6, force_max=np.inf)
    controller.reset(plant)
    return controller


def _plain_loop(plant, controller, x0, W_nodes, p, dt, n, m):
    nu = len(plant.inputs)
    X, u = np.empty((n + 1, plant.nx)), np.zeros(nu)
    X[0] = x0
    for i in range(0, n, m):
        k = min(m, n - i)
        y = np.asarray(plant.h(X[i], u, W_nodes[i, 0], p)).ravel()
        u = np.asarray(controller(i * dt, y), float).reshape(nu)
        Xk, _ = integrators.run_fixed_step(plant, X[i], np.tile(u, (k, 1)), W_nodes[i:i + k],
                                           p, dt, "rk4")
        X[i + 1:i + k + 1] = Xk[1:]
    return X


@pytest.mark.parametrize("steps", [1, 3])
def test_held_stepper_is_the_plain_loop(steps):
    """Latching (a switching law: any change in the sampled outputs moves its latch times)
    on the sphere, 40 s, commands held over 1 and 3 steps; 40 s / dt is not a multiple of 3,
    so the last period is short. Same compiled step, same inputs: equal to round-off."""
    plant = build_plant("sphere")
    wave = waves.regular(2.5, 9.6664)
    dt, n = wave.period / 500, 2070
    W_nodes = integrators.excitation_at_nodes(plant, wave, n, dt,
                                              integrators.METHODS["rk4"].nodes)
    p = plant.params(pto__damping=0.0, pto__stiffness=0.0)
    x0 = plant.x0()
    reference = _plain_loop(plant, _latching(plant), x0, W_nodes, p, dt, n, steps)
    stepper = HeldStepper(plant, "rk4", steps, p, dt)
    controller = _latching(plant)
    X, u = np.empty_like(reference), np.zeros(len(plant.inputs))
    X[0] = x0
    for i in range(0, n, steps):
        k = min(steps, n - i)
        u = np.asarray(controller(i * dt, stepper.outputs(X[i], u, W_nodes[i, 0])), float)
        X[i + 1:i + k + 1] = stepper.advance(X[i], u, W_nodes[i:i + k])
    scale = np.abs(reference).max(axis=0) + 1e-300
    assert np.max(np.abs(X - reference) / scale) < 1e-12
    assert len(controller.holds[0]) >= 6                  # it latched: the test has teeth


def test_simulate_with_a_python_controller_uses_it():
    """simulate's loop and the plain loop agree on the whole record (a regular wave, 30 s)."""
    plant = build_plant("sphere")
    wave = waves.regular(2.5, 9.6664)
    dt = wave.period / 500
    ds = simulate(plant, wave, duration=30.0, dt=dt,
                  controller=Latching(4.9181e4, 2.6, force_max=np.inf))
    n = ds.sizes["time"] - 1
    W_nodes = integrators.excitation_at_nodes(plant, wave, n, dt,
                                              integrators.METHODS["rk4"].nodes)
    X = _plain_loop(plant, _latching(plant), plant.x0(), W_nodes,
                    plant.params(pto__damping=0.0, pto__stiffness=0.0), dt, n, 1)
    for j, name in enumerate(plant.states[:2]):            # heave and its rate
        np.testing.assert_allclose(ds[name].values, X[:, j], rtol=0,
                                   atol=1e-12 * np.abs(X[:, j]).max())


def test_more_steps_than_built_for_is_refused():
    plant = build_plant("sphere")
    stepper = HeldStepper(plant, "rk4", 2, plant.p0, 0.01)
    W = np.zeros((3, len(integrators.METHODS["rk4"].nodes), len(plant.disturbances)))
    with pytest.raises(ValueError, match="3 steps asked, built for 2"):
        stepper.advance(plant.x0(), np.zeros(len(plant.inputs)), W)
