"""The one way studies start a local Dask cluster: listening on this machine only.

A LocalCluster left to its defaults serves its scheduler's web server (the dashboard, or with
`dashboard_address=None` still its health and metrics routes) on every interface, port 8787: a
sweep on a laptop in a café would serve its cluster to the café. Here the scheduler, the
workers and that web server bind `dask.host` (default 127.0.0.1), the web server on a free
port; a user who wants a cluster others can reach names the address (MBCONTROL_DASK_HOST) or
starts a scheduler and passes `scheduler=`.
"""
from __future__ import annotations

from .. import defaults


def local_cluster(n_workers: int, **options):
    """A dask.distributed.LocalCluster of `n_workers` single-threaded worker processes whose
    scheduler, workers and web server (`cluster.dashboard_link`) listen on `dask.host` only,
    the web server on a free port. `options` go to LocalCluster."""
    from dask.distributed import LocalCluster
    host = str(defaults.get("dask.host"))
    options.setdefault("threads_per_worker", 1)
    options.setdefault("processes", True)
    return LocalCluster(n_workers=n_workers, host=host, dashboard_address=f"{host}:0", **options)
