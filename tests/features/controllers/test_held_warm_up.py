"""The MPC's warm-up damper held over its period (controllers.sampled.held_dampers): the cause
of rm3's causal-MPC divergences in 17 of 32 PacWave seas (every Tp from 11.3 s up), and its fix.

References: the sampled loop's verdict from sampled_closed_loop (its own linearisation and
closed-loop map, not held_dampers' code), and the nonlinear closed-loop simulation itself."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis import summary
from mbcontrol.controllers import make
from mbcontrol.controllers.passive import optimal_damping
from mbcontrol.controllers.sampled import HELD_DECAY_SHARE, held_dampers, sampled_closed_loop
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate


@pytest.fixture(scope="module")
def rm3():
    return build_plant("rm3")


def _sea(plant, hs, tp):
    om = plant.hydro.omega
    return waves.irregular(hs, tp, gamma=3.3, seed=0, duration=200.0,
                           data_band=(float(om[0]), float(om[-1])))


def test_the_sea_tuned_damper_held_over_the_mpc_period_is_unstable(rm3):
    """The issue's sea (Hs 2.64 m, Tp 12.58 s): the damper linear theory tunes for it
    (measured 40.7 MN s/m) is stable in continuous time and unstable held over 0.2 s;
    held_dampers scales it to a damper whose held loop is stable and keeps its share of the
    continuous decay rate, and no more than needed (1.1 x it is not acceptable)."""
    c = optimal_damping(rm3, _sea(rm3, 2.64, 12.58), pto="pto")[0]
    assert sampled_closed_loop(rm3, {"pto": (c, 0.0)}, None).stable
    assert not sampled_closed_loop(rm3, {"pto": (c, 0.0)}, 0.2).stable
    held, factor = held_dampers(rm3, {"pto": c}, 0.2)
    assert 0 < factor < 1 and held["pto"] == pytest.approx(factor * c, rel=1e-12)
    loop = sampled_closed_loop(rm3, {"pto": (held["pto"], 0.0)}, 0.2)
    continuous = sampled_closed_loop(rm3, {"pto": (held["pto"], 0.0)}, None)
    assert loop.stable and loop.decay_rate >= HELD_DECAY_SHARE * continuous.decay_rate
    above = sampled_closed_loop(rm3, {"pto": (1.1 * held["pto"], 0.0)}, 0.2)
    above_c = sampled_closed_loop(rm3, {"pto": (1.1 * held["pto"], 0.0)}, None)
    assert not (above.stable and above.decay_rate >= HELD_DECAY_SHARE * above_c.decay_rate)
    # a damper that is fine held is kept as it is
    assert held_dampers(rm3, {"pto": 0.1 * held["pto"]}, 0.2)[1] == 1.0


def test_the_causal_mpc_runs_the_issues_sea(rm3):
    """`simulate rm3 --controller mpc --wave jonswap --hs 2.64 --tp 12.58` diverged at 4.8 s.
    Now it runs 200 s and absorbs power (measured 537 kW; the oracle forecast: 552 kW), its
    warm-up damper scaled (measured factor 0.41)."""
    wave = _sea(rm3, 2.64, 12.58)
    controller = make("mpc", wave=wave)
    ds = simulate(rm3, wave, duration=200.0, dt=0.01, controller=controller)
    warm_up = controller.describe()["warm_up"]
    assert warm_up["completed"] and 0 < warm_up["held_factor"] < 1
    assert summary(ds, rm3)["ptos"]["pto"]["mean_power_W"] > 0
    assert np.all(np.isfinite(ds["pto__force"].values))


def test_no_acceptable_damper_means_none_not_a_crash():
    """A damper a million times too strong for a tank-scale raft (1e7 N m s/rad held over
    0.2 s): not even a millionth of it is acceptable, so the warm-up gets no damper (f = 0)
    rather than an MPC that cannot be reset; the held loop with none is the plant's own."""
    raft = build_plant("hinged_raft")
    names = [p.name for p in raft.scene.ptos]
    held, factor = held_dampers(raft, {n: 1e7 for n in names}, 0.2)
    assert factor == 0.0 and all(v == 0.0 for v in held.values())
    assert not sampled_closed_loop(raft, {n: (10.0, 0.0) for n in names}, 0.2).stable
