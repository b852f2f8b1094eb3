"""Results: the run record that travels with a run (`RunInfo`, read by `run_info`); one netCDF
codec for every file mbcontrol writes (hydrodynamic caches, `simulate --out`, sweeps,
benchmarks), each written to a temporary file and renamed, so nothing half-written; and
`jsonable`, the one conversion of results to strict JSON.

A run's record lives in its Dataset's attrs as Python values (dicts, lists), never as JSON
strings inside a process: JSON appears only in files, where `write_dataset` encodes it and
`read_dataset` decodes it. Save a run with `write_dataset` (or `mbcontrol simulate --out`);
xarray's own `to_netcdf` cannot store dict attributes.

netCDF cannot hold complex numbers, booleans, dictionaries or (portably) infinite
attributes. They are encoded on write and decoded on read, so that
``read_dataset(write_dataset(ds, p))`` returns a dataset equal to ``ds``:

- a complex variable gets a leading dimension ``complex = ["re", "im"]`` (Capytaine's own
  convention, so ``capytaine.io.xarray.merge_complex_values`` reads it too);
- attributes that are bool, None, dict, list, tuple or non-finite float are stored as strings,
  and their original type is recorded in the attribute ``mbc_encoded_attrs`` (JSON).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from typing import TYPE_CHECKING

from .errors import InputError, MbcontrolError
from .atomic import atomic_path

if TYPE_CHECKING:                # xarray costs 1.9 s to import: only where a Dataset is made
    import xarray as xr

ENCODED_ATTRS = "mbc_encoded_attrs"


class DataFileError(MbcontrolError, ValueError):
    """A results file cannot be read: names the file and what was expected."""


@dataclass(frozen=True)
class RunInfo:
    """What made a run and how it is scored: model (its name); wave (Wave.describe(); type
    "none" without one); parameters (the plant's values the run used, by name, SI);
    controller (its describe(), None when the scene's own PTO laws ran); estimator (its
    accuracy report, or None); sampled_loop (mbcontrol.sim.sampled's verdict on the held
    loop, or None); statistics_from_s and statistics_note (where the metrics' window starts
    and why, when a caller chose it; None: the default window)."""
    model: str
    wave: dict
    parameters: dict
    controller: dict | None = None
    estimator: dict | None = None
    sampled_loop: dict | None = None
    statistics_from_s: float | None = None
    statistics_note: str | None = None

    @property
    def warm_up_s(self) -> float:
        """The controller's warm-up (s): the metrics' window starts after it."""
        return float((self.controller or {}).get("warm_up_s") or 0.0)


def run_info(ds) -> RunInfo:
    """The run record of a Dataset made by `simulate` (or a sweep's light run), as it is in a
    process or as read from a file (a file opened by plain xarray holds JSON strings)."""
    attrs = ds.attrs
    start = attrs.get("statistics_from_s")
    return RunInfo(model=str(attrs.get("model", "")),
                   wave=record(attrs, "wave", {"type": "none"}),
                   parameters=record(attrs, "parameters", {}),
                   controller=record(attrs, "controller"), estimator=record(attrs, "estimator"),
                   sampled_loop=record(attrs, "sampled_loop"),
                   statistics_from_s=None if start is None else float(start),
                   statistics_note=attrs.get("statistics_note"))


def record(attrs: dict, key: str, default=None):
    """attrs[key] as a Python value: a dict or list as stored in a process, a JSON string as
    plain xarray reads it from a file; `default` when absent or null."""
    value = attrs.get(key)
    if isinstance(value, str):
        value = json.loads(value)
    return default if value is None else value


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


def write_dataset(ds: xr.Dataset, path, *, precision: str = "float64", every: int = 1,
                  compress: bool = False) -> Path:
    """Write `ds` to netCDF at `path` atomically, encoded as the module says. precision
    "float32" stores floating variables in single precision (relative rounding 6e-8);
    every = k keeps every k-th time sample; compress: deflate each variable (lossless)."""
    if precision not in ("float64", "float32"):
        raise InputError(f"precision {precision!r}: expected float64 or float32")
    if every < 1:
        raise InputError(f"every = {every}: expected a positive number of samples")
    path = Path(path)
    if every > 1 and "time" in ds.dims:
        ds = ds.isel(time=slice(None, None, every))
    out = encode(ds)
    encoding = {}
    for name, var in out.data_vars.items():
        options = {}
        if compress and var.dtype.kind in "fiu" and var.ndim > 0:
            options.update(zlib=True, complevel=4)
        if precision == "float32" and var.dtype.kind == "f":
            options["dtype"] = "float32"
        if options:
            encoding[name] = options
    with atomic_path(path, ".nc") as tmp:
        out.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
    return path


def read_dataset(path) -> xr.Dataset:
    """A file `write_dataset` wrote (any mbcontrol netCDF: a `simulate --out` record, a
    sweep's sweep.nc, a hydrodynamic cache), fully into memory and decoded."""
    path = Path(path)
    if not path.is_file():
        raise DataFileError(f"{path}: no such file (expected a netCDF file mbcontrol wrote)")
    import xarray as xr
    try:
        with xr.open_dataset(path, engine="netcdf4") as raw:
            return decode(raw.load())
    except Exception as exc:  # netCDF4/HDF5 raise several unrelated types
        raise DataFileError(f"{path}: unreadable or corrupt netCDF file ({type(exc).__name__}: "
                            f"{exc})") from exc


def save_dataset(ds: xr.Dataset, path, *, precision: str = "float64", every: int = 1) -> Path:
    """A result (a `simulate` record, a report) to `path`: `write_dataset`, compressed."""
    return write_dataset(ds, path, precision=precision, every=every, compress=True)


def encode(ds: xr.Dataset) -> xr.Dataset:
    """`ds` as netCDF can hold it (module docstring)."""
    out = ds.copy()
    for name in list(out.data_vars):
        da = out[name]
        if np.iscomplexobj(da.values):
            import xarray as xr
            split = xr.concat([da.real, da.imag], dim="complex").transpose("complex", *da.dims)
            split.attrs = _encode_attrs(da.attrs)
            out[name] = split
        else:
            out[name].attrs = _encode_attrs(da.attrs)
    if "complex" in out.dims:
        out = out.assign_coords(complex=["re", "im"])
    out.attrs = _encode_attrs(ds.attrs)
    return out


def decode(ds: xr.Dataset) -> xr.Dataset:
    """The dataset `encode` made `ds` from."""
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


def _encode_attrs(attrs: dict) -> dict:
    out, kinds = {}, {}
    for k, v in attrs.items():
        if isinstance(v, (bool, np.bool_)):
            out[k], kinds[k] = int(bool(v)), "bool"
        elif v is None or isinstance(v, (dict, list, tuple)):
            out[k], kinds[k] = json.dumps(v), "json"
        elif isinstance(v, (float, np.floating)) and not math.isfinite(float(v)):
            out[k], kinds[k] = repr(float(v)), "float"  # 'inf', '-inf', 'nan'
        else:
            out[k] = v
    if kinds:
        out[ENCODED_ATTRS] = json.dumps(kinds)
    return out


def _decode_attrs(attrs: dict) -> dict:
    attrs = dict(attrs)
    kinds = json.loads(attrs.pop(ENCODED_ATTRS, "{}"))
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
