"""Running a sweep's cases: serially, or on Dask (`dask.distributed`) from a local cluster of
one worker per core to an existing cluster's scheduler.

Cases that share a plant (same model and scene parameters) go to a task in groups, so a
worker builds a plant once (its compiled code comes from the on-disk cache) and runs the
group through it. Records are written by the calling process as tasks finish, so a killed
sweep keeps what finished; a worker that dies loses its task in flight, which the scheduler
runs again elsewhere. Both paths run the same function on the same cases: identical numbers.
"""
from __future__ import annotations

import math
import os
import time
from collections import defaultdict

_PLANTS: dict = {}
FAULT_ENV = "MBCONTROL_SWEEP_FAULT"     # test hook: "exit-after:N" (the sweep process) or
                                        # "kill-worker-once:PATH" (a worker, once)


def _plant(model: str, scene_params: tuple):
    """The plant of a model and scene parameters, built once per process."""
    key = (model, scene_params)
    if key not in _PLANTS:
        from ...plant import build_plant
        from ...scene import load_scene
        _PLANTS[key] = build_plant(load_scene(model, dict(scene_params) or None))
    return _PLANTS[key]


def run_case(case) -> dict:
    """Simulate one case in closed loop and measure it: {"case": key, "metrics": {name:
    value} (per PTO `<pto>__<metric>` as `mbcontrol.analysis.metrics.pto_metrics`, and the
    totals mean_power_W, mean_electrical_power_W), "wall_time_s"}."""
    import inspect

    from mbcontrol.controllers import REGISTRY, make

    from ... import waves
    from ...analysis import summary
    from ...sim import simulate
    params, scene_params, settings = case.resolved()
    plant = _plant(case.model, tuple(sorted(scene_params.items())))
    sea = case.sea
    headings = plant.hydro.data["wave_direction"].values
    wave = waves.irregular(sea.hs, sea.tp, gamma=sea.gamma, seed=case.seed,
                           duration=case.duration, band=_band(plant, sea.tp),
                           direction=float(headings[0]) if len(headings) == 1 else 0.0)
    controller = None
    if case.controller:
        cls = REGISTRY[case.controller]
        if "wave" in inspect.signature(cls).parameters:
            settings.setdefault("wave", wave)
        controller = make(case.controller, **settings)
    start = time.perf_counter()
    ds = simulate(plant, wave, duration=case.duration, dt=case.dt, controller=controller,
                  method=case.method, params=params or None)
    result = summary(ds, plant)
    metrics = {}
    for pto, m in result.get("ptos", {}).items():
        for k, v in m.items():
            if isinstance(v, (int, float)) and v is not None:
                metrics[f"{pto}__{k}"] = float(v)
    ptos = result.get("ptos", {})
    metrics["mean_power_W"] = sum(m["mean_power_W"] for m in ptos.values())
    metrics["mean_electrical_power_W"] = sum(m["mean_electrical_power_W"] for m in ptos.values())
    return {"case": case.key, "metrics": metrics, "wall_time_s": time.perf_counter() - start}


def _band(plant, tp: float):
    """The spectrum's band (multiples of the peak frequency) kept inside the hydro data."""
    omega = plant.hydro.omega
    wp = 2 * math.pi / tp
    lo, hi = max(0.3, float(omega[0]) / wp), min(4.0, float(omega[-1]) / wp)
    if not lo < hi:
        raise ValueError(f"a sea with Tp {tp:g} s lies outside {plant.name}'s hydro data "
                         f"({float(omega[0]):.3g}-{float(omega[-1]):.3g} rad/s)")
    return (lo, hi)


def run_group(cases) -> list[dict]:
    """A task: the cases of one plant, run in order."""
    fault = os.environ.get(FAULT_ENV, "")
    if fault.startswith("kill-worker-once:"):
        flag = fault.split(":", 1)[1]
        if not os.path.exists(flag):
            open(flag, "w").close()
            os._exit(1)                    # a worker dies in the middle of its task
    return [run_case(c) for c in cases]


def groups(cases, per_task: int) -> list[list]:
    """Cases split into tasks: same plant in a task, at most per_task cases each."""
    by_plant = defaultdict(list)
    for c in cases:
        by_plant[(c.model, dict(c.resolved()[1]).__repr__())].append(c)
    out = []
    for members in by_plant.values():
        out += [members[k:k + per_task] for k in range(0, len(members), per_task)]
    return out


def execute(cases, store, *, workers: int | None = None, scheduler: str | None = None,
            progress: bool = True, per_task: int | None = None) -> dict:
    """Run the cases the store lacks; workers=0 runs serially in this process, None or N
    on a local Dask cluster of N workers (default: one per core), scheduler an address.
    Returns {"computed", "reused", "wall_time_s"}."""
    todo = [c for c in cases if not store.has(c.key)]
    reused = len(cases) - len(todo)
    start = time.perf_counter()
    bar = _bar(progress, len(cases), reused)
    stop_after = _exit_after()
    done = 0

    def save(records):
        nonlocal done
        for r in records:
            store.write(r["case"], r)
            done += 1
            if bar is not None:
                bar.update(1)
            if stop_after is not None and done >= stop_after:
                os._exit(9)                # the sweep process is killed part-way

    if todo and workers == 0 and scheduler is None:
        for group in groups(todo, per_task or len(todo)):
            for case in group:
                save([run_case(case)])
    elif todo:
        _on_dask(todo, save, workers, scheduler, per_task)
    if bar is not None:
        bar.close()
    return {"computed": len(todo), "reused": reused, "wall_time_s": time.perf_counter() - start}


def _on_dask(todo, save, workers, scheduler, per_task) -> None:
    from dask.distributed import Client, LocalCluster, as_completed
    if scheduler:
        client = Client(scheduler)
        cluster = None
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=40)
        client = Client(cluster)
    try:
        n_workers = max(1, len(client.scheduler_info()["workers"]))
        size = per_task or max(1, math.ceil(len(todo) / (4 * n_workers)))
        tasks = groups(todo, size)
        futures = [client.submit(run_group, g, pure=False, retries=2) for g in tasks]
        for future in as_completed(futures):
            save(future.result())
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _exit_after():
    fault = os.environ.get(FAULT_ENV, "")
    return int(fault.split(":", 1)[1]) if fault.startswith("exit-after:") else None


def _bar(progress: bool, total: int, reused: int):
    if not progress:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, initial=reused, desc="sweep", unit="case")
