"""The one way files are written: complete or not at all, readable by everyone.

`atomic_path(path)` yields a temporary name in the target's folder; whatever the caller writes
there is flushed to disk (fsync) and renamed over `path` only when the block ends without an
error, so a crash, a kill or a full disk never leaves a truncated file under `path` (a reader
sees the old file or the new one). The file gets mode 0666 less the umask (0644 usually), as
`open` would give it: `tempfile.mkstemp` alone makes 0600, which hid case files and identify
outputs from other users. A failed write removes its temporary file.
"""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_path(path, suffix: str = ""):
    """Context manager: a temporary Path beside `path` to write to; renamed onto `path`
    (parent folders created) when the block succeeds, removed when it fails."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix + ".tmp", dir=path.parent)
    os.close(fd)
    tmp = Path(tmp)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:       # the data on disk before the name points at it
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


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
