"""The console: mbcontrol's messages and progress bars. One-line status messages go to the
"mbcontrol" logger (a stderr handler unless the application configured logging; the CLI's
-q and -v set its level), long work shows a tqdm bar unless "log.quiet" is set, and C
libraries' buffered output is flushed before Python moves a descriptor."""
from __future__ import annotations

import logging
import sys

from . import defaults


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
    """A tqdm bar for long work, on a terminal or in a Jupyter kernel only: off when stderr is
    a pipe or a file (a CI log, `2> log`: a bar redrawn with carriage returns garbles them),
    when the default "log.quiet" is set (-q, MBCONTROL_QUIET=1) or TQDM_DISABLE is; options
    go to tqdm (total, desc, unit ...)."""
    from tqdm.auto import tqdm
    if defaults.get("log.quiet") or not _interactive():
        options["disable"] = True
    return tqdm(**options)


def _interactive() -> bool:
    """Does a person watch stderr: a terminal, or a notebook's kernel?"""
    try:
        if sys.stderr.isatty():
            return True
    except (AttributeError, ValueError):       # a closed or a bare stream
        pass
    return "ipykernel" in sys.modules


def flush_c_stdio() -> None:
    """Flush C's standard I/O buffers (a compiled library's printf to a pipe is buffered, and
    would come out after the Python side has moved the descriptor it was meant for)."""
    import ctypes
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass
