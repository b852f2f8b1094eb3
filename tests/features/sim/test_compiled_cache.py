"""The compiled-code cache trusts nothing it finds: a damaged library (truncated by a full disk,
or foreign on a shared file system) is rebuilt with a warning instead of crashing the loader,
build folders of killed compiles are cleaned, and a failed compile is not reported as done."""
import os
import subprocess
import sys
import time

import casadi as ca
import pytest

from mbcontrol.sim import compiled


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path))
    monkeypatch.setenv("MBCONTROL_QUIET", "1")
    return tmp_path / "compiled"


def _square():
    x = ca.SX.sym("x")
    return ca.Function("square_test", [x], [x * x + 1])


def _compile_elsewhere():
    """Compile in another process, as a previous run did: this one never maps the library
    (truncating a library a process has loaded crashes that process, whatever its cache does)."""
    code = ("import casadi as ca; from mbcontrol.sim import compiled; x = ca.SX.sym('x'); "
            "compiled.compile_function(ca.Function('square_test', [x], [x * x + 1]))")
    subprocess.run([sys.executable, "-c", code], check=True, env=os.environ.copy())


pytestmark = pytest.mark.skipif(compiled.compiler() is None, reason="no C compiler")


def test_a_truncated_library_is_rebuilt_with_a_warning(cache):
    _compile_elsewhere()
    (library,) = cache.glob("square_test_*.so")
    record = library.with_suffix(".sha256")
    size, digest = record.read_text().split()
    assert int(size) == library.stat().st_size and len(digest) == 64
    library.write_bytes(library.read_bytes()[: int(size) // 3])        # a full disk's leftovers
    with pytest.warns(RuntimeWarning, match=r"square_test_.*\.so is damaged .* rebuilding it"):
        g = compiled.compile_function(_square())
    assert float(g(3.0)) == 10.0
    assert record.read_text().split()[0] == str(library.stat().st_size) == size


def test_a_library_without_its_record_is_rebuilt_and_stale_builds_are_removed(cache):
    _compile_elsewhere()
    (library,) = cache.glob("square_test_*.so")
    library.with_suffix(".sha256").unlink()
    stale, fresh = cache / "build-killed", cache / "build-running"
    for folder in (stale, fresh):
        folder.mkdir()
        (folder / "square_test.c").write_text("/* left behind */")
    old = time.time() - 2 * compiled.STALE_BUILD_S
    os.utime(stale, (old, old))
    f = compiled.compile_function(_square())             # no record: rebuilt, quietly
    assert float(f(2.0)) == 5.0 and library.with_suffix(".sha256").exists()
    assert not stale.exists() and fresh.exists()


def test_a_failed_compile_falls_back_and_caches_nothing(cache, monkeypatch):
    monkeypatch.setattr(compiled, "FLAGS", ("-definitely-not-a-flag",))
    with pytest.warns(RuntimeWarning, match="C compilation failed"):
        f = compiled.compile_function(_square())
    assert float(f(3.0)) == 10.0                        # the interpreted function
    assert not list(cache.glob("*.so")) and not list(cache.glob("build-*"))


def test_two_processes_needing_the_same_code_compile_it_once(cache):
    """Two processes start compiling one new function at once (as two test or sweep workers
    on a cold cache do): the second waits on the build lock and loads the first's library.
    The function is big enough (a 60-term polynomial chain, about a second of -O3) that the
    two builds overlap: without the lock both compile (checked: 2 compiles). Counted from each
    process's "compiled lock_test in" log line."""
    code = ("import logging, sys, casadi as ca; from mbcontrol.sim import compiled\n"
            "logging.basicConfig(level=logging.INFO, stream=sys.stdout, format='%(message)s')\n"
            "x = ca.SX.sym('x', 40); y = x\n"
            "for k in range(60): y = ca.sin(y) * y + k * ca.cos(y[::-1])\n"
            "f = compiled.compile_function(ca.Function('lock_test', [x], [ca.sum1(y)]))\n"
            "print('value', float(f(ca.DM.ones(40))))\n")
    env = {**os.environ, "MBCONTROL_QUIET": "0"}
    runs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, env=env) for _ in range(2)]
    outputs = [r.communicate(timeout=300)[0] for r in runs]
    assert all(r.returncode == 0 for r in runs), outputs
    compiles = sum(out.count("compiled lock_test in") for out in outputs)
    assert compiles == 1, outputs
    values = {line for out in outputs for line in out.splitlines() if line.startswith("value")}
    assert len(values) == 1                          # both loaded the one library
    assert len(list(cache.glob("lock_test_*.so"))) == 1
