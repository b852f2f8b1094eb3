"""Power performance: wave energy flux, capture width, power matrices, annual energy, and the
occurrence of sea states at a site from a year of buoy spectra (NOAA NDBC files).

Units: SI; spectra S(omega) in m^2 s/rad; energy flux J in W per metre of wave crest; energy
per year in MWh with HOURS_PER_YEAR = 8766 (365.25 days).
"""
from __future__ import annotations

import gzip
import math
from pathlib import Path

import numpy as np
import xarray as xr

HOURS_PER_YEAR = 8766.0


def energy_flux(hs: float, tp: float, gamma: float = 3.3, depth: float = math.inf,
                rho: float = 1025.0, g: float = 9.81) -> float:
    """J = rho g int S(omega) c_g(omega) d omega (W/m) of a JONSWAP sea in water of `depth` m
    (deep water: J = rho g^2 Hm0^2 Te / (64 pi), Te = m_-1 / m_0 in period)."""
    from ...waves import group_velocity, jonswap_spectrum
    wp = 2 * math.pi / tp
    w = np.linspace(0.2 * wp, 6.0 * wp, 4000)
    s = jonswap_spectrum(w, hs, tp, gamma)
    s *= (hs / 4) ** 2 / np.trapezoid(s, w)               # exact m0 on the grid
    cg = g / (2 * w) if math.isinf(depth) else np.array([group_velocity(x, depth, g) for x in w])
    return float(rho * g * np.trapezoid(s * cg, w))


def annual_energy_MWh(mean_power_W, weights) -> float:
    """Mean annual energy production: sum_i w_i P_i x 8766 h, in MWh (weights: shares of the
    year; NaN powers count as 0 only where the weight is 0)."""
    p = np.asarray(mean_power_W, float)
    w = np.asarray(weights, float)
    if np.any(np.isnan(p) & (w > 0)):
        raise ValueError("annual energy: a sea state with weight > 0 has no power")
    return float(np.nansum(p * w) * HOURS_PER_YEAR / 1e6)


def power_matrix(ds: xr.Dataset, variable: str = "mean_power_W", period: str = "tp",
                 reduce_dims=("seed",)) -> xr.DataArray:
    """The variable over an (hs, period) table, averaged over seeds; a sweep over a grid or
    over a list whose seas fall on one."""
    da = ds[variable].mean([d for d in reduce_dims if d in ds[variable].dims])
    if set(da.dims) - {"sea"}:
        raise ValueError(f"power matrix: {variable} still varies over "
                         f"{sorted(set(da.dims) - {'sea'})}; select one value of each first")
    hs, per = np.unique(ds["hs"].values), np.unique(np.round(ds[period].values, 9))
    table = np.full((hs.size, per.size), np.nan)
    for k in range(ds.sizes["sea"]):
        i = np.searchsorted(hs, ds["hs"].values[k])
        j = np.searchsorted(per, round(float(ds[period].values[k]), 9))
        table[i, j] = float(da.isel(sea=k))
    return xr.DataArray(table, coords={"hs": hs, period: per}, dims=("hs", period),
                        name=variable, attrs={"units": "W"})


def read_ndbc_spectra(path) -> tuple[np.ndarray, np.ndarray, list]:
    """(f in Hz, S in m^2/Hz per row, row stamps) from an NDBC spectral wave density file
    (text or .gz: header 'YY MM DD hh [mm] f1 f2 ...', one hour a row; rows with the
    missing-value code 999 are dropped)."""
    path = Path(path)
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        lines = [l.split() for l in fh if l.strip()]
    header = [h.lstrip("#") for h in lines[0]]
    n_time = sum(1 for h in header if h in ("YY", "YYYY", "MM", "DD", "hh", "mm"))
    try:
        f = np.array([float(h) for h in header[n_time:]])
    except ValueError:
        raise ValueError(f"{path}: header {' '.join(header[:8])}...: expected date columns "
                         f"then frequencies in Hz") from None
    stamps, rows = [], []
    for k, parts in enumerate(lines[1:], start=2):
        if len(parts) != n_time + f.size:
            raise ValueError(f"{path}: line {k} has {len(parts)} values; expected "
                             f"{n_time + f.size}")
        values = np.array([float(v) for v in parts[n_time:]])
        if np.any(values >= 999.0):
            continue
        stamps.append(" ".join(parts[:n_time]))
        rows.append(values)
    return f, np.array(rows), stamps


def spectral_hm0_te(f, S) -> tuple[np.ndarray, np.ndarray]:
    """Hm0 = 4 sqrt(m0) (m) and Te = m_-1 / m0 (s) per row of S(f) (m^2/Hz, f in Hz)."""
    m0 = np.trapezoid(S, f, axis=-1)
    m_1 = np.trapezoid(S / f, f, axis=-1)
    return 4 * np.sqrt(m0), m_1 / m0


def occurrence(hm0, te, hs_edges, te_edges) -> xr.DataArray:
    """Joint occurrence (share of the records) over Hm0 x Te bins, labelled by bin centres."""
    counts, _, _ = np.histogram2d(hm0, te, bins=[hs_edges, te_edges])
    share = counts / max(len(hm0), 1)
    centre = lambda e: 0.5 * (np.asarray(e[:-1]) + np.asarray(e[1:]))  # noqa: E731
    return xr.DataArray(share, coords={"hs": centre(hs_edges), "te": centre(te_edges)},
                        dims=("hs", "te"), name="occurrence",
                        attrs={"records": int(len(hm0))})
