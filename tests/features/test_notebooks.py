"""Every notebook in notebooks/ runs top to bottom (its own asserts included). The executed
copy is kept in out/notebooks/ for the documentation (`make docs` renders it with its figures
instead of running the notebook again)."""
import json
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

from mbcontrol.atomic import atomic_path

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXECUTED = ROOT / "out" / "notebooks"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path, monkeypatch):
    """...and, as the documentation shows it (make_docs.tidy), holds no compile message,
    progress bar or path of the machine that ran it."""
    monkeypatch.setenv("MBCONTROL_QUIET", "1")        # the kernel's: no status lines or bars
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    EXECUTED.mkdir(parents=True, exist_ok=True)
    with atomic_path(EXECUTED / path.name) as tmp:
        nbformat.write(nb, str(tmp))
    shown = json.dumps([cell.get("outputs", []) for cell in _tidy()(nb).cells])
    leaks = [w for w in (str(ROOT), sys.prefix, "site-packages", "compiling", "mbcontrol: ")
             if w in shown]
    assert not leaks, f"{path.name}: the rendered tutorial shows {leaks}"


def _tidy():
    """What the documentation does to an executed notebook (notebooks/make_docs.py)."""
    import runpy
    return runpy.run_path(str(ROOT / "notebooks" / "make_docs.py"))["tidy"]


def test_there_are_notebooks():
    assert NOTEBOOKS, "notebooks/ has no .ipynb files"


def test_notebooks_are_what_make_notebooks_writes():
    """The .ipynb files are generated (notebooks/make_notebooks.py keeps them reviewable as
    Python): an edit made to a notebook alone would be lost at the next regeneration."""
    import runpy
    maker = runpy.run_path(str(ROOT / "notebooks" / "make_notebooks.py"))
    written = {"tour_hinged_barge": "TOUR", "controllers_sphere": "CONTROLLERS",
               "work_precision_rm3": "WORK_PRECISION", "identification_flume": "IDENTIFICATION",
               "power_matrix": "POWER_MATRIX", "electrical_sphere": "ELECTRICAL",
               "export_fmu": "EXPORT", "farm_layouts": "FARM",
               "codesign": "CODESIGN"}
    assert sorted(written) == sorted(p.stem for p in NOTEBOOKS)
    for stem, cells in written.items():
        built = maker["build"](maker[cells])
        committed = nbformat.read(ROOT / "notebooks" / f"{stem}.ipynb", as_version=4)
        assert [c.source for c in committed.cells] == [c.source for c in built.cells], stem
