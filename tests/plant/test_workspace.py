"""A plant's workspace (mbcontrol.plant.workspace): what is derived from a plant, compiled
code included, lives with the plant and goes with it. References: the interpreter's own
bookkeeping (a weak reference dies with its object) and the process's resident memory."""
import dataclasses
import gc
import math
import pickle
import weakref

import numpy as np

from mbcontrol.analysis import linearize
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate
from mbcontrol.waves import regular

# flume_section's scene parameters are masses: every value shares one hydrodynamic dataset
MODEL, PARAMETER = "flume_section", "axle_mass"
BEAM_SEA = regular(0.05, 1.5, direction=math.pi / 2)      # its data has this heading only


def _used_plant(axle_mass: float, compiled: bool = True):
    plant = build_plant(load_scene(MODEL, {PARAMETER: axle_mass}))
    simulate(plant, BEAM_SEA, duration=3.0, dt=0.01, audit=False, compiled=compiled)
    return plant


def _rss_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def test_a_dropped_plant_takes_its_compiled_code_with_it():
    plant = _used_plant(0.05)
    linearize(plant)
    assert {key[0] for key in plant.workspace} >= {"sim.chunk", "sim.outputs",
                                                  "plant.jacobians"}
    gone = weakref.ref(plant)
    del plant
    gc.collect()
    assert gone() is None


def test_a_copied_or_pickled_plant_starts_with_an_empty_workspace():
    plant = _used_plant(0.05)
    assert plant.workspace
    copy = dataclasses.replace(plant, p0=plant.p0 * 1.0)
    assert copy.workspace == {} and plant.workspace
    again = pickle.loads(pickle.dumps(plant))
    assert again.workspace == {} and plant.workspace
    ds_a = simulate(plant, BEAM_SEA, duration=3.0, dt=0.01, audit=False)
    ds_b = simulate(again, BEAM_SEA, duration=3.0, dt=0.01, audit=False)
    assert np.array_equal(ds_a["time"].values, ds_b["time"].values)
    for name in plant.states[:4]:
        np.testing.assert_array_equal(ds_a[name].values, ds_b[name].values)


def test_memory_stays_flat_over_200_plants_built_used_and_dropped():
    """Issue 39's measure: 200 plants of scene-parameter values, each built, simulated and
    dropped in one process; the resident memory after the first 20 may not grow by 10 %
    (before the workspace it grew by 31 %). Each mass is a constant in the plant's code, so
    a compiled run would compile every plant (0.8 s each on a cold cache): these run
    CasADi's interpreter, and the test above shows the compiled code goes with its plant."""
    rss = []
    for i in range(200):
        _used_plant(0.05 + 0.001 * i, compiled=False)   # dropped at once: nothing else refers to it
        if i + 1 in (20, 200):
            gc.collect()
            rss.append(_rss_mb())
    assert rss[1] < 1.10 * rss[0], (f"resident memory {rss[0]:.1f} MB after 20 plants, "
                                    f"{rss[1]:.1f} MB after 200")
