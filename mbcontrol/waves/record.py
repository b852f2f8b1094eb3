"""A measured free-surface elevation record as a wave (WEC-Sim's "elevationImport"): a file or
an elevation series (t, eta).

The file: two columns, time (s) and free-surface elevation (m, positive up) at the scene's
origin, separated by whitespace or commas; one header line (no number in it) may come before
the data, `#` starts a comment (a whole line or the rest of one), blank lines are skipped.

What is refused, each by a `WaveError` naming the file, the line, the column and what was
expected: a cell that is not a number, NaN or inf, a row without exactly two cells, time that
does not strictly increase, a record of fewer than MIN_SAMPLES samples or shorter than
MIN_DURATION_S, a gap (a step over GAP_FACTOR times the median step), a file of more than
MAX_ROWS rows or MAX_BYTES bytes, a flat record, a record steeper than a wave can be (an
elevation in mm read as m). Uneven sampling (steps whose spread exceeds UNEVEN_RTOL of the
median: time written with too few digits, a logger's jitter) is resampled onto a uniform grid
by linear interpolation, with a RuntimeWarning naming the file, the old step range and the new
step (linear interpolation damps high frequencies: at half the Nyquist frequency by up to
29 %, for a new sample midway between two old ones; little where the old steps only jitter).

`from_record` (a file, or arrays) and `from_elevation` (arrays) run one decomposition: the
record, mean removed, by one FFT at its own resolution: components omega_k = 2 pi k / T,
T = N dt, k = 1..N/2, so that `Wave.elevation` reproduces the record at its sample times to
round-off; from_record measures time from the record's first sample (the simulation's t = 0),
from_elevation keeps the series' own time unless asked. The wave repeats with period T: a
longer run repeats the record (allowed; noted). Tests: tests/waves/test_record.py,
tests/waves/test_excitation.py.
"""
from __future__ import annotations

import dataclasses
import hashlib
import io
import math
import os
import re
import warnings
from array import array
from pathlib import Path

import numpy as np

from .. import defaults
from ..errors import WaveError
from .realisation import MAX_COMPONENTS, Wave

MAX_ROWS = 10_000_000      # 10^7 rows: 28 h at 100 Hz, a year at 1/3 Hz; more is not one run
MAX_BYTES = 1 << 29        # 512 MiB: 10^7 rows of two 20-digit numbers, with room to spare
MIN_SAMPLES = 64           # 32 components: fewer do not resolve a spectrum's peak and tails
MIN_DURATION_S = 10.0      # a few periods of a tank wave (~1-3 s); an ocean record is minutes
UNEVEN_RTOL = 1e-6         # steps spread more (relative to the median) are resampled
GAP_FACTOR = 1.5           # a step over 1.5 median steps is a missing sample, not jitter
REST_FRACTION = 0.1        # "at rest": |eta| under 0.1 std over the first half Tz
RAMP_TZ = 2.0              # a ramp of 2 mean zero-crossing periods (irregular seas: 2 Tp)
MEAN_FRACTION = 0.01       # a mean above 1 % of the std is noted when it is left out
KEPT_MIN = 1e-6            # a record with less of its variance in the data's band is noise there
COLUMNS = ("time (s)", "elevation (m)")

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NOT_FINITE = ("nan", "inf", "infinity")


def read_elevation(path) -> tuple[np.ndarray, np.ndarray]:
    """(t, eta): the record's times (s) and elevations (m, positive up), checked as the module
    docstring says; an unevenly sampled record comes back resampled onto a uniform grid (with a
    RuntimeWarning). WaveError names the file, the line and the column of what is wrong."""
    t, eta, _ = _read(path)
    return t, eta


def _read(path) -> tuple[np.ndarray, np.ndarray, dict]:
    """(t, eta, {"source", "sha256", ...}): the file read and checked."""
    path = Path(path)
    try:
        size = os.stat(path).st_size
        if size > MAX_BYTES:
            raise WaveError(f"{path}: {size:,} bytes; expected an elevation record of at most "
                            f"{MAX_BYTES:,} bytes ({MAX_ROWS:,} rows): cut it into runs")
        data = path.read_bytes()
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError) as exc:
        raise WaveError(f"{path}: cannot read the elevation record ({exc.strerror}); expected "
                        f"a file of two columns, time (s) and elevation (m)") from None
    t, eta, lines = _parse(data, str(path))
    t, eta, info = _checked(t, eta, str(path), lambda i: f"line {lines[i]}")
    return t, eta, {"source": path.name, "sha256": hashlib.sha256(data).hexdigest(), **info}


def _parse(data: bytes, name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, eta, the file's line number of each sample), every cell checked."""
    if b"\n" not in data:                  # old Mac line ends (CR alone)
        data = data.replace(b"\r", b"\n")
    times, values, lines, header = array("d"), array("d"), array("q"), False
    for number, raw in enumerate(io.BytesIO(data), 1):
        try:
            text = raw.decode("utf-8").split("#", 1)[0].strip()
        except UnicodeDecodeError:
            raise WaveError(f"{name}: line {number}: not text (UTF-8); expected two columns, "
                            f"time (s) and elevation (m)") from None
        if not text:
            continue
        cells = [c.strip() for c in text.split(",")] if "," in text else text.split()
        if not lines and not header and not any(_numeric(c) for c in cells):
            header = True                     # the one header line, before the data
            continue
        if len(lines) >= MAX_ROWS:
            raise WaveError(f"{name}: line {number}: more than {MAX_ROWS:,} samples; expected "
                            f"a record of at most {MAX_ROWS:,} rows: cut it into runs")
        try:                                  # the common case, fast; else every cell named
            t, eta = float(cells[0]), float(cells[1])
            plain = len(cells) == 2 and math.isfinite(t + eta) and "_" not in text
        except (ValueError, IndexError):
            plain = False
        if not plain:
            t, eta = _row(cells, name, number, text)
        times.append(t)
        values.append(eta)
        lines.append(number)
    if not lines:
        raise WaveError(f"{name}: no data rows; expected two columns, time (s) and elevation "
                        f"(m), after at most one header line")
    return np.array(times, float), np.array(values, float), np.array(lines, np.int64)


def _numeric(cell: str) -> bool:
    return bool(_NUMBER.fullmatch(cell)) or cell.lower().lstrip("+-") in _NOT_FINITE


def _row(cells, name: str, number: int, text: str) -> tuple[float, float]:
    """A data row's (time, elevation), or a WaveError naming the line and the column."""
    if len(cells) != 2:
        raise WaveError(f"{name}: line {number}: {len(cells)} column(s) in {text[:60]!r}; "
                        f"expected 2, {COLUMNS[0]} and {COLUMNS[1]}")
    row = []
    for column, (cell, what) in enumerate(zip(cells, COLUMNS), 1):
        where = f"{name}: line {number}, column {column} ({what})"
        if not cell:
            raise WaveError(f"{where}: empty; expected a number")
        if not _NUMBER.fullmatch(cell):
            kind = "not finite" if _numeric(cell) else "not a number"
            raise WaveError(f"{where}: {cell[:30]!r} is {kind}; expected a finite number")
        row.append(float(cell))
        if not math.isfinite(row[-1]):          # 1e999 overflows to inf
            raise WaveError(f"{where}: {cell[:30]!r} overflows; expected a finite number")
    return row[0], row[1]


def _checked(t, eta, name: str, where) -> tuple[np.ndarray, np.ndarray, dict]:
    """The record's time checked (increasing, long enough, without gaps) and made uniform;
    where(i): how sample i is named ("line 12")."""
    n = t.size
    steps = np.diff(t)
    bad = np.flatnonzero(~(steps > 0))
    if bad.size:
        i = int(bad[0]) + 1
        raise WaveError(f"{name}: {where(i)}, column 1 ({COLUMNS[0]}): {t[i]:.10g} s is not "
                        f"after {t[i - 1]:.10g} s ({where(i - 1)}); expected strictly "
                        f"increasing time")
    span = float(t[-1] - t[0]) * n / max(n - 1, 1) if n > 1 else 0.0
    if n < MIN_SAMPLES or span < MIN_DURATION_S:
        raise WaveError(f"{name}: {n} samples over {span:.4g} s; expected at least "
                        f"{MIN_SAMPLES} samples and {MIN_DURATION_S:g} s (a record's "
                        f"spectrum needs several wave periods)")
    median = float(np.median(steps))
    gaps = np.flatnonzero(steps > GAP_FACTOR * median)
    if gaps.size:
        i = int(gaps[0]) + 1
        raise WaveError(f"{name}: {where(i)}, column 1 ({COLUMNS[0]}): a gap of "
                        f"{steps[i - 1]:.6g} s before t = {t[i]:.10g} s (the median step is "
                        f"{median:.6g} s); expected evenly sampled time: cut the record at "
                        f"the gap or fill it")
    spread = float(steps.max() - steps.min()) / median
    info = {}
    if spread > UNEVEN_RTOL:
        grid = np.linspace(t[0], t[-1], n)
        dt = float(grid[1] - grid[0])
        warnings.warn(f"{name}: the time step varies from {steps.min():.6g} s to "
                      f"{steps.max():.6g} s (spread {spread:.2g} of the median, more than "
                      f"{UNEVEN_RTOL:g}); resampled by linear interpolation onto a uniform "
                      f"step of {dt:.10g} s ({n} samples)", RuntimeWarning, stacklevel=3)
        info["resampled_from_dt_s"] = [float(steps.min()), float(steps.max())]
        t, eta = grid, np.interp(grid, t, eta)
    return t, eta, info


def from_record(path_or_arrays, *, data_band=None, ramp_time: float | None = None,
                duration: float | None = None) -> Wave:
    """The wave (kind "record") of a measured elevation record: a file (see the module
    docstring) or a pair of arrays (t s, eta m) checked alike, decomposed as `from_elevation`
    does, with time measured from the record's first sample (the simulation's t = 0).

    Components omega_k = 2 pi k / T (T = N dt, k = 1..N/2) from one FFT of the record, mean
    removed: `elevation(t - t0)` reproduces the record at its sample times to round-off (t0 its
    first time). data_band = (lo, hi) rad/s (the hydro data's): components outside are
    dropped, their share of the variance in settings["record_outside_data"]. ramp_time (s):
    None chooses one: none when the record starts at rest (|eta| under REST_FRACTION of its
    std over its first half mean zero-crossing period Tz, the components kept), else RAMP_TZ
    Tz. duration (s): the run's, when known; a run longer than T repeats the record
    (settings["repeats"]). settings: source, sha256 (of the file's bytes), samples, dt_s,
    duration_s, t0_s, hs_m (4 std), tp_s (peak of the periodogram; "tp" too, which
    `Wave.period` reads), tz_s, mean_m, and "notes": sentences on what was left out,
    resampled, ramped or repeated.
    """
    if isinstance(path_or_arrays, (str, os.PathLike)):
        t, eta, info = _read(path_or_arrays)
    else:
        t, eta, info = _arrays(path_or_arrays)
    return _decompose(t, eta, info, band=data_band, ramp_time=ramp_time, duration=duration)


def from_elevation(t, eta, *, band=None, ramp_time: float | None = 0.0, direction: float = 0.0,
                   duration: float | None = None, from_start: bool = False) -> Wave:
    """A wave (kind "record") reproducing an elevation series eta(t) at the n-frame origin (m,
    up): the array-level `from_record`, the one decomposition both run (arrays checked as a
    file's columns are: finite, strictly increasing, evenly sampled or resampled with a
    warning, long enough; a flat or impossibly steep series refused).

    One FFT, mean removed: components omega_k = 2 pi k / T (T = N dt), exactly the periodic
    extension of the series; components outside `band` (rad/s, e.g. the hydro data's) are
    dropped, their share of the variance in settings["record_outside_data"]. Time is the
    series' own: `elevation(t)` reproduces eta at the given t to round-off (phases referred to
    t = 0), unless from_start (from_record's convention: t = 0 is the first sample). ramp_time:
    none by default (None: chosen as from_record chooses it); direction: rad. Excitation from
    this wave equals the (non-causal) circular convolution of the series with the excitation
    impulse response (tests/waves/test_excitation.py).
    """
    t, eta, info = _arrays((t, eta))
    return _decompose(t, eta, info, band=band, ramp_time=ramp_time, duration=duration,
                      direction=direction, from_start=from_start)


def _decompose(t, eta, info: dict, *, band, ramp_time, duration, direction: float = 0.0,
               from_start: bool = True) -> Wave:
    """The wave of a checked, evenly sampled series (t, eta), `info` its provenance
    ({"source", "sha256", ...}): see from_record (settings) and from_elevation (time)."""
    name, n = info["source"], t.size
    dt = float(t[-1] - t[0]) / (n - 1)
    mean = float(np.mean(eta))
    spectrum = np.fft.rfft(eta - mean)[1:]
    omega = np.arange(1, spectrum.size + 1) * (2 * np.pi / (n * dt))
    amplitude = 2 * np.abs(spectrum) / n
    power = 2 * np.abs(spectrum) ** 2 / n ** 2                # each component's variance, m^2
    if n % 2 == 0:                # the Nyquist term X_N/2 (-1)^n / N is one cosine: not doubled
        amplitude[-1] /= 2
        power[-1] /= 2
    total = float(power.sum())
    if not total > 0:
        raise WaveError(f"{name}: the elevation is constant ({mean:.6g} m); expected a wave "
                        f"record (for still water: --wave none)")
    keep = np.ones(omega.size, bool) if band is None else \
        (omega >= band[0]) & (omega <= band[1])
    settings = {**info, "samples": int(n), "dt_s": dt, "duration_s": n * dt,
                "t0_s": float(t[0]), "hs_m": 4 * math.sqrt(total),
                "tp_s": float(2 * np.pi / omega[np.argmax(power)]), "mean_m": mean, "notes": []}
    settings["tp"] = settings["tp_s"]
    _check_kept(settings, keep, power, band)
    settings["tz_s"] = 2 * np.pi * math.sqrt(power[keep].sum()
                                             / np.sum(power[keep] * omega[keep] ** 2))
    phase = np.angle(spectrum) - (0.0 if from_start else omega * float(t[0]))
    wave = Wave("record", omega[keep], amplitude[keep], phase[keep], direction, 0.0, settings,
                2 * np.pi / (n * dt))
    ramp_time = _ramp(settings, wave, dt, ramp_time, math.sqrt(power[keep].sum()))
    if abs(mean) > MEAN_FRACTION * math.sqrt(total):
        settings["notes"].append(f"{name}: the record's mean, {mean:.4g} m, is left out (the "
                                 f"model's still water level is its own)")
    if duration is not None and duration > n * dt * (1 + 1e-9):
        settings["repeats"] = duration / (n * dt)
        settings["notes"].append(
            f"{name}: the run ({duration:.6g} s) is longer than the record ({n * dt:.6g} s): "
            f"the record repeats {settings['repeats']:.3g} times, with a step of "
            f"{eta[0] - eta[-1]:.3g} m where it wraps")
    return dataclasses.replace(wave, ramp_time=ramp_time)


def _arrays(pair) -> tuple[np.ndarray, np.ndarray, dict]:
    """(t, eta, info) of a pair of arrays, checked as a file's columns are."""
    try:
        t, eta = (np.asarray(a, dtype=float) for a in pair)
    except (TypeError, ValueError):
        raise WaveError("an elevation record: expected a file name or a pair of arrays (t s, "
                        "eta m)") from None
    if t.ndim != 1 or t.shape != eta.shape:
        raise WaveError(f"an elevation record: t {t.shape} and eta {eta.shape}; expected two "
                        f"1-D arrays of one length")
    for column, (values, what) in enumerate(zip((t, eta), COLUMNS), 1):
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise WaveError(f"arrays: sample {bad[0]}, column {column} ({what}): "
                            f"{values[bad[0]]}; expected a finite number")
    digest = hashlib.sha256(np.ascontiguousarray(np.stack([t, eta])).tobytes()).hexdigest()
    t, eta, info = _checked(t, eta, "arrays", lambda i: f"sample {i}")
    return t, eta, {"source": "arrays", "sha256": digest, **info}


def _check_kept(settings: dict, keep, power, data_band) -> None:
    """Refuse a record steeper than a wave can be, of more than MAX_COMPONENTS components kept,
    or with nothing inside the hydro data's band; note the share of its variance left out."""
    name, hs, tp = settings["source"], settings["hs_m"], settings["tp_s"]
    wavelength = 9.80665 * tp ** 2 / (2 * math.pi)
    if hs > defaults.get("waves.breaking_steepness") * wavelength:
        raise WaveError(f"{name}: Hs {hs:.4g} m (4 std) at a peak period of {tp:.4g} s is "
                        f"steeper than a wave can be (it breaks at H/L = 1/7); expected the "
                        f"elevation column in metres (not mm or cm)")
    if keep.sum() > MAX_COMPONENTS:
        raise WaveError(f"{name}: {int(keep.sum())} components "
                        f"{'in all' if data_band is None else 'inside the data band'}, more "
                        f"than {MAX_COMPONENTS} (one per 1 / T Hz); expected a shorter record "
                        f"or a narrower band")
    if data_band is None:
        return
    outside = float(power[~keep].sum() / power.sum())
    if not outside < 1 - KEPT_MIN:
        raise WaveError(f"{name}: no part of the record (peak period {tp:.4g} s) lies inside "
                        f"the hydro data's band {data_band[0]:.3g}..{data_band[1]:.3g} rad/s "
                        f"(a share of {1 - outside:.2g} of its variance); expected a record of "
                        f"the waves the model was computed for")
    settings["record_outside_data"] = outside
    settings["data_band_rad_s"] = [float(data_band[0]), float(data_band[1])]
    if outside > 1e-3:
        settings["notes"].append(
            f"{name}: {100 * outside:.2g} % of the record's variance lies outside the hydro "
            f"data ({data_band[0]:.3g}..{data_band[1]:.3g} rad/s) and is left out")


def _ramp(settings: dict, wave: Wave, dt: float, ramp_time: float | None, std: float) -> float:
    """The ramp (s): the given one, else none when the kept wave (unramped; std its standard
    deviation, m) is at rest over its first half Tz from t = 0, sampled every dt, else
    RAMP_TZ Tz; settings say which and why."""
    tz, name = settings["tz_s"], settings["source"]
    first = max(2, math.ceil(0.5 * tz / dt))
    level = float(np.max(np.abs(wave.elevation(np.arange(first) * dt))))
    settings["start_m"] = level
    if ramp_time is not None:
        if not (math.isfinite(ramp_time) and ramp_time >= 0):
            raise WaveError(f"{name}: ramp_time {ramp_time}: expected a time >= 0 s")
        return float(ramp_time)
    if level <= REST_FRACTION * std:
        return 0.0
    ramp_time = RAMP_TZ * tz
    settings["notes"].append(
        f"{name}: the record does not start at rest (|eta| up to {level:.3g} m, "
        f"{level / std:.2g} std, over its first {first * dt:.3g} s): ramped over "
        f"{ramp_time:.4g} s ({RAMP_TZ:g} mean zero-crossing periods)")
    return ramp_time
