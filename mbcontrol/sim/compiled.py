"""Compile CasADi Functions to native code with the system C compiler, cached on disk.

The cache key is the generated C source itself (plus flags, CasADi version, the compiler and
its version, the platform and the CPU), so code is reused across processes whenever the
structure is the same; parameters that stay symbolic (PTO, friction, ...) do not enter the key.
Without a compiler, the interpreted Function is returned, with one warning; so it is when the
compiler fails (exits with an error, makes no library, or makes one the loader refuses: one
warning per compiler and flags, naming what failed and to set CC). A full disk or a cache
folder that cannot be written is an EnvironmentProblem naming the folder.

Every library is checked before it is loaded: its size and SHA-256, recorded beside it
(`.sha256`) when it was built, must match. A truncated or foreign file (a full disk, a cache
shared over a network file system) would otherwise crash the process in the loader with no
message (a bus error); a mismatch is moved aside (mbcontrol.cache.set_aside) and rebuilt,
with a warning. Build folders left by a killed
compile are removed once they are an hour old (a concurrent compile's are younger). Concurrent
compiles of one function are safe: each builds in its own folder and renames into place; and
where fcntl exists a per-library lock makes the second process wait for the first's library
instead of compiling it again.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

import casadi as ca

from .. import defaults
from ..atomic import guarded, write_text
from ..cache import cache_dir, exclusive, reason_of, set_aside
from ..console import status

# -O3 for this CPU, and reassociation so that the radiation model's dense products vectorise;
# NaN and Inf keep their IEEE meaning (no -ffinite-math-only), so divergence is still caught.
# Measured on the hinged barge: 1.5x faster than -O2, results equal to 1e-16.
FLAGS = ("-O3", "-march=native", "-fno-math-errno", "-fassociative-math", "-fno-signed-zeros",
         "-fno-trapping-math", "-freciprocal-math", "-shared", "-fPIC")
# Unoptimised, for code that runs once per sample and is mostly a farm's radiation constants (the
# output map of array_grid's 16 floats, 706 kB of C): gcc -O3 took 12 s on it, -O0 0.8 s, and
# the 6,000 samples of a 60 s record are then mapped in 0.25 s. (Its step, run 24,000 times per
# 60 s, stays optimised: -O0 made those 15x slower.)
# (Since 2026-12-06 a farm's step and outputs hold its couplings as data, module plant.pieces:
# short code, compiled with FLAGS.)
PLAIN_FLAGS = ("-O0", "-shared", "-fPIC")
# Said-once flags: which warnings this process has given (messages, never results)
_warned = False
_warned_cc = False


def _cpu_tag() -> str:
    """The CPU model and features: -march=native code must not be reused on another CPU."""
    try:
        lines = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        import platform
        return platform.machine() + platform.processor()
    return "".join(sorted({l for l in lines if l.startswith(("model name", "flags"))}))


STALE_BUILD_S = 3600.0      # a build folder this old belongs to a killed process


def _compiler_tag(cc: str) -> str:
    """The compiler's version line and the platform: a library is only reused where it was made."""
    import platform
    try:
        version = subprocess.run([cc, "--version"], capture_output=True, text=True,
                                 timeout=30).stdout.splitlines()[:1]
    except (OSError, subprocess.SubprocessError):
        version = []
    return " ".join(version) + platform.platform()


def _digest(path: Path) -> str:
    return f"{path.stat().st_size} {hashlib.sha256(path.read_bytes()).hexdigest()}"


def _verified(library: Path) -> bool:
    """True if the library matches its recorded size and hash. A damaged one is moved aside
    (mbcontrol.cache.set_aside: kept as .corrupt-*, with a warning) and an unrecorded one
    removed, so that either is rebuilt."""
    record = library.with_suffix(".sha256")
    try:
        expected = record.read_text().strip()
        found = _digest(library)
    except OSError:
        expected, found = None, None
    if expected is not None and found == expected:
        return True
    if expected is not None:
        set_aside(library, f"size and SHA-256 {found!r}, recorded {expected!r}",
                  what="compiled cache entry")
    library.unlink(missing_ok=True)
    record.unlink(missing_ok=True)
    return False


def _remove_stale_builds(folder: Path) -> None:
    now = time.time()
    for build in folder.glob("build-*"):
        try:
            if now - build.stat().st_mtime > STALE_BUILD_S:
                shutil.rmtree(build, ignore_errors=True)
        except OSError:
            pass


def compiler() -> str | None:
    """The C compiler to use (the default "compile.cc", i.e. $CC, else gcc, else cc), or None.
    One that is not a command here is said once, and gcc or cc used instead."""
    global _warned_cc
    wanted = str(defaults.get("compile.cc")) or None
    for name in (wanted, "gcc", "cc"):
        if name and shutil.which(name):
            if wanted and name != wanted and not _warned_cc:
                warnings.warn(f"CC={wanted!r} is not a command here; compiling with {name} "
                              f"instead (unset CC, or set it to an installed C compiler)",
                              RuntimeWarning, stacklevel=3)
                _warned_cc = True
            return name
    return None


def compile_function(fun: ca.Function, enabled: bool = True, optimise: bool = True, *,
                     label: str | None = None) -> ca.Function:
    """A native-code version of `fun` (same signature), from the cache when possible; FLAGS, or
    PLAIN_FLAGS with ``optimise=False``. label: what the compile message calls it (default
    its name), so that two structures of one name read apart."""
    global _warned
    cc = compiler() if enabled else None
    if cc is None:
        if enabled and not _warned:
            warnings.warn("no C compiler found; simulating with interpreted CasADi code "
                          "(correct, slower)", RuntimeWarning, stacklevel=2)
            _warned = True
        return fun
    folder = cache_dir() / "compiled"
    with guarded(folder, "creating"):
        folder.mkdir(parents=True, exist_ok=True)
    generator = ca.CodeGenerator(f"{fun.name()}.c", {"with_header": False})
    generator.add(fun)
    source = generator.dump()
    flags = FLAGS if optimise else PLAIN_FLAGS
    key = hashlib.sha256((source + " ".join(flags) + ca.__version__ + cc + _tag(cc)
                          + _cpu_tag()).encode())
    library = folder / f"{fun.name()}_{key.hexdigest()[:20]}.so"
    if library.exists() and _verified(library):
        return _load(fun, library, cc, flags)
    with exclusive(library):   # a second process needing this code waits and loads it
        if library.exists() and _verified(library):     # another process just built it
            return _load(fun, library, cc, flags)
        return _build(fun, source, (cc, flags), folder, library, label or fun.name())


def _build(fun, source, how, folder: Path, library: Path, label: str) -> ca.Function:
    """Compile `source` into `library` with how = (compiler, flags) (see compile_function);
    the interpreted `fun` when the compiler fails, with a warning. A full disk or a folder
    that cannot be written is an EnvironmentProblem naming the folder."""
    cc, flags = how
    _remove_stale_builds(folder)
    started = time.perf_counter()
    status(f"compiling {label} ({len(source) // 1000} kB of C): typically 2-60 s, cached "
           f"afterwards (each distinct structure compiles once)", __name__)
    with guarded(folder, "compiling into"), \
            tempfile.TemporaryDirectory(prefix="build-", dir=folder) as tmp:
        c_file = Path(tmp) / f"{fun.name()}.c"
        c_file.write_text(source)
        built = Path(tmp) / "out.so"
        failure = _compile([cc, *flags, str(c_file), "-o", str(built), "-lm"], built)
        if failure:
            return _interpreted(fun, how, failure)
        seconds = time.perf_counter() - started
        status(f"compiled {label} in {seconds:.1f} s", __name__)
        with open(folder / "builds.log", "a") as log:     # what the cache cost, one line a build
            log.write(f"{time.strftime('%Y-%m-%dT%H:%M:%S')}\t{fun.name()}\t"
                      f"{len(source) // 1000} kB\t{seconds:.2f} s\t{flags[0]}\n")
        # the record first, then the library: a library is never there without its record
        write_text(library.with_suffix(".sha256"), _digest(built) + "\n")
        os.replace(built, library)        # atomic: readers never see half a library
    return _load(fun, library, cc, flags)


def _compile(command: list, built: Path) -> str | None:
    """Run the compiler; None if it made `built`, else what went wrong (one line)."""
    try:
        result = subprocess.run(command, capture_output=True, text=True)
    except OSError as exc:                            # not executable, gone meanwhile
        return f"{command[0]} could not be run: {exc.strerror or exc}"
    if result.returncode != 0:
        said = " ".join(result.stderr.split())[:300]
        return f"{command[0]} exited with status {result.returncode}" + (f": {said}" if said else "")
    if not built.is_file() or built.stat().st_size == 0:
        return f"{command[0]} reported success but made no library"
    return None


def _load(fun, library: Path, cc: str, flags) -> ca.Function:
    """The compiled Function in `library`; one the loader refuses (made by a broken compiler)
    is moved aside and `fun` runs interpreted."""
    try:
        return ca.external(fun.name(), str(library))
    except RuntimeError as exc:
        set_aside(library, reason_of(exc), what="compiled cache entry", then="not using it")
        library.with_suffix(".sha256").unlink(missing_ok=True)
        return _interpreted(fun, (cc, flags), f"its library does not load: {reason_of(exc)}")


_FAILED: set = set()        # (compiler, flags) that failed here: said once, not per function


def _interpreted(fun, how, why: str) -> ca.Function:
    if how not in _FAILED:
        _FAILED.add(how)
        warnings.warn(f"C compilation failed ({why}); using interpreted CasADi code (correct, "
                      f"slower). To compile, set CC to a working C compiler (e.g. CC=gcc)",
                      RuntimeWarning, stacklevel=4)
    return fun


_TAGS: dict = {}            # a cache, not state: compiler -> its version line (pure lookup)


def _tag(cc: str) -> str:
    if cc not in _TAGS:
        _TAGS[cc] = _compiler_tag(cc)
    return _TAGS[cc]
