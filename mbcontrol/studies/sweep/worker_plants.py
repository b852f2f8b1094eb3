"""The plants a sweep run keeps on a Dask worker, and how a local cluster's workers start.

A worker plugin registered per run under a name of its own, so two runs on one cluster (or
one after the other) never share a plant, and a worker that restarts mid-run gets a fresh
cache from the scheduler. Workers started by "forkserver" are forks of one fresh,
single-threaded interpreter that has imported what a case runs (`preload_forkserver`): the
imports (2-6 s of CPU a worker, spawned) are paid once, and nothing is built there. Imported
only where Dask is used (it imports `distributed`)."""
from __future__ import annotations

import uuid

from distributed import WorkerPlugin, get_worker

from .case_run import PlantCache

# What the fork server imports before it forks workers: a case's code (the plant, its
# simulation, metrics and checks, the controllers) and Dask's worker. Modules only: no plant,
# scene or hydro data is read there, so a scene edited between two sweeps is built afresh.
FORKSERVER_PRELOAD = ("distributed", "numpy", "pandas", "casadi", "mbcontrol.analysis",
                      "mbcontrol.controllers", "mbcontrol.plant", "mbcontrol.scene",
                      "mbcontrol.sim", "mbcontrol.waves", "mbcontrol.studies.sweep.runner",
                      "mbcontrol.studies.sweep.worker_plants")


class RunPlants(WorkerPlugin):
    """A worker's PlantCache for one sweep run (`name`); pickled empty to every worker."""

    def __init__(self, name: str | None = None):
        self.name = name or f"mbcontrol-sweep-plants-{uuid.uuid4().hex[:12]}"
        self.plants = None

    def __getstate__(self):                  # what goes to the workers: the name alone
        return {"name": self.name}

    def __setstate__(self, state):
        self.name, self.plants = state["name"], None

    def setup(self, worker):
        self.plants = PlantCache()

    def teardown(self, worker):
        self.plants = None


def worker_plants(name: str, dask_worker=None) -> PlantCache:
    """The PlantCache of run `name` on this Dask worker (`dask_worker`, or the worker running
    the current task)."""
    worker = dask_worker if dask_worker is not None else get_worker()
    plugin = worker.plugins[name]
    if plugin.plants is None:               # set up before any task runs; never None there
        plugin.plants = PlantCache()
    return plugin.plants


def preload_forkserver() -> None:
    """Before a LocalCluster starts under distributed.worker.multiprocessing-method =
    "forkserver": the fork server, when this process has not started it yet, imports
    FORKSERVER_PRELOAD. Dask's own list is set first (it sets it once per process), then
    this one replaces it; a server already running keeps what it imported."""
    from distributed.utils import get_mp_context
    get_mp_context().set_forkserver_preload(list(FORKSERVER_PRELOAD))


def worker_environment() -> dict:
    """This process's defaults that are not built in (from its environment or `defaults.set`),
    as environment text for the workers' nannies to set: a fork server keeps the environment
    it started with, and a case runs under this process's defaults wherever it runs (this
    process runs some while the workers start)."""
    from ... import defaults
    return {row["env"]: _text(row["value"]) for row in defaults.table()
            if row["source"] != "built-in"}


def _text(value) -> str:
    """A default's value as its environment variable reads it back (`defaults.get`)."""
    if isinstance(value, bool):
        return "1" if value else "0"
    return repr(value) if isinstance(value, float) else str(value)
