"""The one way files are written: complete or not at all, readable by everyone.

`atomic_path(path)` yields a temporary name in the target's folder; whatever the caller writes
there is flushed to disk (fsync) and renamed over `path` only when the block ends without an
error, so a crash, a kill or a full disk never leaves a truncated file under `path` (a reader
sees the old file or the new one). The file gets mode 0666 less the umask (0644 usually), as
`open` would give it: `tempfile.mkstemp` alone makes 0600, which hid case files and identify
outputs from other users. A failed write removes its temporary file.

A write the machine refuses (a full disk or quota, no permission, a read-only file system)
raises `EnvironmentProblem`, one sentence naming the path and what to do, instead of an
OSError whose traceback says neither (`guarded` does the same for other file work).
"""
from __future__ import annotations

import errno
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import EnvironmentProblem

# what a user fixes on the machine, not in the input; anything else stays as it was raised
_FULL = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC), errno.EFBIG}
_DENIED = {errno.EACCES, errno.EPERM}
ENVIRONMENT_ERRNOS = frozenset(_FULL | _DENIED | {errno.EROFS})
# a write that failed with a library's own error type (netCDF4/HDF5 say "HDF error") on a
# disk with less than this left is taken as disk full: no real write fails that way otherwise
_NEARLY_FULL_BYTES = 1 << 20


def environment_problem(exc: BaseException, path, doing: str = "writing"
                        ) -> EnvironmentProblem | None:
    """`exc` as the one-line EnvironmentProblem it stands for (naming `path`, what was being
    done and the remedy), or None when it is not about the machine."""
    path = Path(path)
    code = getattr(exc, "errno", None)
    unexplained = not isinstance(code, int) or code <= 0      # no errno, or a library's own
    if code not in ENVIRONMENT_ERRNOS and not (unexplained and _nearly_full(path)):
        return None
    folder = path.parent
    elsewhere = "or write elsewhere (for the cache: MBCONTROL_CACHE=/another/folder)"
    if code in _DENIED:
        fix = (f"make it readable (chmod u+r {path})" if doing == "reading" else
               f"make its folder writable (chmod u+w {folder})")
        text = f"{path}: permission denied while {doing} it; {fix} {elsewhere}"
    elif code == errno.EROFS:
        text = (f"{path}: read-only file system while {doing} it; write elsewhere (for the "
                f"cache: MBCONTROL_CACHE=/another/folder)")
    else:
        text = (f"{path}: no space left on the device (disk or quota full) while {doing} it; "
                f"free some space on it {elsewhere}")
    return EnvironmentProblem(text)


def _nearly_full(path: Path) -> bool:
    for folder in (path.parent, *path.parents):
        try:
            usage = shutil.disk_usage(folder)
        except OSError:                # not there (yet): ask its nearest existing parent
            continue
        return 0 < usage.total and usage.free < _NEARLY_FULL_BYTES     # not /proc's 0 of 0
    return False


@contextmanager
def guarded(path, doing: str = "writing"):
    """Context manager: an OSError of the machine's (environment_problem) raised in the block
    becomes its EnvironmentProblem; any other error passes unchanged."""
    try:
        yield
    except EnvironmentProblem:
        raise
    except (OSError, RuntimeError) as exc:
        problem = environment_problem(exc, path, doing)
        if problem is None:
            raise
        raise problem from exc


@contextmanager
def atomic_path(path, suffix: str = ""):
    """Context manager: a temporary Path beside `path` to write to; renamed onto `path`
    (parent folders created) when the block succeeds, removed when it fails."""
    path = Path(path)
    with guarded(path):
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix + ".tmp",
                                   dir=path.parent)
        os.close(fd)
        tmp = Path(tmp)
        try:
            yield tmp
            _commit(tmp, path)
        finally:
            tmp.unlink(missing_ok=True)


def _commit(tmp: Path, path: Path) -> None:
    """The data on disk (fsync) before the name points at it; then the usual mode, then the
    name."""
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    os.chmod(tmp, 0o666 & ~_umask())
    os.replace(tmp, path)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path, text: str) -> Path:
    """Write `text` (UTF-8) to `path` atomically; returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_bytes(path, data: bytes) -> Path:
    """Write `data` to `path` atomically; returns the path."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)
