"""Every notebook in notebooks/ runs top to bottom (its own asserts included). The executed
copy is kept in out/notebooks/ for the documentation (`make docs` renders it with its figures
instead of running the notebook again)."""
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

from mbcontrol.atomic import atomic_path

ROOT = Path(__file__).parent.parent
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXECUTED = ROOT / "out" / "notebooks"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path):
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    EXECUTED.mkdir(parents=True, exist_ok=True)
    with atomic_path(EXECUTED / path.name) as tmp:
        nbformat.write(nb, str(tmp))


def test_there_are_notebooks():
    assert NOTEBOOKS, "notebooks/ has no .ipynb files"
