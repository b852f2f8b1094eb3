"""Where BEM results, radiation fits and compiled code are cached: the default "cache.folder"
($MBCONTROL_CACHE, else ~/.cache/mbcontrol; mbcontrol.defaults). Generated C and compiled
libraries go here and nowhere else."""
from __future__ import annotations

import contextlib
import logging
import sys
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


def status(message: str, name: str = "mbcontrol") -> None:
    """One line for a long job the cache will spare next time (a radiation fit, a
    compilation): what it is doing and how long it usually takes. Logged at INFO on the
    logger `name` (a package's, e.g. "mbcontrol.hydro.model"; they all propagate to
    "mbcontrol"). Unless the application configured logging itself, the "mbcontrol" logger
    gets one stderr handler ("mbcontrol: ..."), at INFO, or WARNING with MBCONTROL_QUIET=1
    (the CLI's -q and -v set the level too)."""
    _ensure_handler()
    logging.getLogger(name).info(message)


class _Stderr(logging.StreamHandler):
    """Writes to the sys.stderr of the moment, which pytest and notebooks swap."""

    def __init__(self):
        super().__init__(sys.stderr)

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, value):
        pass


def _ensure_handler() -> None:
    logger = logging.getLogger("mbcontrol")
    if logger.handlers or logging.getLogger().handlers:
        return                           # the application decides where messages go
    handler = _Stderr()
    handler.setFormatter(logging.Formatter("mbcontrol: %(message)s"))
    logger.addHandler(handler)
    if logger.level == logging.NOTSET:
        logger.setLevel(logging.WARNING if defaults.get("log.quiet") else logging.INFO)


def set_verbosity(level: int) -> None:
    """The "mbcontrol" logger's level (logging.DEBUG, INFO, WARNING ...), e.g. from -v / -q."""
    _ensure_handler()
    logging.getLogger("mbcontrol").setLevel(level)


def progress_bar(**options):
    """A tqdm bar for long work, off when the default "log.quiet" is set (-q, MBCONTROL_QUIET=1)
    or TQDM_DISABLE is; options go to tqdm (total, desc, unit ...)."""
    from tqdm.auto import tqdm
    if defaults.get("log.quiet"):
        options["disable"] = True
    return tqdm(**options)


def flush_c_stdio() -> None:
    """Flush C's standard I/O buffers (a compiled library's printf to a pipe is buffered, and
    would come out after the Python side has moved the descriptor it was meant for)."""
    import ctypes
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass
