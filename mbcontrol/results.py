"""Saving results: netCDF written to a temporary file and renamed, so nothing half-written."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import xarray as xr


def save_dataset(ds: xr.Dataset, path) -> Path:
    """Write `ds` to netCDF at `path` atomically (complex variables split into re/im)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    out = ds.copy()
    for name in [v for v in out.data_vars if out[v].dtype.kind == "c"]:
        out[f"{name}__re"], out[f"{name}__im"] = out[name].real, out[name].imag
        out = out.drop_vars(name)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".nc.tmp")
    os.close(fd)
    try:
        out.to_netcdf(tmp)
        os.chmod(tmp, 0o644)             # mkstemp makes 0600
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
