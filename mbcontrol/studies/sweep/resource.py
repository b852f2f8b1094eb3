"""The resource's year-to-year variability from buoy records (NOAA NDBC spectral density
files, `waves.read_ndbc_spectra`): each hour a sea state (Hm0 = 4 sqrt(m0), Te = m-1 / m0,
trapezoidal moments over the file's frequencies), assigned to the nearest of the site's seas,
and the hours of each block (a year, or with one year only a calendar month) made weights
over those seas (`Resource`), for the budget's resource term (`budget.resource_blocks`).

Nearest: the least Euclidean distance in (Hm0 / range of the site's Hm0, Te / range of its
Te), the ranges over the site's seas (a sea with only Tp has Te = Tp x Te/Tp of its JONSWAP
gamma). A block with fewer than MIN_HOURS valid hours is left out (and said).

With one year, blocks are its months and the interannual variability is estimated by a
month-block bootstrap: a synthetic year is 12 months drawn with replacement, so its annual
energy's variance is sigma_m^2 / 12 (sigma_m the months' spread, ddof 1: unbiased; computed in
closed form, no random draws). This ASSUMES months are exchangeable: the seasonal cycle
counts as variability, which overstates the spread a real year shows (its seasons are fixed);
it is an upper estimate, said so wherever it is reported.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ... import defaults
from ...errors import InputError

# MIN_HOURS: the defaults "resource.min_hours_year" (24 x 120) and "resource.min_hours_month"
# (24 x 7)


@dataclass(frozen=True)
class Resource:
    """Blocks of a buoy record as weights over a site's seas: kind "year" or "month",
    weights label -> (n_sea,) shares summing to 1, hours label -> valid hours, files, and
    notes (blocks left out)."""
    kind: str
    weights: dict
    hours: dict
    files: tuple
    notes: tuple = field(default_factory=tuple)


def hourly_sea_states(path) -> tuple[list, np.ndarray, np.ndarray]:
    """(stamps as (year, month), Hm0 m, Te s) of each valid hour of an NDBC spectral file."""
    from ...waves import read_ndbc_spectra
    f, S, stamps = read_ndbc_spectra(path)
    if S.size == 0:
        raise InputError(f"{path}: no valid hour (every row has the missing-value code 999)")
    if np.any(f <= 0):
        raise InputError(f"{path}: header: expected positive frequencies in Hz")
    m0 = np.trapezoid(S, f, axis=1)
    m_1 = np.trapezoid(S / f, f, axis=1)
    ok = m0 > 0
    hm0, te = 4.0 * np.sqrt(np.where(ok, m0, 1.0)), np.where(ok, m_1 / np.where(ok, m0, 1), 0)
    when = []
    for s in stamps:
        parts = s.split()
        year = int(parts[0])
        when.append((year + 1900 if year < 100 else year, int(parts[1])))
    keep = np.flatnonzero(ok)
    return [when[i] for i in keep], hm0[keep], te[keep]


def site_te(seas) -> np.ndarray:
    """Each site sea's energy period (s): the file's Te, else Tp x Te/Tp of its JONSWAP."""
    from ...waves import te_over_tp
    return np.array([s.te if math.isfinite(s.te) else s.tp * te_over_tp(s.gamma) for s in seas])


def nearest_sea(hm0, te, seas) -> np.ndarray:
    """Index of the nearest site sea of each (Hm0, Te), in the ranges' normalised plane."""
    H, T = np.array([s.hs for s in seas]), site_te(seas)
    sh = np.ptp(H) or 1.0
    st = np.ptp(T) or 1.0
    d = ((np.asarray(hm0)[:, None] - H[None]) / sh) ** 2 + \
        ((np.asarray(te)[:, None] - T[None]) / st) ** 2
    return np.argmin(d, axis=1)


def ndbc_resource(paths, seas) -> Resource:
    """The buoy files' hours as per-year weights over `seas` (two or more years in all) or,
    with one year, per-month weights (see the module's note on that assumption)."""
    when, index = [], []
    for path in paths:
        if not Path(path).is_file():
            raise InputError(f"--resource {path}: no such file (expected an NDBC spectral "
                             f"density file, text or .gz)")
        w, hm0, te = hourly_sea_states(path)
        when += w
        index.append(nearest_sea(hm0, te, seas))
    index = np.concatenate(index)
    years = sorted({y for y, _ in when})
    kind = "year" if len(years) >= 2 else "month"
    labels = [str(y) if kind == "year" else f"{y}-{m:02d}" for y, m in when]
    weights, hours, notes = {}, {}, []
    for label in sorted(set(labels)):
        mine = index[[lab == label for lab in labels]]
        least = defaults.get(f"resource.min_hours_{kind}")
        if mine.size < least:
            notes.append(f"{kind} {label} left out: {mine.size} valid hours (fewer than "
                         f"{least})")
            continue
        weights[label] = np.bincount(mine, minlength=len(seas)) / mine.size
        hours[label] = int(mine.size)
    if len(weights) < 2:
        raise InputError(f"--resource {', '.join(map(str, paths))}: {len(weights)} {kind}s "
                         f"with enough valid hours; the variability needs two or more")
    return Resource(kind, weights, hours, tuple(str(p) for p in paths), tuple(notes))


def block_spread(values, kind: str) -> tuple[float, int]:
    """(the interannual standard deviation of the annual energy, degrees of freedom) from
    per-block annual energies (MWh): per year their spread (ddof 1); per month the month-block
    bootstrap's sigma_m / sqrt(12) (ddof 1)."""
    v = np.asarray(values, float)
    spread = float(np.std(v, ddof=1))
    return (spread if kind == "year" else spread / math.sqrt(12.0)), v.size - 1
