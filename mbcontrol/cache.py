"""Where BEM results, radiation fits and compiled code are cached: the default "cache.folder"
($MBCONTROL_CACHE, else ~/.cache/mbcontrol; mbcontrol.defaults). Generated C and compiled
libraries go here and nowhere else.

A cache must never turn one bad moment into failures that stick. So:
- a folder this process cannot write (read-only, another user's, a file in its place) is
  replaced, for this process, by a private temporary folder, with one warning saying how to
  fix it (`cache_dir`);
- an entry that cannot be read (truncated by a full disk or a kill before writes were atomic,
  damaged on a shared file system) is moved aside as `<name>.corrupt-<time>` (kept for a
  look, never deleted), with a warning naming it, and made again once; if the new one cannot
  be read either, an EnvironmentProblem names it (`read_entry`, `load_or_make`, and
  `rebuilt_once` where the reading happens deep inside the code that makes the entry).
Sweep and co-design stores use the same readers: an unreadable case is run again, the others
are kept.
"""
from __future__ import annotations

import atexit
import contextlib
import errno
import os
import shutil
import tempfile
import time
import warnings
import zipfile
from contextvars import ContextVar
from pathlib import Path

from . import defaults
from .atomic import ENVIRONMENT_ERRNOS, environment_problem, guarded
from .errors import EnvironmentProblem, MbcontrolError

# what reading a damaged file raises: numpy's npz (BadZipFile, EOFError, ValueError, KeyError),
# json (ValueError), netCDF through mbcontrol.results (DataFileError, a ValueError), the OS
UNREADABLE = (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile)


class CacheWarning(RuntimeWarning):
    """An unreadable cache or store entry was set aside, or the cache folder is not writable."""


class EntrySetAside(MbcontrolError):
    """A reader set an unreadable cache entry aside but cannot make it again itself (the
    caller that makes the entry does: `rebuilt_once`). Should it reach a user, it still says
    what happened and that running again rebuilds the entry."""

    def __init__(self, path, aside, reason: str):
        super().__init__(f"{path}: unreadable cache entry ({reason}); moved aside to "
                         f"{Path(aside).name if aside else 'nowhere (already gone)'}; "
                         f"run again to rebuild it")
        self.path = Path(path)


_usable: dict[str, Path] = {}      # configured folder -> the folder this process uses
_private: list[Path] = []           # this process's temporary cache, made at most once


def cache_dir() -> Path:
    """The cache folder (created if missing); a private temporary one if it cannot be written."""
    folder = Path(defaults.get("cache.folder")).expanduser()
    known = _usable.get(str(folder))
    if known is not None and known != folder:
        return known
    try:
        folder.mkdir(parents=True, exist_ok=True)     # again: a test may have removed it
        if known is None:                             # checked once per folder and process
            _probe(folder)
        known = folder
    except OSError as exc:
        known = _private_cache(folder, exc)
    _usable[str(folder)] = known
    return known


def _probe(folder: Path) -> None:
    """Raise the OSError a write in `folder` meets. Actually writing is the only test that
    holds: os.access passes for root whatever the mode, and knows nothing of ACLs."""
    fd, name = tempfile.mkstemp(prefix=".write-test-", dir=folder)
    os.close(fd)
    os.unlink(name)


def _private_cache(folder: Path, exc: OSError) -> Path:
    reason, fix = exc.strerror or str(exc), f"make it writable (chmod u+w {folder}), or "
    if not _private:
        try:
            _private.append(Path(tempfile.mkdtemp(prefix="mbcontrol-cache-")))
        except OSError as again:
            raise EnvironmentProblem(
                f"cache folder {folder} cannot be written ({reason}), nor a temporary folder "
                f"in {tempfile.gettempdir()} ({again.strerror or again}); set MBCONTROL_CACHE "
                f"to a writable folder") from again
        atexit.register(_remove_private, _private[0], os.getpid())
    if folder.exists() and not folder.is_dir():
        reason, fix = "a file is in its place", "move that file away, or "
    elif exc.errno == errno.EROFS:
        fix = ""                           # chmod cannot help on a read-only file system
    warnings.warn(f"cache folder {folder} cannot be written ({reason}); this process caches "
                  f"in {_private[0]} instead, removed when it ends (BEM solves, radiation fits "
                  f"and compiled code are made again each run). Fix: {fix}choose another "
                  f"folder: MBCONTROL_CACHE=/a/writable/folder", CacheWarning, stacklevel=3)
    return _private[0]


def _remove_private(folder: Path, owner: int) -> None:
    if os.getpid() == owner:      # a forked child inherits the hook, not the folder
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def exclusive(path: Path):
    """Held while `path` (a cache entry) is made: a second process needing the same entry (a
    test worker, a sweep's Dask worker) waits for the first and loads its result instead of
    making it again (two test workers compiling raft3's 275-state chunk at once each took
    twice as long; two solving WaveBot's BEM, 40 s each). An advisory lock (fcntl) on
    `path`.lock, released by the kernel if its holder dies; where fcntl is missing, or the
    folder cannot be written (a read-only cache handed over as it is), no lock: concurrent
    writers stay safe (entries are written atomically), only wasteful, and a write that
    must happen says why it cannot."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    lock = Path(path).with_suffix(".lock")
    try:
        lock.parent.mkdir(parents=True, exist_ok=True)
        handle = open(lock, "a")
    except OSError as exc:
        if environment_problem(exc, lock) is None:
            raise
        handle = None
    if handle is None:
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def set_aside(path, reason: str, *, what: str = "cache entry", then: str = "rebuilding it",
              seen: os.stat_result | None = None) -> Path | None:
    """Rename the unreadable entry `path` to `<name>.corrupt-<time>` beside it and warn
    (CacheWarning: `what`, the path, `reason`, where it went and `then`, what happens next).
    None if another process moved or replaced it first (`seen`: its stat when it was read;
    a newer file is someone's good rebuild, left alone)."""
    path = Path(path)
    if seen is not None and not _same_file(path, seen):
        return None
    stamp = time.strftime("%Y%m%dT%H%M%S")
    aside, n = path.with_name(f"{path.name}.corrupt-{stamp}"), 1
    while aside.exists():
        n += 1
        aside = path.with_name(f"{path.name}.corrupt-{stamp}-{n}")
    try:
        with guarded(path, "moving aside an unreadable copy of"):
            os.rename(path, aside)
    except FileNotFoundError:
        return None
    warnings.warn(f"{what} {path} is damaged or unreadable ({reason}); moved aside to "
                  f"{aside.name}; {then}", CacheWarning, stacklevel=3)
    return aside


def _same_file(path: Path, seen: os.stat_result) -> bool:
    try:
        now = path.stat()
    except OSError:
        return False
    return (now.st_ino, now.st_size, now.st_mtime_ns) == (seen.st_ino, seen.st_size,
                                                          seen.st_mtime_ns)


def reason_of(exc: BaseException) -> str:
    """An exception as a short clause for a one-line message."""
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text[:200]}" if text else type(exc).__name__


def read_entry(path, read, *, what: str = "cache entry", then: str = "rebuilding it"):
    """read(path) for an entry that exists; None when it is missing, or unreadable: then it is
    set aside (`set_aside`) so that the caller makes it again. A file this process may not
    read is an EnvironmentProblem, not damage."""
    path = Path(path)
    try:
        seen = path.stat()
    except FileNotFoundError:
        return None
    try:
        return read(path)
    except EnvironmentProblem:
        raise
    except EntrySetAside:                                 # the reader has set it aside
        return None
    except UNREADABLE as exc:
        if isinstance(exc, FileNotFoundError) and not path.exists():
            return None                                   # another process set it aside
        if getattr(exc, "errno", None) in ENVIRONMENT_ERRNOS:     # not damage: access
            raise environment_problem(exc, path, "reading") from exc
        set_aside(path, reason_of(exc), what=what, then=then, seen=seen)
        return None


def load_or_make(path, read, make, *, what: str = "cache entry"):
    """The entry at `path` read by read(path), made first by make(path) (which writes it) when
    it is missing or unreadable (set aside); under `exclusive(path)`. Made once: if the new
    entry cannot be read either, EnvironmentProblem naming it."""
    with exclusive(path):
        value = read_entry(path, read, what=what)
        if value is not None:
            return value
        make(path)
        value = read_entry(path, read, what=what, then="not trying again")
    if value is None:
        raise _still_unreadable(path, what)
    return value


def rebuilt_once(attempt):
    """attempt() (which makes a cache entry if missing, then reads it), and once more if its
    reader set the entry aside (EntrySetAside); a second failure is an EnvironmentProblem."""
    try:
        return attempt()
    except EntrySetAside:
        try:
            return attempt()
        except EntrySetAside as again:
            raise _still_unreadable(again.path, "cache entry") from again


def _still_unreadable(path, what: str) -> EnvironmentProblem:
    return EnvironmentProblem(
        f"{path}: the {what} was made again and still cannot be read (both copies are kept "
        f"beside it as .corrupt-*); the disk or file system may be failing or full: check it, "
        f"or point MBCONTROL_CACHE at another folder")


def in_cache(path) -> bool:
    """Is `path` an entry of this process's cache folder?"""
    try:
        return Path(path).resolve().is_relative_to(cache_dir().resolve())
    except OSError:
        return False


class ServedLog:
    """What a cache served, told to a caller that asks: inside `with log.recording() as
    served:` every entry noted (`log.note`) is appended to `served`, for each recorder active
    (nested ones each get it); with none active, noting does nothing. The active recorders are
    a ContextVar, so nothing is kept between calls and no caller sees another's (threads and
    tasks each start with none). models/generate_hydro.py --ship-fits records the fits and
    MoorDyn statics the catalogue's plants use."""

    def __init__(self, name: str):
        self._recorders: ContextVar[tuple] = ContextVar(name, default=())

    def note(self, item) -> None:
        for served in self._recorders.get():
            served.append(item)

    @contextlib.contextmanager
    def recording(self):
        served: list = []
        token = self._recorders.set(self._recorders.get() + (served,))
        try:
            yield served
        finally:
            self._recorders.reset(token)
