"""Batch runs: many seas and parameter sets in one compiled call give what one run each gives."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate, simulate_batch


@pytest.mark.parametrize("method", ["rk4", "exp-rk4"])
def test_batch_equals_separate_runs(method):
    plant = build_plant("rm3")
    seas = [waves.irregular(hs, tp, seed=s, duration=60) for hs, tp, s in
            ((1.0, 7.0, 1), (2.5, 8.0, 2), (3.0, 10.0, 3))]
    pto = plant.scene.ptos[0].name
    params = [{f"{pto}__damping": d} for d in (5e5, 1.2e6, 3e6)]
    batch = simulate_batch(plant, seas, params, duration=60, dt=0.1, method=method)
    assert batch.sizes["case"] == 3
    for c in range(3):
        one = simulate(plant, seas[c], duration=60, dt=0.1, method=method, params=params[c])
        for name in ("float__Heave", f"{pto}__power"):
            ref = one[name].values
            # the same arithmetic in another compiled function: equal to rounding
            assert np.allclose(batch[name].values[c], ref, rtol=1e-9,
                               atol=1e-9 * np.abs(ref).max()), (c, name)


def test_batch_shares_a_single_wave_and_rejects_mismatched_lists():
    plant = build_plant("sphere")
    sea = waves.regular(2.0, 8.0)
    ds = simulate_batch(plant, sea, [{"pto__damping": d} for d in (1e5, 4e5)], duration=20,
                        dt=0.05)
    power = ds["pto__power"].values[:, ds.time.values > 10].mean(axis=1)
    assert power[0] != power[1]
    with pytest.raises(ValueError, match="expected 1 or 3"):
        simulate_batch(plant, [sea, sea], [{}, {}, {}], duration=1, dt=0.1)
