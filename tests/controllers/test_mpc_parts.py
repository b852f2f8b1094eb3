"""The MPC in its three parts (issue 59, item 2): settings (frozen), the setup built from a
plant (fixed once built) and the run data (one per run). Two controllers made from the same
arguments share nothing that either could change; a run never changes its setup; reset
starts a run afresh; the names from before the split still read through."""
import dataclasses
import inspect
import warnings

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers import make
from mbcontrol.controllers.mpc import Mpc, MpcRun, MpcSettings, MpcSetup
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

SEA = waves.irregular(2.0, 9.0, seed=1)


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


def _settings():
    return dict(horizon_s=4.0, dt_s=0.2, wave=SEA, force_max={"pto": 4e5}, rate_max=2e6,
                measured=["pto__position", "pto__velocity"], envelope=False, warm_up_s=5.0)


def _mutable(root, skip) -> dict:
    """id -> path of every changeable object reachable from root (arrays that can be written,
    lists, dicts, sets and our own objects' attribute dicts), not descending into `skip`
    (the plant and the wave: the caller's, shared on purpose) nor into CasADi or cvxpy."""
    found, seen = {}, set()
    stack = [(root, "root")]
    while stack:
        obj, path = stack.pop()
        if id(obj) in seen or any(obj is s for s in skip):
            continue
        seen.add(id(obj))
        module = type(obj).__module__ or ""
        if isinstance(obj, np.ndarray):
            if obj.flags.writeable:
                found[id(obj)] = path
            if obj.dtype == object:
                stack += [(v, f"{path}[]") for v in obj.ravel()]
        elif isinstance(obj, (list, dict, set)):
            if not (isinstance(obj, dict) and type(obj).__name__ == "FrozenDict"):
                found[id(obj)] = path
            items = obj.items() if isinstance(obj, dict) else enumerate(obj)
            stack += [(v, f"{path}[{k!r}]") for k, v in items]
        elif isinstance(obj, tuple):
            stack += [(v, f"{path}[{k}]") for k, v in enumerate(obj)]
        elif module.startswith(("controllers", "mbcontrol.controllers")) and hasattr(obj, "__dict__"):
            if not dataclasses.is_dataclass(obj) or not obj.__dataclass_params__.frozen:
                found[id(obj)] = path
            stack += [(v, f"{path}.{k}") for k, v in vars(obj).items()]
    return found


def test_settings_are_frozen_with_the_constructor_s_names_and_defaults():
    kw = _settings()
    mpc = Mpc(**kw)
    assert isinstance(mpc.settings, MpcSettings)
    with pytest.raises(dataclasses.FrozenInstanceError):
        mpc.settings.horizon_s = 5.0
    with pytest.raises(TypeError):
        mpc.settings.force_max["pto"] = 1.0            # a per-PTO setting is frozen too
    kw["force_max"]["pto"] = 1.0                        # and a copy: the caller's dict is its own
    assert mpc.settings.force_max == {"pto": 4e5} and mpc.force_max == {"pto": 4e5}
    assert mpc.settings.forecast == "ar" and mpc.settings.measured == ("pto__position",
                                                                       "pto__velocity")
    with pytest.raises(AttributeError):
        mpc.horizon_s = 5.0                             # the old names read, never write
    # one list of settings: Mpc(**settings) and make("mpc", ...) take MpcSettings' arguments
    params = inspect.signature(Mpc).parameters
    assert list(params) == [f.name for f in dataclasses.fields(MpcSettings)]
    assert params["forecast"].default is None and params["horizon_s"].default == 10.0
    assert make("mpc", horizon_s=4.0, wave=SEA).settings == MpcSettings(horizon_s=4.0, wave=SEA)
    with pytest.raises(ValueError, match="forecast must be one of"):
        Mpc(forecast="psychic")


def test_two_mpcs_with_the_same_settings_share_nothing_mutable(sphere):
    kw = _settings()
    a, b = Mpc(**kw), Mpc(**kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a.reset(sphere)
        b.reset(sphere)
    skip = (sphere, SEA)
    mutable_a = _mutable(a, skip)
    mutable_b = _mutable(b, skip)
    assert len(mutable_a) > 20                          # the walk reached the run data
    shared = set(mutable_a) & set(mutable_b)
    assert not shared, [mutable_a[i] for i in shared]
    # running one leaves the other at rest
    simulate(sphere, SEA, duration=20.0, dt=0.05, controller=a)
    assert a.run.stats["solves"] > 0 and b.run.stats["solves"] == 0
    assert not np.any(b.run.kalman.state) and b.run.ar.history == []


def test_a_run_leaves_its_setup_as_built_and_reset_starts_afresh(sphere):
    mpc = Mpc(**_settings())
    first = simulate(sphere, SEA, duration=40.0, dt=0.05, controller=mpc)
    setup, run = mpc.setup, mpc.run
    assert isinstance(setup, MpcSetup) and isinstance(run, MpcRun)
    with pytest.raises(dataclasses.FrozenInstanceError):
        setup.N = 3
    arrays = {k: v for k, v in vars(setup.qp).items() if isinstance(v, np.ndarray)}
    assert arrays and not any(v.flags.writeable for v in arrays.values())
    with pytest.raises(ValueError, match="read-only"):
        setup.qp.H_u[0, 0] = 0.0
    assert not setup.kalman.K.flags.writeable and not setup.limits["force"].flags.writeable
    # the run data hold what the run did; a second run starts from rest and repeats it
    assert run.stats["solves"] > 100 and run.qp.soft_solves >= 0 and run.plan is not None
    second = simulate(sphere, SEA, duration=40.0, dt=0.05, controller=mpc)
    assert mpc.run is not run and mpc.setup is not setup
    assert np.array_equal(first["u__pto"].values, second["u__pto"].values)
    # the names from before the split read through to their parts
    assert mpc.stats is mpc.run.stats and mpc.qp is mpc.setup.qp and mpc.N == 20
    assert mpc.horizon_s == 4.0 and mpc.period == 0.2 and mpc.warm_up_end == mpc.run.warm_up_end


def test_before_reset_the_mpc_describes_its_settings_and_refuses_to_run():
    mpc = Mpc(**_settings())
    assert mpc.setup is None and mpc.run is None
    described = mpc.describe()
    assert described["horizon_s"] == 4.0 and described["stats"] == {}
    with pytest.raises(AttributeError, match="reset"):
        mpc.cp
    with pytest.raises(ValueError, match="reset"):
        mpc(0.0, np.zeros(4))
