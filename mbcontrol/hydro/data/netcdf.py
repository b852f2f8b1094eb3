"""Atomic netCDF write and checked read for hydrodynamic datasets.

netCDF cannot hold complex numbers, booleans, dictionaries or (portably) infinite
attributes. They are encoded on write and decoded on read, so that
``read_netcdf(write_netcdf_atomic(ds, p))`` returns a dataset equal to ``ds``:

- a complex variable gets a leading dimension ``complex = ["re", "im"]``
  (Capytaine's own convention, so ``capytaine.io.xarray.merge_complex_values`` reads it too);
- attributes that are bool, dict, list, tuple or non-finite float are stored as strings,
  and their original type is recorded in the attribute ``mbc_encoded_attrs`` (JSON).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError

from ...atomic import atomic_path

_ENC_KEY = "mbc_encoded_attrs"


def _encode_attrs(attrs: dict) -> dict:
    out, kinds = {}, {}
    for k, v in attrs.items():
        if isinstance(v, (bool, np.bool_)):
            out[k], kinds[k] = int(bool(v)), "bool"
        elif isinstance(v, (dict, list, tuple)):
            out[k], kinds[k] = json.dumps(v), "json"
        elif isinstance(v, (float, np.floating)) and not math.isfinite(float(v)):
            out[k], kinds[k] = repr(float(v)), "float"  # 'inf', '-inf', 'nan'
        else:
            out[k] = v
    if kinds:
        out[_ENC_KEY] = json.dumps(kinds)
    return out


def _decode_attrs(attrs: dict) -> dict:
    attrs = dict(attrs)
    kinds = json.loads(attrs.pop(_ENC_KEY, "{}"))
    for k, kind in kinds.items():
        if k not in attrs:
            continue
        if kind == "bool":
            attrs[k] = bool(int(attrs[k]))
        elif kind == "json":
            attrs[k] = json.loads(attrs[k])
        elif kind == "float":
            attrs[k] = float(attrs[k])
    return attrs


def _encode(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy()
    for name in list(out.data_vars):
        da = out[name]
        if np.iscomplexobj(da.values):
            split = xr.concat([da.real, da.imag], dim="complex").transpose("complex", *da.dims)
            split.attrs = _encode_attrs(da.attrs)
            out[name] = split
        else:
            out[name].attrs = _encode_attrs(da.attrs)
    if "complex" in out.dims:
        out = out.assign_coords(complex=["re", "im"])
    out.attrs = _encode_attrs(ds.attrs)
    return out


def _decode(ds: xr.Dataset) -> xr.Dataset:
    out = ds.copy()
    for name in list(out.data_vars):
        da = out[name]
        attrs = _decode_attrs(da.attrs)
        if "complex" in da.dims:
            da = da.sel(complex="re", drop=True) + 1j * da.sel(complex="im", drop=True)
        da.attrs = attrs
        out[name] = da
    if "complex" in out.coords:
        out = out.drop_vars("complex")
    out.attrs = _decode_attrs(ds.attrs)
    # String coordinates come back as object arrays; make them plain unicode again.
    for c in out.coords:
        if out[c].dtype == object:
            out = out.assign_coords({c: out[c].values.astype(str)})
    return out


def write_netcdf_atomic(ds: xr.Dataset, path: str | Path) -> Path:
    """Write ``ds`` to ``path`` (netCDF4) through a temporary file in the same folder.

    The final name appears only once the file is complete (``os.replace``), so a crash
    or a full disk never leaves a truncated file under ``path``.
    """
    path = Path(path)
    with atomic_path(path) as tmp:
        _encode(ds).to_netcdf(tmp, engine="netcdf4")
    return path


def read_netcdf(path: str | Path, *, required: tuple[str, ...] = ()) -> xr.Dataset:
    """Read a file written by :func:`write_netcdf_atomic`, fully into memory.

    Raises HydroError naming the file if it cannot be opened or lacks a ``required`` variable.
    """
    path = Path(path)
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a hydrodynamic netCDF dataset)")
    try:
        with xr.open_dataset(path, engine="netcdf4") as raw:
            ds = _decode(raw.load())
    except Exception as exc:  # netCDF4/HDF5 raise several unrelated types
        raise HydroError(f"{path}: unreadable or corrupt netCDF file ({type(exc).__name__}: {exc}); "
                         "expected a dataset written by mbcontrol.hydro — delete it to recompute") from exc
    missing = [v for v in required if v not in ds.variables]
    if missing:
        raise HydroError(f"{path}: missing variable(s) {missing}; expected a complete mbcontrol.hydro dataset")
    return ds
