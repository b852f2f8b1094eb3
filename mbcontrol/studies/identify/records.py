"""Measured records: time series of named channels with units, read from CSV or netCDF.

A `Record` is what a file holds: time (s) and channels by name, each with its unit. Readers
take a column map (file column -> channel name) so a lab's naming meets the plant's; a
`[unit]` suffix in a CSV header ("Sway [m]") or a netCDF `units` attribute gives the unit, and
every channel is converted to SI on reading (mm, cm -> m; deg -> rad; kN -> N; ms -> s; see
UNITS): a unit not in UNITS is an error naming the file and the column, never a silent factor.
A column without a unit is kept as it is (its unit ""), and `require_quantity` refuses it
where the caller knows what the channel must be only if its unit says otherwise.
`check_channels` refuses a channel that is missing, NaN or flat (a tracking failure), naming
the file and the channel.
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

# unit as written -> (quantity, SI unit, factor to SI); spellings are matched case-sensitively
# (mm is not Mm) after stripping spaces
UNITS = {
    "s": ("time", "s", 1.0), "ms": ("time", "s", 1e-3),
    "m": ("length", "m", 1.0), "cm": ("length", "m", 1e-2), "mm": ("length", "m", 1e-3),
    "rad": ("angle", "rad", 1.0), "deg": ("angle", "rad", np.pi / 180),
    "degree": ("angle", "rad", np.pi / 180), "degrees": ("angle", "rad", np.pi / 180),
    "°": ("angle", "rad", np.pi / 180),
    "N": ("force", "N", 1.0), "kN": ("force", "N", 1e3),
    "Nm": ("moment", "N m", 1.0), "kNm": ("moment", "N m", 1e3),
    "m/s": ("velocity", "m/s", 1.0), "mm/s": ("velocity", "m/s", 1e-3),
    "m/s2": ("acceleration", "m/s2", 1.0), "m/s^2": ("acceleration", "m/s2", 1.0),
    "rad/s": ("angular velocity", "rad/s", 1.0), "deg/s": ("angular velocity", "rad/s", np.pi / 180),
    "kg": ("mass", "kg", 1.0), "V": ("voltage", "V", 1.0), "-": ("dimensionless", "-", 1.0),
}
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
    try:
        header, data = _parsed_csv(path)
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except (OSError, ValueError, EOFError, lzma.LZMAError) as exc:
        raise RecordError(f"{path}: not a readable CSV record ({type(exc).__name__}: {exc})") from None
    if data.shape[1] != len(header):
        raise RecordError(f"{path}: {data.shape[1]} columns of numbers under {len(header)} "
                          f"header names")
    names, units = zip(*(_split_unit(c) for c in header))
    return _record(path, list(names), dict(zip(names, units)), data.T, columns, time)


def _parsed_csv(path: Path) -> tuple[list, np.ndarray]:
    """(header, numbers) of a CSV file, kept in the cache by the file's content: a tank
    campaign's 48 compressed records take 9 s to decompress and parse, 0.4 s to load again."""
    import hashlib
    import io

    from ...atomic import write_bytes
    from ...cache import cache_dir, read_entry
    raw = path.read_bytes()
    cached = cache_dir() / "records" / f"csv_{hashlib.sha256(raw).hexdigest()[:24]}.npz"
    stored = read_entry(cached, _read_parsed, what="parsed-CSV cache entry")   # unreadable: aside
    if stored is not None:
        return stored
    opener = _OPENERS.get(path.suffix)
    # text mode either way: universal newlines, as open(path, "rt") gave
    with (opener(io.BytesIO(raw), "rt") if opener else io.TextIOWrapper(io.BytesIO(raw))) as fh:
        header = fh.readline().rstrip("\n").split(",")
        data = np.loadtxt(fh, delimiter=",", ndmin=2)
    buffer = io.BytesIO()
    np.savez(buffer, header=np.array(header, dtype=str), data=data)
    cached.parent.mkdir(parents=True, exist_ok=True)
    write_bytes(cached, buffer.getvalue())
    return header, data


def _read_parsed(cached: Path) -> tuple[list, np.ndarray]:
    with np.load(cached, allow_pickle=False) as stored:
        return [str(h) for h in stored["header"]], stored["data"]


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


def to_si(path, column: str, unit: str, values):
    """(values in SI, SI unit) for a column written in `unit` ("" is kept as it is);
    RecordError naming the file and the column for a unit not in UNITS."""
    key = unit.replace(" ", "")
    if not key:
        return np.asarray(values, float), ""
    if key not in UNITS:
        raise RecordError(f"{path}: column {column!r} has unit {unit!r}, which mbcontrol does "
                          f"not know; expected one of {', '.join(sorted(UNITS))} (converted to "
                          f"SI on reading)")
    _, si, factor = UNITS[key]
    return np.asarray(values, float) * factor, si


def require_quantity(record: "Record", name: str, quantity: str) -> None:
    """RecordError unless channel `name`'s unit is one of `quantity` ("length", "angle",
    ...) or not given (then SI is assumed, as the plant's outputs are)."""
    unit = record.units.get(name, "")
    if unit and UNITS[unit.replace(" ", "")][0] != quantity:
        expected = sorted(u for u, (q, _, _) in UNITS.items() if q == quantity)
        raise RecordError(f"{record.path}: channel {name!r} is in {unit!r}; expected {quantity} "
                          f"units ({', '.join(expected)})")


def _record(path, names, units, arrays, columns, time) -> Record:
    if time not in names:
        raise RecordError(f"{path}: no time column {time!r}; columns: {', '.join(names)}")
    values = dict(zip(names, arrays))
    t, time_unit = to_si(path, time, units.get(time, ""), values.pop(time))
    if time_unit not in ("", "s"):
        raise RecordError(f"{path}: time column {time!r} is in {units[time]!r}; expected s or ms")
    if t.size < 2 or not np.all(np.diff(t) > 0):
        raise RecordError(f"{path}: time column {time!r} is not increasing")
    kept = {c: c for c in values} if columns is None else columns
    missing = [c for c in kept if c not in values]
    if missing:
        raise RecordError(f"{path}: no column(s) {missing}; the file has {', '.join(values)}")
    channels, si_units = {}, {}
    for column, name in kept.items():       # only the columns kept: others may be anything
        channels[name], si_units[name] = to_si(path, column, units.get(column, ""), values[column])
    return Record(str(path), t, channels, si_units)


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
