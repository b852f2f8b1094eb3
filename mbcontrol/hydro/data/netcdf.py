"""Atomic netCDF write and checked read for hydrodynamic datasets: mbcontrol's one netCDF
codec (`mbcontrol.results`: complex variables and typed attributes round-trip), with the
errors of hydrodynamic data.
"""
from __future__ import annotations

from pathlib import Path

import xarray as xr

from mbcontrol.errors import HydroError

from ...results import DataFileError, read_dataset, write_dataset


def write_netcdf_atomic(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4, `mbcontrol.results.write_dataset`) through a
    temporary file in the same folder: the final name appears only once the file is
    complete, so a crash or a full disk never leaves a truncated file under ``path``."""
    return write_dataset(ds, path)


def read_netcdf(path: str | Path, *, required: tuple[str, ...] = ()) -> xr.Dataset:
    """Read a file written by :func:`write_netcdf_atomic`, fully into memory.

    Raises HydroError naming the file if it cannot be opened or lacks a ``required`` variable.
    """
    path = Path(path)
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a hydrodynamic netCDF dataset)")
    try:
        ds = read_dataset(path)
    except DataFileError as exc:
        raise HydroError(f"{exc}; expected a dataset written by mbcontrol.hydro — delete it to "
                         "recompute") from exc.__cause__
    missing = [v for v in required if v not in ds.variables]
    if missing:
        raise HydroError(f"{path}: missing variable(s) {missing}; expected a complete mbcontrol.hydro dataset")
    return ds
