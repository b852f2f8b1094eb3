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
