"""CI cannot pass by skipping: with MBCONTROL_REQUIRE_SHARED=1 (set by .ci/run) a test that
skips because ../shared "data not found" fails; other skips (no C compiler) stay skips."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

MISSING = '''import pytest
pytest.skip("tank data not found at /nowhere", allow_module_level=True)
def test_a(): pass
'''
MARKED = '''import pytest
@pytest.mark.skipif(True, reason="site data not found")
def test_b(): pass
@pytest.mark.skipif(True, reason="no C compiler")
def test_c(): pass
'''


def _run(folder: Path, required: bool) -> str:
    env = {k: v for k, v in os.environ.items() if k != "MBCONTROL_REQUIRE_SHARED"}
    if required:
        env["MBCONTROL_REQUIRE_SHARED"] = "1"
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-o", "addopts=", str(folder)], capture_output=True, text=True,
                          env=env, cwd=folder)
    return done.stdout.strip().splitlines()[-1]


def test_missing_shared_data_fails_only_when_required(tmp_path):
    shutil.copy(Path(__file__).parents[1] / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_missing.py").write_text(MISSING)
    (tmp_path / "test_marked.py").write_text(MARKED)
    assert _run(tmp_path, required=False).startswith("3 skipped in ")
    (tmp_path / "test_missing.py").unlink()
    assert _run(tmp_path, required=True).startswith("1 skipped, 1 error")
    (tmp_path / "test_marked.py").unlink()
    (tmp_path / "test_missing.py").write_text(MISSING)
    assert "1 error" in _run(tmp_path, required=True)
