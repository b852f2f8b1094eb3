"""The plants a sweep run keeps on a Dask worker: a worker plugin registered per run under a
name of its own, so two runs on one cluster (or one after the other) never share a plant, and
a worker that restarts mid-run gets a fresh cache from the scheduler. Imported only where Dask
is used (it imports `distributed`)."""
from __future__ import annotations

import uuid

from distributed import WorkerPlugin, get_worker

from .case_run import PlantCache


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
