"""Export reads an MPC's settings and a setup of its own (Mpc.export_view), never the caller's
controller (issue 59, item 2): the caller's Mpc, fresh or mid-run, is the same object with
the same run data after an export; a linear law too. What is exported is chosen by the law
protocol's class attributes (exportable, kind), not by the controller's name."""
import copy
import warnings

import numpy as np
import pytest

from mbcontrol.controllers import Law, Passive, make
from mbcontrol.export import controller_spec, export_controller
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate
from mbcontrol.waves import irregular

SEA = irregular(2.0, 9.0, seed=1)
SETTINGS = {"horizon_s": 8.0, "dt_s": 0.2, "wave": SEA, "envelope": False}


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


def _snapshot(mpc) -> dict:
    """The run data by value, and the identity of every part."""
    r = mpc.run
    return {"ids": (id(mpc.settings), id(mpc.setup), id(r), id(r.qp), id(r.kalman),
                    id(r.ar), id(r.stats)),
            "u_prev": r.u_prev.copy(), "plan": r.plan.copy(), "last_t": r.last_t,
            "state": r.kalman.state.copy(), "ar": np.array(r.ar.history),
            "stats": copy.deepcopy(r.stats), "history": copy.deepcopy(r.history),
            "qp": (r.qp.last, r.qp.soft_solves, copy.deepcopy(r.qp.forms[0]["fast"].__dict__)),
            "describe": mpc.describe()}


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def test_export_leaves_the_caller_s_mpc_as_it_was(sphere, tmp_path):
    fresh = make("mpc", **SETTINGS)
    settings = fresh.settings
    exported = export_controller(fresh, sphere, tmp_path / "fresh")
    assert fresh.setup is None and fresh.run is None and fresh.settings is settings
    # the spec describes an MPC bound to the plant (as the old reset-then-read did)
    assert exported.spec.settings["warm_up"]["planned_s"] == 45.0
    assert exported.spec.settings["stats"]["solves"] == 0

    running = make("mpc", **SETTINGS)
    simulate(sphere, SEA, duration=60.0, dt=0.05, controller=running)
    before = _snapshot(running)
    assert before["stats"]["solves"] > 0 and before["ar"].size > 0     # mid-run state
    again = export_controller(running, sphere, tmp_path / "running")
    assert _same(_snapshot(running), before)
    # its setup and the export's agree: the C constants are the caller's MPC's
    assert np.array_equal(again.spec.arrays["MBC_K"][1], running.setup.kalman.K)
    assert again.spec.defines == exported.spec.defines


def test_a_linear_law_is_exported_from_a_private_binding(sphere):
    law = make("reactive", damping=5e4, stiffness=-2e5, force_max=4e5)
    before = dict(vars(law))
    spec = controller_spec(law, sphere)
    assert vars(law) == before                  # never reset: same attributes, same objects
    assert [p.value for p in spec.parameters] == [5e4, -2e5, 4e5]


def test_what_is_exported_follows_the_class_not_the_name(sphere):
    class Renamed(Passive):                     # a passive law by another name
        name = "my_damper"
    spec = controller_spec(Renamed(damping=5e4), sphere)
    assert spec.kind == "law" and spec.name == "my_damper"

    class Kept(Law):                            # a law that does not say it is exportable
        name, kind = "kept", "linear"
    with pytest.raises(ValueError, match="'kept' cannot be exported.*exportable: .*mpc"):
        controller_spec(Kept(), sphere)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="IPOPT"):
            controller_spec(make("nmpc", wave=SEA), sphere)
