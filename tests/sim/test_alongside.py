"""The outputs evaluated on a second core while a run steps (mbcontrol.sim.alongside).

Reference: `integrators.outputs` on the run's own states, inputs and excitation, after the
run (the plain, sequential pass): the outputs a run returns must be those, to the bit (the
same compiled map over the same blocks), with the worker (forced here: the sphere's linear
outputs are too cheap to start one), without it, and on one core. A run that fails mid-way
must leave no worker thread behind.
"""
import threading

import numpy as np
import pytest

from mbcontrol import sim, waves
from mbcontrol.errors import SimulationError
from mbcontrol.plant import build_plant
from mbcontrol.sim import alongside, integrators

SEA = waves.irregular(2.0, 8.0, seed=4, duration=30.0)


@pytest.fixture(scope="module")
def plant():
    return build_plant("sphere")


def _rerun_outputs(plant, ds):
    X = ds["state"].values
    U = np.column_stack([ds[name].values for name in plant.inputs])
    W = np.column_stack([ds[name].values for name in plant.disturbances])
    return integrators.outputs(plant, X, U, W, plant.p0)


@pytest.mark.parametrize("cores, worth", [(2, 0.0), (2, 1.0), (1, 0.0)])
def test_outputs_alongside_are_the_sequential_outputs(plant, monkeypatch, cores, worth):
    monkeypatch.setattr(alongside, "_cores", lambda: cores)
    monkeypatch.setattr(alongside, "WORKER_BLOCK_S", worth)
    ds = sim.simulate(plant, SEA, duration=30.0, dt=0.01)      # 3,001 samples: 6 blocks
    Y = np.column_stack([ds[name].values for name in plant.outputs])
    np.testing.assert_array_equal(Y, _rerun_outputs(plant, ds))


def test_the_worker_takes_the_finished_blocks_when_they_are_costly(plant, monkeypatch):
    monkeypatch.setattr(alongside, "_cores", lambda: 2)
    n = 2000
    rng = np.random.default_rng(1)
    X = rng.normal(size=(n + 1, plant.nx)) * 0.1
    U = np.zeros((n + 1, len(plant.inputs)))
    W = rng.normal(size=(n + 1, len(plant.disturbances))) * 1e4
    expected = integrators.outputs(plant, X, U, W, plant.p0)
    cheap = alongside.OutputsAlongside(plant, n + 1, plant.p0)
    cheap.advance(1100, X, U, W)         # the first block, timed: 50 us, no worker
    assert cheap._pool is None and cheap._done == 512
    np.testing.assert_array_equal(cheap.finish(X, U, W), expected)
    monkeypatch.setattr(alongside, "WORKER_BLOCK_S", 0.0)
    costly = alongside.OutputsAlongside(plant, n + 1, plant.p0)
    costly.advance(1100, X, U, W)        # rows below 1,100 final: block 0 here, block 1 there
    assert costly._pool is not None and len(costly._futures) == 1
    np.testing.assert_array_equal(costly.finish(X, U, W), expected)


def test_a_failed_run_leaves_no_worker(plant):
    before = {t.name for t in threading.enumerate()}
    params = plant.params(pto__damping=-5.0e6)                 # negative damping: it grows
    with pytest.raises(SimulationError):
        sim.simulate(plant, SEA, duration=30.0, dt=0.01, params=params)
    after = {t.name for t in threading.enumerate() if t.name.startswith("mbcontrol-outputs")}
    assert not (after - before)
