"""What the command line does when the machine, not the input, stops it: a full disk or a
missing permission is one line naming the path and what to do, exit status 5, no traceback
(-v adds it); a cache folder that cannot be written is replaced by a private temporary one
with one warning saying how to fix it; a compiler that fails leaves the interpreted code,
with a warning. Tests run as root, where chmod 0o555 stops no write: a read-only folder is
made by a read-only bind mount in a private mount namespace (unshare -m), or the failure
is injected where the OS would raise it."""
import errno
import json
import os
import shutil
import subprocess
import sys

import pytest

from mbcontrol import atomic, cache
from mbcontrol.cache import CacheWarning
from mbcontrol.cli import main

SIMULATE = ["simulate", "sphere", "--wave", "regular", "--height", "1", "--period", "8",
            "--duration", "20", "--allow-invalid"]


@pytest.fixture
def quiet(monkeypatch):
    monkeypatch.setenv("MBCONTROL_QUIET", "1")


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _disk_full_at(monkeypatch, name):
    """The atomic writer meets a full disk when it commits a file called `name`."""
    commit = atomic._commit

    def full(tmp, path):
        if path.name == name:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp))
        commit(tmp, path)

    monkeypatch.setattr(atomic, "_commit", full)


def test_a_full_disk_is_one_line_and_status_5(capsys, monkeypatch, tmp_path, quiet):
    out_file = tmp_path / "run.nc"
    _disk_full_at(monkeypatch, "run.nc")
    code, _, err = _run(capsys, *SIMULATE, "--out", str(out_file))
    assert code == 5                        # was: OSError's traceback, status 1 of Python
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err == (f"mbcontrol: error: {out_file}: no space left on the device (disk or quota "
                   f"full) while writing it; free some space on it or write elsewhere (for the "
                   f"cache: MBCONTROL_CACHE=/another/folder)\n")
    assert not list(tmp_path.iterdir())     # no half file, no temporary left behind


def test_verbose_adds_the_traceback(capsys, monkeypatch, tmp_path, quiet):
    _disk_full_at(monkeypatch, "run.nc")
    code, _, err = _run(capsys, "-v", *SIMULATE, "--out", str(tmp_path / "run.nc"))
    assert code == 5 and "Traceback" in err and "OSError: [Errno 28]" in err
    assert err.rstrip().splitlines()[-1].startswith("mbcontrol: error: ")


@pytest.mark.parametrize("code, said", [(errno.EACCES, "permission denied while using it; "
                                                       "make its folder writable (chmod u+w /x)"),
                                        (errno.EROFS, "read-only file system while using it")])
def test_a_refused_write_anywhere_is_one_line(capsys, monkeypatch, code, said):
    """An OSError of the machine's raised outside the atomic writer (a plot, a log)."""
    from mbcontrol.cli import commands

    def run(args):
        raise OSError(code, os.strerror(code), "/x/out.png")
    monkeypatch.setattr(commands, "run_models", run)
    monkeypatch.setattr(sys.modules["mbcontrol.cli"], "run_models", run)
    status, _, err = _run(capsys, "models")
    assert status == 5 and err.startswith(f"mbcontrol: error: /x/out.png: {said}"), err
    assert err.count("\n") == 1


def test_an_other_os_error_is_still_a_bug(monkeypatch):
    from mbcontrol.cli import commands

    def run(args):
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", "/x/y")
    monkeypatch.setattr(commands, "run_models", run)
    monkeypatch.setattr(sys.modules["mbcontrol.cli"], "run_models", run)
    with pytest.raises(FileNotFoundError):
        main(["models"])


def test_a_cache_folder_that_is_a_file_falls_back_to_a_private_one(capsys, monkeypatch,
                                                                      tmp_path, quiet):
    blocked = tmp_path / "cache"
    blocked.write_text("not a folder")
    monkeypatch.setenv("MBCONTROL_CACHE", str(blocked))
    with pytest.warns(CacheWarning) as said:      # was: FileExistsError's traceback
        code, out, err = _run(capsys, "hydro", "sphere", "--tol", "0.3", "--json")
    assert code == 0, err
    (warning,) = [w for w in said if "cannot be written" in str(w.message)]
    text = str(warning.message)
    assert f"cache folder {blocked} cannot be written (a file is in its place)" in text
    assert "Fix: move that file away, or choose another folder: MBCONTROL_CACHE=" in text
    private = cache.cache_dir()
    assert private != blocked and list(private.glob("radiation_*.npz"))   # the fit went there
    assert json.loads(out)["tol"] == 0.3 and blocked.read_text() == "not a folder"


def test_an_unwritable_cache_folder_falls_back(monkeypatch, tmp_path):
    """Permission denied (what a non-root user meets in chmod 0o555), injected at the probe."""
    folder = tmp_path / "shared"
    folder.mkdir()
    monkeypatch.setenv("MBCONTROL_CACHE", str(folder))

    def refused(path):
        raise PermissionError(errno.EACCES, "Permission denied", str(path))
    monkeypatch.setattr(cache, "_probe", refused)
    with pytest.warns(CacheWarning, match=rf"cache folder {folder} cannot be written "
                                          rf"\(Permission denied\).*MBCONTROL_CACHE="):
        private = cache.cache_dir()
    assert private != folder and private.is_dir()
    with (private / "x.lock").open("w"):
        pass
    assert cache.cache_dir() == private        # once per process: no second probe, no warning


def test_a_lock_that_cannot_be_made_is_skipped(monkeypatch, tmp_path):
    """A read-only cache handed over with its entries: they are read without a lock."""
    def refused(*args, **kwargs):
        raise PermissionError(errno.EROFS, "Read-only file system", str(tmp_path / "e.lock"))
    monkeypatch.setattr(cache, "open", refused, raising=False)
    with cache.exclusive(tmp_path / "e.nc"):
        pass


def _read_only_bind_works(source, target) -> bool:
    if shutil.which("unshare") is None or shutil.which("mount") is None:
        return False
    probe = subprocess.run(["unshare", "-m", "sh", "-c",
                            f"mount --bind -o ro '{source}' '{target}' && ! touch '{target}/p'"],
                           capture_output=True)
    return probe.returncode == 0


def test_a_read_only_cache_folder_falls_back(tmp_path):
    """A real read-only file system (EROFS), in a private mount namespace of its own."""
    folder = tmp_path / "ro-cache"
    folder.mkdir()
    if not _read_only_bind_works(folder, folder):
        pytest.skip("no private read-only bind mount here (unshare -m, mount --bind -o ro)")
    env = {**os.environ, "MBCONTROL_CACHE": str(folder), "MBCONTROL_QUIET": "1"}
    command = (f"mount --bind -o ro '{folder}' '{folder}' && exec '{sys.executable}' -m "
               f"mbcontrol hydro sphere --tol 0.3 --json")
    run = subprocess.run(["unshare", "-m", "sh", "-c", command], capture_output=True,
                         text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr  # was: EROFS traceback at the fit's write
    assert "Traceback" not in run.stderr
    assert run.stderr.count("cannot be written") == 1, run.stderr
    assert f"cache folder {folder} cannot be written (Read-only file system)" in run.stderr
    assert json.loads(run.stdout)


def test_a_compiler_that_makes_nothing_leaves_interpreted_code(capsys, monkeypatch, tmp_path,
                                                              quiet):
    """CC=/bin/true "succeeds" and writes no library (was: FileNotFoundError's traceback)."""
    from mbcontrol.sim import compiled
    if not os.path.exists("/bin/true"):
        pytest.skip("no /bin/true")
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path / "cache"))
    reference = _run(capsys, *SIMULATE, "--json")
    assert reference[0] == 0, reference[2]
    monkeypatch.setenv("CC", "/bin/true")
    monkeypatch.setattr(compiled, "_FAILED", set())
    with pytest.warns(RuntimeWarning, match=r"C compilation failed \(/bin/true reported success "
                                            r"but made no library\); using interpreted"):
        code, out, err = _run(capsys, *SIMULATE, "--json")
    assert code == 0, err
    assert not list((tmp_path / "cache" / "compiled").glob("build-*"))
    ran, ref = json.loads(out), json.loads(reference[1])
    assert ran["ptos"]["pto"]["mean_power_W"] == pytest.approx(ref["ptos"]["pto"]["mean_power_W"],
                                                                rel=1e-9)


def test_a_compiler_not_installed_is_said_and_replaced(monkeypatch):
    from mbcontrol.sim import compiled
    if shutil.which("gcc") is None and shutil.which("cc") is None:
        pytest.skip("no C compiler")
    monkeypatch.setenv("CC", "/nowhere/cc")
    monkeypatch.setattr(compiled, "_warned_cc", False)
    with pytest.warns(RuntimeWarning, match=r"CC='/nowhere/cc' is not a command here; "
                                            r"compiling with (gcc|cc) instead"):
        assert compiled.compiler() in ("gcc", "cc")
