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


def save_dataset(ds: xr.Dataset, path, *, precision: str = "float64", every: int = 1) -> Path:
    """Write `ds` to netCDF at `path` atomically (complex variables split into re/im), each
    variable deflate-compressed (lossless). precision "float32" stores floating variables in
    single precision (relative rounding 6e-8, half the size again); every = k keeps every k-th
    time sample (a figure needs far fewer than the integrator's steps)."""
    if precision not in ("float64", "float32"):
        raise ValueError(f"precision {precision!r}: expected float64 or float32")
    if every < 1:
        raise ValueError(f"every = {every}: expected a positive number of samples")
    path = Path(path)
    out = ds.copy()
    if every > 1 and "time" in out.dims:
        out = out.isel(time=slice(None, None, every))
    for name in [v for v in out.data_vars if out[v].dtype.kind == "c"]:
        out[f"{name}__re"], out[f"{name}__im"] = out[name].real, out[name].imag
        out = out.drop_vars(name)
    encoding = {}
    for name, var in out.data_vars.items():
        if var.dtype.kind in "fiu" and var.ndim > 0:
            encoding[name] = {"zlib": True, "complevel": 4}
            if precision == "float32" and var.dtype.kind == "f":
                encoding[name]["dtype"] = "float32"
    with atomic_path(path, ".nc") as tmp:
        out.to_netcdf(tmp, encoding=encoding)
    return path
