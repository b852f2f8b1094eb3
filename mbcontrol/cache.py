"""Where BEM results, radiation fits and compiled code are cached: the default "cache.folder"
($MBCONTROL_CACHE, else ~/.cache/mbcontrol; mbcontrol.defaults). Generated C and compiled
libraries go here and nowhere else."""
from __future__ import annotations

import contextlib
from pathlib import Path

from . import defaults


def cache_dir() -> Path:
    """The cache folder (created if missing)."""
    path = Path(defaults.get("cache.folder")).expanduser()
    path.mkdir(parents=True, exist_ok=True)
    return path


@contextlib.contextmanager
def exclusive(path: Path):
    """Held while `path` (a cache entry) is made: a second process needing the same entry (a
    test worker, a sweep's Dask worker) waits for the first and loads its result instead of
    making it again (two test workers compiling raft3's 275-state chunk at once each took
    twice as long; two solving WaveBot's BEM, 40 s each). An advisory lock (fcntl) on
    `path`.lock, released by the kernel if its holder dies; where fcntl is missing, no lock:
    concurrent writers stay safe (entries are written atomically), only wasteful."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    lock = Path(path).with_suffix(".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    with open(lock, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
