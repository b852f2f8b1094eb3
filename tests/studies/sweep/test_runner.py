"""The runner's tasks: guided tasks hold every case once, in the order the sweep runs them, one
plant a task, large first and single cases last; per_task keeps fixed sizes. A Dask run of
guided tasks gives the records the serial run gives, removes its plant plugin, and runs the
caller's `meanwhile` work once, on a thread, while the tasks run (serially: after them)."""
import math
import threading

import pytest

from mbcontrol.studies.sweep import grid, runner
from mbcontrol.studies.sweep.cases import build_cases
from mbcontrol.studies.sweep.store import CaseStore


def _cases(n_seeds: int, scene_values=(None,)):
    out = []
    for value in scene_values:
        scene = {} if value is None else {"mass": value}
        out += build_cases("sphere", grid([1.0, 2.0], [8.0, 10.0]), seeds=n_seeds,
                           scene_params=scene, duration=60.0, dt=0.1)
    return out


def _plant(case) -> tuple:
    return case.model, tuple(sorted(case.resolved()[1].items())), case.nonlinear


@pytest.mark.parametrize("n_seeds,workers", [(50, 2), (3, 2), (1, 4), (25, 1)])
def test_guided_tasks_hold_every_case_once_largest_first(n_seeds, workers):
    cases = _cases(n_seeds)
    tasks = runner.guided_tasks(cases, workers)
    assert [c for t in tasks for c in t] == cases            # every case once, in order
    sizes = [len(t) for t in tasks]
    assert sizes[0] == max(1, math.ceil(len(cases) / (runner.GUIDED * workers)))
    assert sizes == sorted(sizes, reverse=True) and sizes[-1] == 1
    # each task is 1 / (GUIDED x workers) of what was left before it, at least one case
    left = len(cases)
    for size in sizes:
        assert size == max(1, math.ceil(left / (runner.GUIDED * workers)))
        left -= size


def test_guided_tasks_keep_one_plant_a_task_and_per_task_sizes():
    cases = _cases(5, scene_values=(None, 2.0e5))     # two plants: the scene and mass 2e5
    queue = [c for g in runner.groups(cases, len(cases)) for c in g]
    tasks = runner.guided_tasks(queue, 2)
    assert [c for t in tasks for c in t] == queue
    assert all(len({_plant(c) for c in t}) == 1 for t in tasks)
    fixed = runner.guided_tasks(queue, 2, per_task=3)
    assert [c for t in fixed for c in t] == queue
    assert [len(t) for t in fixed] == ([3] * 6 + [2]) * 2     # 20 cases a plant: 3 x 6 + 2
    assert runner.guided_tasks([], 2) == []


def test_guided_dask_tasks_give_the_serial_records(monkeypatch):
    from dask.distributed import Client, LocalCluster
    cases = _cases(3)                                    # 12 cases: tasks of 2, 2, 1, 1, ...
    serial = CaseStore(None)
    runner.execute(cases, serial, workers=0, progress=False)
    clustered = CaseStore(None)
    ran = []                                 # the threads it ran on
    later = runner.Meanwhile(lambda: ran.append(threading.current_thread()))
    with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None,
                      host="127.0.0.1") as cluster, Client(cluster) as client:
        queue = list(cases)
        runner._on_dask(queue, lambda records: [clustered.write(r["case"], r)
                                                for r in records], client, None,
                         later=later)
        assert not queue
        assert not [k for k in client.run(lambda dask_worker: list(dask_worker.plugins))
                    .values() if any("mbcontrol-sweep-plants" in p for p in k)]
    for c in cases:
        assert clustered.read(c.key)["metrics"] == serial.read(c.key)["metrics"]
        assert clustered.read(c.key)["valid"] == serial.read(c.key)["valid"]
    later.finish()
    assert len(ran) == 1 and ran[0] is not threading.main_thread()


def test_meanwhile_runs_once_after_serial_cases_and_raises_what_it_raised():
    cases = _cases(1)[:2]
    store, seen = CaseStore(None), []
    runner.execute(cases, store, workers=0, progress=False,
                   meanwhile=lambda: seen.append(all(store.has(c.key) for c in cases)))
    assert seen == [True]                      # once, after the cases were stored

    def fails():
        raise RuntimeError("the caller's own error")
    later = runner.Meanwhile(fails)
    later.start()
    with pytest.raises(RuntimeError, match="the caller's own error"):
        later.finish()
    later.finish()                             # nothing left to run: no second call
