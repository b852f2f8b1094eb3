"""Saving results: netCDF written to a temporary file and renamed, so nothing half-written;
and `jsonable`, the one conversion of results to strict JSON."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from .atomic import atomic_path


def jsonable(obj):
    """Strict-JSON form of a result: NumPy scalars and arrays to Python, complex to [re, im],
    infinite and nan floats (JSON has neither) to None."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, (complex, np.complexfloating)):
        return [jsonable(obj.real), jsonable(obj.imag)]
    return obj


def save_dataset(ds: xr.Dataset, path) -> Path:
    """Write `ds` to netCDF at `path` atomically (complex variables split into re/im)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    out = ds.copy()
    for name in [v for v in out.data_vars if out[v].dtype.kind == "c"]:
        out[f"{name}__re"], out[f"{name}__im"] = out[name].real, out[name].imag
        out = out.drop_vars(name)
    with atomic_path(path, ".nc") as tmp:
        out.to_netcdf(tmp)
    return path
