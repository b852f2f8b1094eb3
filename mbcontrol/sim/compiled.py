"""Compile CasADi Functions to native code with the system C compiler, cached on disk.

The cache key is the generated C source itself (plus flags, CasADi version, the compiler and
its version, the platform and the CPU), so code is reused across processes whenever the
structure is the same; parameters that stay symbolic (PTO, friction, ...) do not enter the key.
Without a compiler, the interpreted Function is returned, with one warning.

Every library is checked before it is loaded: its size and SHA-256, recorded beside it
(`.sha256`) when it was built, must match. A truncated or foreign file (a full disk, a cache
shared over a network file system) would otherwise crash the process in the loader with no
message (a bus error); a mismatch is rebuilt, with a warning. Build folders left by a killed
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

from ..atomic import write_text
from ..cache import cache_dir, exclusive
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
PLAIN_FLAGS = ("-O0", "-shared", "-fPIC")
_warned = False


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
    """True if the library matches its recorded size and hash; a damaged or unrecorded one is
    removed (with a warning when it was damaged) so that it is rebuilt."""
    record = library.with_suffix(".sha256")
    try:
        expected = record.read_text().strip()
        found = _digest(library)
    except OSError:
        expected, found = None, None
    if expected is not None and found == expected:
        return True
    if expected is not None:
        warnings.warn(f"compiled cache entry {library} is damaged (size and SHA-256 {found!r}, "
                      f"recorded {expected!r}); rebuilding it", RuntimeWarning, stacklevel=3)
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
    """The C compiler to use ($CC, else gcc, else cc), or None."""
    for name in (os.environ.get("CC"), "gcc", "cc"):
        if name and shutil.which(name):
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
    folder.mkdir(parents=True, exist_ok=True)
    generator = ca.CodeGenerator(f"{fun.name()}.c", {"with_header": False})
    generator.add(fun)
    source = generator.dump()
    flags = FLAGS if optimise else PLAIN_FLAGS
    key = hashlib.sha256((source + " ".join(flags) + ca.__version__ + cc + _tag(cc)
                          + _cpu_tag()).encode())
    library = folder / f"{fun.name()}_{key.hexdigest()[:20]}.so"
    if library.exists() and _verified(library):
        return ca.external(fun.name(), str(library))
    with exclusive(library):   # a second process needing this code waits and loads it
        if library.exists() and _verified(library):     # another process just built it
            return ca.external(fun.name(), str(library))
        return _build(fun, source, flags, cc, folder, library, label or fun.name())


def _build(fun, source, flags, cc, folder: Path, library: Path, label: str) -> ca.Function:
    """Compile `source` into `library` (see compile_function); the interpreted `fun` on a
    compiler error, with a warning."""
    _remove_stale_builds(folder)
    started = time.perf_counter()
    status(f"compiling {label} ({len(source) // 1000} kB of C): typically 2-60 s, cached "
           f"afterwards (each distinct structure compiles once)", __name__)
    with tempfile.TemporaryDirectory(prefix="build-", dir=folder) as tmp:
        c_file = Path(tmp) / f"{fun.name()}.c"
        c_file.write_text(source)
        built = Path(tmp) / "out.so"
        result = subprocess.run([cc, *flags, str(c_file), "-o", str(built), "-lm"],
                                capture_output=True, text=True)
        if result.returncode != 0:
            warnings.warn(f"C compilation failed ({result.stderr[:300]}); using "
                          f"interpreted CasADi code", RuntimeWarning, stacklevel=3)
            return fun
        seconds = time.perf_counter() - started
        status(f"compiled {label} in {seconds:.1f} s", __name__)
        with open(folder / "builds.log", "a") as log:     # what the cache cost, one line a build
            log.write(f"{time.strftime('%Y-%m-%dT%H:%M:%S')}\t{fun.name()}\t"
                      f"{len(source) // 1000} kB\t{seconds:.2f} s\t{flags[0]}\n")
        # the record first, then the library: a library is never there without its record
        write_text(library.with_suffix(".sha256"), _digest(built) + "\n")
        os.replace(built, library)        # atomic: readers never see half a library
    return ca.external(fun.name(), str(library))


_TAGS: dict = {}


def _tag(cc: str) -> str:
    if cc not in _TAGS:
        _TAGS[cc] = _compiler_tag(cc)
    return _TAGS[cc]
