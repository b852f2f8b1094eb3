"""Atomic netCDF write and checked read for hydrodynamic datasets: mbcontrol's one netCDF
codec (`mbcontrol.results`: complex variables and typed attributes round-trip), with the
errors of hydrodynamic data.
"""
from __future__ import annotations

from pathlib import Path

import xarray as xr

from mbcontrol.errors import HydroError

from ...cache import EntrySetAside, in_cache, reason_of, set_aside
from ...results import DataFileError, read_dataset, write_dataset


def write_netcdf_atomic(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4, `mbcontrol.results.write_dataset`) through a
    temporary file in the same folder: the final name appears only once the file is
    complete, so a crash or a full disk never leaves a truncated file under ``path``."""
    return write_dataset(ds, path)


def read_netcdf(path: str | Path, *, required: tuple[str, ...] = ()) -> xr.Dataset:
    """Read a file written by :func:`write_netcdf_atomic`, fully into memory.

    Raises HydroError naming the file if it cannot be opened or lacks a ``required`` variable.
    A file of the cache folder (a converted [hydro] source, a BEM run) that cannot be read is
    moved aside instead, with a warning, and `mbcontrol.cache.EntrySetAside` raised: the code
    that made it makes it again (`mbcontrol.cache.rebuilt_once`).
    """
    path = Path(path)
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a hydrodynamic netCDF dataset)")
    seen = path.stat()         # what was read: a rebuild by another process is not set aside
    try:
        ds = read_dataset(path)
    except DataFileError as exc:
        if in_cache(path):
            _set_aside(path, reason_of(exc.__cause__ or exc), seen)
        raise HydroError(f"{exc}; expected a dataset written by mbcontrol.hydro — delete it to "
                         "recompute") from exc.__cause__
    missing = [v for v in required if v not in ds.variables]
    if missing and in_cache(path):
        _set_aside(path, f"missing variable(s) {missing}", seen)
    if missing:
        raise HydroError(f"{path}: missing variable(s) {missing}; expected a complete mbcontrol.hydro dataset")
    return ds


def _set_aside(path: Path, reason: str, seen):
    raise EntrySetAside(path, set_aside(path, reason, what="hydrodynamic cache entry", seen=seen),
                        reason)
