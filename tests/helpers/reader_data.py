"""The third-party hydro files the reader tests read (../shared/data, see its README) and a small
accessor; the fixtures that read them are in tests/hydro/conftest.py."""
from __future__ import annotations

from pathlib import Path

DATA = Path(__file__).resolve().parents[3] / "shared" / "data"
SPHERE, RM3, WAVESTAR = DATA / "wamit" / "sphere.out", DATA / "wamit" / "rm3.out", DATA / "bemio" / "wavestar.h5"

RHO, G = 1000.0, 9.81
R_SPHERE = 5.0
DOFS6 = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
RM3_FORCE = dict(force_symmetric=True, negative_damping="project")  # rm3.out is not reciprocal: test_wamit.py


def _m(ds, var, i, j=None, **sel):
    """Entry X[force i, motion j] (or wrench entry i) of a dataset variable, as numpy."""
    da = ds[var]
    if j is None:
        return da.sel(influenced_dof=i, **sel).values
    return da.sel(influenced_dof=i, radiating_dof=j, **sel).values
