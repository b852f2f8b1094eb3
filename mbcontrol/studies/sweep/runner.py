"""Running a sweep's cases: serially, or on Dask (`dask.distributed`) from a local cluster of
one worker per core to an existing cluster's scheduler.

Cases that share a plant (same model and scene parameters) go to a task in groups, large
first and single cases last (`guided_tasks`), and a worker builds each plant once for the run
(its compiled code from the on-disk cache) and runs every group through it; workers run under
this process's defaults (`worker_plants.worker_environment`). Records are written by the calling process as tasks finish, so a killed
sweep keeps what finished; a worker that dies loses its task in flight, which the scheduler
runs again elsewhere. Both paths run the same function on the same cases: identical numbers.

Light cases (rm3 for an hour at dt 0.05 s: 21 ms of stepping) are dominated by what surrounds
the stepping, so a case without a controller skips the Dataset (`sim.light`), and a local
cluster is started only when the sweep is long enough to pay for it (`execute`). Its workers
are spawned (fresh interpreters) or, with "sweep.start" = "forkserver", forked from one fresh
interpreter that imported a case's code once (`worker_plants`): never forked from this
process, which runs threads (Dask's event loop, the cluster's starter, progress bars, BLAS)
and whose copy can inherit a lock another thread holds and hang for ever; a CI run did.
"sweep.start" = "fork" (MBCONTROL_SWEEP_START=fork) keeps that fastest start for those who
accept it, behind a start watchdog.

The plants live in the run's `PlantCache` (this process) and in a worker plugin registered for
the run (`worker_plants.RunPlants`, Dask workers): nothing is kept in module state, so a second
sweep in the same process builds its plants from the scene as it is then.
"""
from __future__ import annotations

import math
import os
import time
from collections import defaultdict

from ... import defaults
from ...console import progress_bar
from ...errors import InputError

from .case_run import PlantCache, run_case, sea_wave  # noqa: F401  (this module's face)


def run_group(cases, plants: str | PlantCache | None = None) -> list[dict]:
    """A task: the cases of one plant, run in order. plants: the run's PlantCache, or on a
    Dask worker the name of the run's `worker_plants.RunPlants` plugin (None: a new cache)."""
    if isinstance(plants, str):
        from .worker_plants import worker_plants
        plants = worker_plants(plants)
    plants = PlantCache() if plants is None else plants
    return [run_case(c, plants) for c in cases]


def groups(cases, per_task: int) -> list[list]:
    """Cases split into tasks: same plant in a task, at most per_task cases each."""
    by_plant = defaultdict(list)
    for c in cases:
        by_plant[(c.model, dict(c.resolved()[1]).__repr__(), c.nonlinear)].append(c)
    out = []
    for members in by_plant.values():
        out += [members[k:k + per_task] for k in range(0, len(members), per_task)]
    return out


# Guided tasks: each takes 1 / (GUIDED x workers) of the cases left (at least one), so the
# first tasks carry many cases (200 light rm3 cases on 2 workers: 25, ~2 s, against a task's
# few ms of scheduling) and the last are single cases, which even out the workers' ends.
GUIDED = 4


def guided_tasks(cases, n_workers: int, per_task: int | None = None) -> list[list]:
    """Cases (in plant order, `groups`) split into tasks of one plant each, largest first:
    per_task cases each when given, else guided (GUIDED)."""
    left, out = len(cases), []
    for members in groups(cases, len(cases) or 1):
        k = 0
        while k < len(members):
            size = per_task or max(1, math.ceil(left / (GUIDED * n_workers)))
            out.append(members[k:k + size])
            k += size
            left -= len(out[-1])
    return out


# A local cluster's fixed costs (start, close; s) by how its workers start, measured on 2
# cores with rm3. "spawn": fresh interpreters (LocalCluster of 2 processes 1.3-1.5 s, then
# each worker's imports, plant and compiled code 1.6-2.6 s; closing 0.5-1.4 s).
# "forkserver": forks of one fresh single-threaded interpreter that imported a case's code
# once (`worker_plants.preload_forkserver`): one set of imports instead of one a worker, and
# a close of 0.1 s (against spawn under the same load: start 0.6x, close 0.07x). "fork":
# copies of this process, its imports, plants and loaded code included (0.13-0.31 s to start,
# 0.03-0.05 s to close), opt-in only: a fork copies every lock of every thread (Dask's loop,
# BLAS, tqdm's monitor) in whatever state it is, and one held lock hangs the copy; a CI run
# hung 70 min that way. A sweep starts a cluster only when its cases, timed here, would take
# longer serially (`_cluster_pays`; the default "sweep.cluster" = "always" starts it whatever
# it costs); a start that has not finished in START_TIMEOUT_S is abandoned with a warning and
# the cases run here.
CLUSTER_COSTS = {"spawn": (3.0, 1.0), "fork": (0.5, 0.2), "forkserver": (2.0, 0.1)}
START_TIMEOUT_S = 180.0
CLOSE_MARGIN = 1.5          # the close counted 1.5 times: what the estimate leaves for noise
CLUSTER_CHOICES = ("auto", "always")
# Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which also turns off glibc's
# adaptive mmap threshold: every array over 128 kB is then fresh pages from the kernel, and a
# light case's NumPy work (records of 72,000 samples) ran 2-3x slower on a worker than here
# (rm3: 400 against 250 ms a case with its checks, 170 against 155 ms with these). These are
# the adaptive threshold's own limits, fixed: big arrays reuse the heap, as in this process.
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": 1 << 25, "MALLOC_TRIM_THRESHOLD_": 1 << 26}


def execute(cases, store, *, workers: int | None = None, scheduler: str | None = None,
            progress: bool = True, per_task: int | None = None,
            plants: PlantCache | None = None, meanwhile=None) -> dict:
    """Run the cases the store lacks; workers=0 runs serially in this process, None or N
    on a local Dask cluster of N workers (default: one per core), scheduler an address.

    A local cluster is started only when it pays: the first cases run here, timed; when the
    rest would finish sooner serially than with the cluster's start and close
    (CLUSTER_COSTS), they run here too (a small or light sweep, or one worker). Workers are
    started in the background while this process keeps running cases ("sweep.start":
    "spawn", "forkserver", or "fork": forked, faster to start, unsafe in a threaded
    process). A cluster not started within START_TIMEOUT_S is abandoned (warning). Same cases, same function, same numbers
    wherever a case runs. plants: the run's PlantCache for the cases run here (None: a new
    one); workers keep their own for this call. meanwhile: the caller's own work that does
    not need the records (a callable, run once before this returns): on a thread while Dask
    workers run the cases, this process otherwise idle, else after the cases. Returns
    {"computed", "reused", "wall_time_s", "where"}: "serial", "cluster" or "scheduler"."""
    plants = PlantCache() if plants is None else plants
    later = Meanwhile(meanwhile)
    todo = [c for c in cases if not store.has(c.key)]
    reused = len(cases) - len(todo)
    start = time.perf_counter()
    bar = _bar(progress, len(cases), reused)

    def save(records):
        for r in records:
            store.write(r["case"], r)
            if bar is not None:
                bar.update(1)

    where = "serial"
    queue = [c for group in groups(todo, len(todo) or 1) for c in group]   # a plant at a time
    if queue and scheduler is not None:
        from dask.distributed import Client
        client = Client(scheduler)
        try:
            _on_dask(queue, save, client, per_task, later=later)
        finally:
            client.close()
        where = "scheduler"
    elif queue and workers != 0:
        n = workers or os.cpu_count() or 1
        where = _local(queue, (save, plants, later), n, per_task)
    for case in queue:                     # serial, or what the local path left here
        save([run_case(case, plants)])
    queue.clear()
    later.finish()
    if bar is not None:
        bar.close()
    return {"computed": len(todo), "reused": reused, "wall_time_s": time.perf_counter() - start,
            "where": where}


def _start_method() -> str:
    """How local workers start: the default "sweep.start" ("spawn", "fork" or
    "forkserver")."""
    chosen = str(defaults.get("sweep.start"))
    if chosen not in CLUSTER_COSTS:
        raise InputError(f"sweep.start (MBCONTROL_SWEEP_START) = {chosen!r}: expected one of "
                         f"{', '.join(CLUSTER_COSTS)}")
    return chosen


def _cluster_forced() -> bool:
    """Whether the default "sweep.cluster" asks for the local cluster whatever it costs."""
    chosen = str(defaults.get("sweep.cluster"))
    if chosen not in CLUSTER_CHOICES:
        raise InputError(f"sweep.cluster (MBCONTROL_SWEEP_CLUSTER) = {chosen!r}: expected one "
                         f"of {', '.join(CLUSTER_CHOICES)}")
    return chosen == "always"


def _cluster_pays(serial_s: float, n_workers: int, method: str = "spawn") -> bool:
    """Whether n local workers started by `method` finish `serial_s` of work (as timed here)
    sooner than this process: spawned (or fork-served) workers start while this process
    keeps working, forked ones while it waits; then the rest is shared."""
    if n_workers < 2:
        return False
    start, close = CLUSTER_COSTS[method]
    rest = serial_s if method == "fork" else max(0.0, serial_s - start)
    return start + rest / n_workers + CLOSE_MARGIN * close < serial_s


def idle_cores() -> int:
    """Cores not busy with other work: the machine's, less the 1-minute load average beyond
    this process (os.getloadavg; all of them where it is not available)."""
    cores = os.cpu_count() or 1
    try:
        busy = max(0, round(os.getloadavg()[0]) - 1)
    except (AttributeError, OSError):
        return cores
    return max(1, cores - busy)


def _local(queue: list, here: tuple, n: int, per_task) -> str:
    """Run `queue` (emptied) on a local cluster of n workers when it pays, else leave it to
    the caller's serial loop; here = (save, the run's PlantCache, its Meanwhile).
    Returns where the cases ran. Workers only share the cores other work leaves idle: on a
    machine already busy (a test suite with a worker per core) a cluster's processes would
    only take turns with it, and its start and close are lost."""
    save, plants, later = here
    forced = _cluster_forced()
    method = _start_method()
    if not forced:
        usable = min(n, idle_cores())
        if usable < 2:
            return "serial"
        timed = []
        while queue and len(timed) < 2:    # the first pays one-off costs (code, caches)
            t0 = time.perf_counter()
            save([run_case(queue.pop(0), plants)])
            timed.append(time.perf_counter() - t0)
        if not queue or not _cluster_pays(min(timed) * len(queue), usable, method):
            return "serial"
    first = queue[0]
    starter = _ClusterStarter(n, (first.model, tuple(sorted(first.resolved()[1].items())),
                                  int(round(first.duration / first.dt)), first.method,
                                  first.nonlinear == "always"), method)
    starter.start()
    deadline = time.perf_counter() + START_TIMEOUT_S
    # while the workers start nothing waits: this process runs cases (a forced cluster keeps
    # a case a worker, so that it runs some); a fork copies this process, so it is left alone
    reserve = n if forced else 0
    while len(queue) > reserve and method != "fork" and not starter.ready.is_set():
        save([run_case(queue.pop(0), plants)])
    if not starter.ready.wait(max(0.0, deadline - time.perf_counter())):
        import warnings                     # its thread is a daemon: left behind, not joined
        warnings.warn(f"sweep: the local Dask cluster ({method}) did not start within "
                      f"{START_TIMEOUT_S:.0f} s; running the remaining {len(queue)} cases here",
                      RuntimeWarning, stacklevel=3)
        return "serial"
    try:
        if starter.error is not None:
            import warnings
            warnings.warn(f"sweep: the local Dask cluster did not start ({starter.error}); "
                          f"running the remaining {len(queue)} cases here", RuntimeWarning,
                          stacklevel=3)
            return "serial"
        if not queue:                       # this process finished them while it started
            return "serial"
        _on_dask(queue, save, starter.client, per_task, starter.plants, later)
        return "cluster"
    finally:
        starter.join()
        starter.close()


class _ClusterStarter:
    """A LocalCluster of n single-threaded worker processes, started by `method` ("spawn",
    "forkserver" or "fork") on a thread (the run's plant plugin registered, each worker's
    plant built and its compiled code loaded), so the caller can keep computing."""

    def __init__(self, n: int, warm: tuple, method: str = "spawn"):
        import threading
        self.n, self.warm, self.method = n, warm, method
        self.cluster = self.client = self.error = self.plants = None
        self.ready = threading.Event()
        self._thread = threading.Thread(target=self._run, name="sweep-cluster", daemon=True)

    def start(self):
        self._thread.start()

    def join(self):
        self._thread.join()

    def _run(self):
        try:
            import dask
            from dask.distributed import Client

            from ..cluster import local_cluster
            config = {f"distributed.nanny.pre-spawn-environ.{k}": v
                      for k, v in WORKER_MALLOC.items()}
            config["distributed.worker.multiprocessing-method"] = self.method
            from .worker_plants import preload_forkserver, worker_environment
            with dask.config.set(config):       # a worker restarted later is spawned
                if self.method == "forkserver":
                    preload_forkserver()
                self.cluster = local_cluster(self.n, silence_logs=40,
                                             env=worker_environment())
            self.client = Client(self.cluster)
            self.plants = _register_plants(self.client)
            self.client.run(_warm, *self.warm, plants=self.plants)
        except Exception as exc:           # reported by the caller, which runs on serially
            self.error = exc
        finally:
            self.ready.set()

    def close(self):
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def _register_plants(client) -> str:
    """Register a fresh `worker_plants.RunPlants` on the client's workers; its name."""
    from .worker_plants import RunPlants
    plugin = RunPlants()
    client.register_plugin(plugin, name=plugin.name)
    return plugin.name


def _warm(model: str, scene_params: tuple, n_steps: int, method: str,
          nonlinear: bool = False, *, plants: str, dask_worker=None) -> None:
    """On a worker: import what a case uses (the checks' control and scipy: ~1 s), build the
    plant into the run's cache (the plugin `plants`) and load its compiled stepping and
    output code, before cases come."""
    import numpy as np

    import mbcontrol.controllers  # noqa: F401

    import mbcontrol.analysis  # noqa: F401   (its metrics and validity checks)
    from ...sim import method as method_of
    from ...sim import plant_outputs, prepare

    from .worker_plants import worker_plants
    plant = worker_plants(plants, dask_worker).plant(model, scene_params, nonlinear)
    if method_of(method).fixed_step:
        prepare(plant, n_steps, method)
        rows = n_steps + 1
        plant_outputs(plant, np.zeros((rows, plant.nx)), np.zeros((rows, len(plant.inputs))),
                      np.zeros((rows, len(plant.disturbances))), plant.p0)


def _on_dask(queue: list, save, client, per_task, plants: str | None = None,
             later: Meanwhile | None = None) -> None:
    """Run `queue` (emptied) on a Dask client's workers, in tasks of a plant's cases
    (`guided_tasks`: per_task cases each, or by default large first tasks that amortise their
    scheduling and single-case last ones that balance the workers). A task ships its cases
    (settings and input hashes, pickled ~0.8 kB each) and returns their records (metrics and
    verdict, ~0.5 kB each): the plant is the worker's own, built once (`_warm`). plants: the run's plant plugin
    on the workers (None: one is registered for this call and removed after it, so a shared
    cluster keeps no plants); later: started once the tasks are submitted."""
    from dask.distributed import as_completed
    todo = list(queue)
    queue.clear()
    ours = plants is None
    plants = _register_plants(client) if ours else plants
    try:
        n_workers = max(1, len(client.scheduler_info()["workers"]))
        futures = [client.submit(run_group, g, plants, pure=False, retries=2)
                   for g in guided_tasks(todo, n_workers, per_task)]
        if later is not None:
            later.start()
        for future in as_completed(futures):
            save(future.result())
    finally:
        if ours:
            client.unregister_worker_plugin(plants)


class Meanwhile:
    """The caller's work (a callable, or None) run once: on a thread from `start` (while
    workers run the cases), else by `finish`, which waits for it and raises what it raised."""

    def __init__(self, work=None):
        self.work, self._thread, self._error = work, None, None

    def start(self) -> None:
        import threading
        if self.work is None:
            return
        work, self.work = self.work, None

        def run():
            try:
                work()
            except BaseException as exc:   # noqa: BLE001 - raised again by finish()
                self._error = exc
        self._thread = threading.Thread(target=run, name="sweep-meanwhile", daemon=True)
        self._thread.start()

    def finish(self) -> None:
        if self.work is not None:
            work, self.work = self.work, None
            work()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        error, self._error = self._error, None
        if error is not None:
            raise error


def _bar(progress: bool, total: int, reused: int):
    if not progress:
        return None
    return progress_bar(total=total, initial=reused, desc="sweep", unit="case")
