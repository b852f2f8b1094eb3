"""Runs without a Dataset (`sim.light`): the same outputs as `simulate` to rounding, the
excitation from one inverse FFT equal to one FFT per node, the same guards."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.errors import SimulationError
from mbcontrol.plant import build_plant
from mbcontrol.sim import integrators, light, simulate
from mbcontrol.sim.record import _versions


def _sea(plant, hs, tp, seed, duration):
    omega = plant.hydro.omega
    return waves.irregular(hs, tp, seed=seed, duration=duration,
                           data_band=(float(omega[0]), float(omega[-1])))


@pytest.mark.parametrize("method", ["rk4", "exp-rk4", "dopri5"])
def test_arrays_equal_simulate(method):
    plant = build_plant("rm3")
    wave = _sea(plant, 2.0, 9.0, 3, 200.0)
    params = {"pto__damping": 8e5}
    ds = simulate(plant, wave, duration=200.0, dt=0.05, method=method, params=params)
    run = light.simulate_arrays(plant, wave, duration=200.0, dt=0.05, method=method,
                                params=params)
    assert np.array_equal(run["time"].values, ds["time"].values)
    assert set(run.data_vars) == set(plant.outputs)
    for name in plant.outputs:
        ref = ds[name].values
        assert np.allclose(run[name].values, ref, rtol=1e-9,
                           atol=1e-9 * max(np.abs(ref).max(), 1e-30)), name
    for key in ("model", "method", "dt_s", "duration_s", "wave", "parameters"):
        assert run.attrs[key] == ds.attrs[key], key


@pytest.mark.parametrize("method", ["rk4", "rk3", "exp-rk4", "dopri5"])
@pytest.mark.parametrize("tp,duration", [(8.0, 3600.0), (11.0, 100.0), (7.0, 140.0)])
def test_one_inverse_fft_equals_an_fft_per_node(method, tp, duration):
    # 100 s of an 11 s sea repeats after 220 s (20 Tp); 140 s of a 7 s sea after exactly the
    # record: its last node wraps around to the first sample
    plant = build_plant("rm3")
    wave = _sea(plant, 2.5, tp, 1, duration)
    dt = 0.05
    n = int(round(duration / dt))
    nodes = integrators.method(method).nodes
    ref = integrators.excitation_at_nodes(plant, wave, n, dt, nodes)
    got = light.excitation_at_nodes(plant, wave, n, dt, nodes)
    assert got.shape == ref.shape
    assert np.abs(got - ref).max() <= 1e-12 * np.abs(ref).max()


def test_regular_waves_and_still_water_fall_back():
    plant = build_plant("sphere")
    nodes = integrators.method("rk4").nodes
    wave = waves.regular(1.0, 8.0)
    assert np.array_equal(light.excitation_at_nodes(plant, wave, 400, 0.05, nodes),
                          integrators.excitation_at_nodes(plant, wave, 400, 0.05, nodes))
    run = light.simulate_arrays(plant, None, duration=10.0, dt=0.05)
    assert np.all(run["excitation_power"].values == 0.0)


def test_a_diverging_run_raises_as_simulate_does():
    plant = build_plant("rm3")
    wave = _sea(plant, 2.0, 9.0, 0, 300.0)
    with pytest.raises(SimulationError):
        simulate(plant, wave, duration=300.0, dt=1.0)
    with pytest.raises(SimulationError, match="diverged"):
        light.simulate_arrays(plant, wave, duration=300.0, dt=1.0)


def test_can_run_only_open_loop_fixed_step():
    plant = build_plant("sphere")
    assert light.can_run(plant, None, "rk4")
    assert not light.can_run(plant, None, "cvodes")
    assert not light.can_run(plant, object(), "rk4")


def test_versions_are_looked_up_once_and_handed_out_as_copies():
    first = _versions()
    first["numpy"] = "changed"
    assert _versions()["numpy"] != "changed"
    assert _versions() == _versions() and "python" in _versions()
