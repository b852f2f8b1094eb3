"""Light sweeps: a case run without a Dataset gives the record a `simulate` run gives (same
keys, same numbers to 1e-9); a local cluster starts only when the sweep pays for it."""
import pytest

from mbcontrol.errors import InputError

from mbcontrol.sim import light
from mbcontrol.studies.sweep import grid
from mbcontrol.studies.sweep import case_run, runner
from mbcontrol.studies.sweep.cases import build_cases
from mbcontrol.studies.sweep.store import CaseStore


def _full_path(monkeypatch):
    monkeypatch.setattr(light, "can_run", lambda *args: False)


@pytest.mark.parametrize("model,vary", [("rm3", {"pto__damping": [6e5, 2e6]}),
                                        ("sphere", {})])
def test_light_record_equals_the_simulate_record(monkeypatch, model, vary):
    roles = {name: "param" for name in vary}
    cases = build_cases(model, grid([1.5, 3.0], [9.0]), seeds=1, vary=vary, roles=roles,
                        duration=300.0, dt=0.05)
    fast = [runner.run_case(c) for c in cases]
    _full_path(monkeypatch)
    full = [runner.run_case(c) for c in cases]
    for a, b in zip(fast, full):
        assert set(a) == set(b) == {"case", "metrics", "valid", "invalid_reasons",
                                    "wall_time_s"}
        assert a["case"] == b["case"]
        assert a["valid"] == b["valid"] and a["invalid_reasons"] == b["invalid_reasons"]
        assert a["metrics"].keys() == b["metrics"].keys()
        for k, v in b["metrics"].items():
            assert a["metrics"][k] == pytest.approx(v, rel=1e-9, abs=1e-9), k


def test_cluster_pays_only_for_long_sweeps():
    assert not runner._cluster_pays(4.0, 2, "spawn")  # 64 light cases: seconds
    assert runner._cluster_pays(4.0, 2, "fork")       # a forked cluster starts in 0.3 s
    assert not runner._cluster_pays(0.8, 2, "fork")
    for method in ("spawn", "fork"):
        assert not runner._cluster_pays(1000.0, 1, method)   # one worker never beats this
        assert runner._cluster_pays(60.0, 2, method)


def test_spawned_workers_agree_with_serial(monkeypatch):
    # Forked workers are not run here: a fork of this threaded test process can copy a held
    # lock and hang (one CI run hung 70 min on it); they are opt-in for users.
    cases = build_cases("rm3", grid([1.5, 3.0], [8.0, 11.0]), duration=200.0, dt=0.05)
    serial = CaseStore(None)
    runner.execute(cases, serial, workers=0, progress=False)
    monkeypatch.delenv("MBCONTROL_SWEEP_START", raising=False)
    assert runner._start_method() == "forkserver"           # the default (its own test:
    monkeypatch.setenv("MBCONTROL_SWEEP_START", "spawn")     # test_worker_plants); spawn here
    assert runner._start_method() == "spawn"
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")
    clustered = CaseStore(None)
    assert runner.execute(cases, clustered, workers=2, progress=False)["where"] == "cluster"
    for c in cases:
        assert clustered.read(c.key)["metrics"] == serial.read(c.key)["metrics"]


def test_small_sweep_on_workers_runs_here_and_forced_cluster_agrees(monkeypatch):
    cases = build_cases("sphere", grid([1.0, 2.0], [8.0, 10.0]), duration=100.0, dt=0.1)
    serial = CaseStore(None)
    assert runner.execute(cases, serial, workers=0, progress=False)["where"] == "serial"
    small = CaseStore(None)
    assert runner.execute(cases, small, workers=2, progress=False)["where"] == "serial"
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")
    clustered = CaseStore(None)
    result = runner.execute(cases, clustered, workers=2, progress=False)
    assert result["where"] == "cluster" and result["computed"] == len(cases)
    for c in cases:
        a, b, d = serial.read(c.key), small.read(c.key), clustered.read(c.key)
        assert a["metrics"] == b["metrics"] == d["metrics"]
        assert a["valid"] == d["valid"]


def test_a_cluster_that_never_starts_is_abandoned_and_the_cases_run_here(monkeypatch):
    class Stuck:                            # a start that hangs, as a deadlocked fork does
        def __init__(self, *args):
            import threading
            self.ready = threading.Event()

        def start(self):
            pass

    monkeypatch.setattr(runner, "_ClusterStarter", Stuck)
    monkeypatch.setattr(runner, "START_TIMEOUT_S", 0.5)
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")
    cases = build_cases("sphere", grid([1.0], [8.0, 10.0]), duration=50.0, dt=0.1)
    store = CaseStore(None)
    with pytest.warns(RuntimeWarning, match="did not start within 0 s"):
        result = runner.execute(cases, store, workers=2, progress=False)
    assert result["where"] == "serial" and result["computed"] == 2
    assert all(store.has(c.key) for c in cases)


def test_a_busy_machine_runs_the_sweep_here(monkeypatch):
    """Workers share the cores other work leaves idle: with the load average already at the
    core count, a sweep on 2 workers runs here, without timing a case or starting a cluster."""
    monkeypatch.setattr(runner.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(runner.os, "getloadavg", lambda: (1.0, 1.0, 1.0))   # this process alone
    assert runner.idle_cores() == 2
    monkeypatch.setattr(runner.os, "getloadavg", lambda: (2.2, 2.0, 2.0))   # and one more job
    assert runner.idle_cores() == 1
    started = []           # a sweep that would pay on an idle machine; a start is recorded
    monkeypatch.setattr(runner, "_cluster_pays", lambda *args: True)
    monkeypatch.setattr(runner._ClusterStarter, "start", lambda self: started.append(self))
    monkeypatch.setattr(runner, "START_TIMEOUT_S", 0.1)
    monkeypatch.setattr(runner, "run_case", lambda case, plants=None: {"case": case.key})
    cases = build_cases("sphere", grid([1.0], [8.0, 10.0, 12.0]), duration=50.0, dt=0.1)
    store = CaseStore(None)
    assert runner.execute(cases, store, workers=2, progress=False)["where"] == "serial"
    assert not started and all(store.has(c.key) for c in cases)


def test_a_run_keeps_only_its_last_plants(monkeypatch):
    """A sweep over scene parameters builds a plant per value; a run's PlantCache keeps the
    last PLANTS_KEPT (cases run a plant at a time), not every one it has passed."""
    built = []
    monkeypatch.setattr("mbcontrol.plant.build_plant", lambda scene: built.append(scene) or object())
    monkeypatch.setattr("mbcontrol.scene.load_scene", lambda model, params=None: (model, params))
    cache = case_run.PlantCache()
    keys = [(("mass", float(m)),) for m in range(case_run.PLANTS_KEPT + 3)]
    plants = [cache.plant("sphere", key) for key in keys]
    assert len(cache) == case_run.PLANTS_KEPT and len(built) == len(keys)
    assert cache.plant("sphere", keys[-1]) is plants[-1] and len(built) == len(keys)
    cache.plant("sphere", keys[0])                          # dropped long ago: built again
    assert len(built) == len(keys) + 1
    mine = object()
    cache.keep("sphere", (("mass", -1.0),), mine)           # a plant the caller built
    assert cache.plant("sphere", (("mass", -1.0),)) is mine and len(built) == len(keys) + 1
    assert case_run.PlantCache().plant("sphere", keys[-1]) is not plants[-1]   # another run


def test_unknown_cluster_choices_are_refused_by_name(monkeypatch):
    monkeypatch.setenv("MBCONTROL_SWEEP_START", "thread")
    with pytest.raises(InputError, match="sweep.start .*'thread'.*spawn, fork"):
        runner._start_method()
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "sometimes")
    with pytest.raises(InputError, match="sweep.cluster .*'sometimes'.*auto, always"):
        runner._cluster_forced()
