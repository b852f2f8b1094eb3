"""Measured records: time series of named channels with units, read from CSV or netCDF.

A `Record` is what a file holds: time (s) and channels by name, each with its unit. Readers
take a column map (file column -> channel name) so a lab's naming meets the plant's; a
`[unit]` suffix in a CSV header ("Sway [m]") gives the unit. `check_channels` refuses a
channel that is missing, NaN or flat (a tracking failure), naming the file and the channel.
CSV files may be compressed (.csv.xz, .csv.gz, .csv.bz2).
"""
from __future__ import annotations

import bz2
import gzip
import lzma
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import MbcontrolError

FLAT_SHARE = 0.5          # a channel whose samples are exactly equal for over half the window
FLAT_RANGE = 1e-12        # or whose range is below this (its unit) is flat: a tracking failure


class RecordError(MbcontrolError, ValueError):
    """A measured record is unreadable, incomplete or unusable; names the file and channel."""


@dataclass(frozen=True)
class Record:
    """time (s, increasing) and channels (name -> samples) with units (name -> unit)."""
    path: str
    time: np.ndarray = field(repr=False)
    channels: dict = field(repr=False)
    units: dict = field(default_factory=dict)

    def channel(self, name: str) -> np.ndarray:
        if name not in self.channels:
            raise RecordError(f"{self.path}: no channel {name!r}; the file has "
                              f"{', '.join(self.channels) or 'none'}")
        return self.channels[name]


_OPENERS = {".xz": lzma.open, ".gz": gzip.open, ".bz2": bz2.open}


def _split_unit(column: str) -> tuple[str, str]:
    match = re.fullmatch(r"\s*(.*?)\s*\[(.*)\]\s*", column)
    return (match.group(1), match.group(2)) if match else (column.strip(), "")


def read_csv(path, columns: dict | None = None, *, time: str = "Time") -> Record:
    """A CSV record: the header names the columns ("Name [unit]" or "Name"); `columns` maps
    file names (without unit) to channel names (None: keep every column as it is named);
    `time`: the time column's name (s). RecordError on an unreadable or ragged file."""
    path = Path(path)
    opener = _OPENERS.get(path.suffix, open)
    try:
        with opener(path, "rt") as fh:
            header = fh.readline().rstrip("\n").split(",")
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except (OSError, ValueError, EOFError, lzma.LZMAError) as exc:
        raise RecordError(f"{path}: not a readable CSV record ({type(exc).__name__}: {exc})") from None
    if data.shape[1] != len(header):
        raise RecordError(f"{path}: {data.shape[1]} columns of numbers under {len(header)} "
                          f"header names")
    names, units = zip(*(_split_unit(c) for c in header))
    return _record(path, list(names), dict(zip(names, units)), data.T, columns, time)


def read_netcdf(path, columns: dict | None = None, *, time: str = "time") -> Record:
    """A netCDF record: 1-D variables over the `time` coordinate (s); units from attrs."""
    import xarray as xr
    path = Path(path)
    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except Exception as exc:                   # netCDF4 / HDF5 raise unrelated types
        raise RecordError(f"{path}: not a readable netCDF record ({type(exc).__name__}: {exc})") from None
    if time not in ds.variables:
        raise RecordError(f"{path}: no time coordinate {time!r}; expected one (s)")
    names = [time] + [v for v in ds.data_vars if ds[v].dims == (time,)]
    units = {n: str(ds[n].attrs.get("units", "")) for n in names}
    return _record(path, names, units, [np.asarray(ds[n].values, float) for n in names],
                   columns, time)


def _record(path, names, units, arrays, columns, time) -> Record:
    if time not in names:
        raise RecordError(f"{path}: no time column {time!r}; columns: {', '.join(names)}")
    values = dict(zip(names, arrays))
    t = np.asarray(values.pop(time), float)
    if t.size < 2 or not np.all(np.diff(t) > 0):
        raise RecordError(f"{path}: time column {time!r} is not increasing")
    if columns is not None:
        missing = [c for c in columns if c not in values]
        if missing:
            raise RecordError(f"{path}: no column(s) {missing}; the file has "
                              f"{', '.join(values)}")
        values = {columns[c]: values[c] for c in columns}
        units = {columns[c]: units.get(c, "") for c in columns}
    return Record(str(path), t, {k: np.asarray(v, float) for k, v in values.items()},
                  {k: units.get(k, "") for k in values})


def channel_problem(record: Record, name: str, window=None) -> str | None:
    """Why channel `name` cannot be used (None if it can): missing, NaN, or flat over the
    window (s; default the whole record)."""
    if name not in record.channels:
        return f"no channel {name!r}"
    y = record.channels[name]
    if window is not None:
        y = y[(record.time >= window[0]) & (record.time <= window[1])]
    if y.size == 0:
        return f"channel {name!r} has no sample in the window"
    if not np.all(np.isfinite(y)):
        return f"channel {name!r} has {int(np.sum(~np.isfinite(y)))} NaN or infinite samples"
    repeated = np.mean(np.diff(y) == 0.0) if y.size > 1 else 1.0
    if np.ptp(y) <= FLAT_RANGE or repeated > FLAT_SHARE:
        return (f"channel {name!r} is flat (range {np.ptp(y):.3g} {record.units.get(name, '')}, "
                f"{100 * repeated:.0f} % of steps unchanged): a tracking failure")
    return None


def check_channels(record: Record, names, window=None) -> None:
    """RecordError naming the file and the first unusable channel of `names`."""
    for name in names:
        problem = channel_problem(record, name, window)
        if problem:
            raise RecordError(f"{record.path}: {problem}")
