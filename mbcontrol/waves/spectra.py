"""Wave spectra and their moments: JONSWAP (Pierson-Moskowitz at gamma = 1), spectral moments,
Hm0 and the energy period Te of any spectrum, and Te / Tp of the spectrum a sea is simulated
with (by quadrature, so a site's Te and the simulated sea's Te can be compared).

Units: omega in rad/s and S(omega) in m^2 s/rad; or f in Hz and S(f) in m^2/Hz (buoy files).
Moments use the trapezoidal rule on the given grid.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..errors import WaveError


def jonswap_spectrum(omega, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """One-sided JONSWAP spectral density S(omega) (m^2 s/rad), DNV-RP-C205 form.

    gamma = 1 gives Pierson-Moskowitz. sigma = 0.07 below the peak, 0.09 above.
    """
    omega = np.asarray(omega, dtype=float)
    pm, r = _pm_and_peak_shape(omega, hs, 2 * np.pi / tp)
    with np.errstate(over="ignore", invalid="ignore"):
        density = (1 - 0.287 * np.log(gamma)) * pm * gamma ** r
    return np.where(omega > 0, np.nan_to_num(density), 0.0)


def _pm_and_peak_shape(omega, hs: float, wp: float):
    """(Pierson-Moskowitz density, r): JONSWAP is (1 - 0.287 ln gamma) PM gamma^r, with
    sigma = 0.07 below the peak frequency wp (rad/s), 0.09 above."""
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        pm = 5 / 16 * hs**2 * wp**4 * omega**-5.0 * np.exp(-1.25 * (wp / omega) ** 4)
        sigma = np.where(omega <= wp, 0.07, 0.09)
        return pm, np.exp(-0.5 * ((omega - wp) / (sigma * wp)) ** 2)


def moment(x, S, n: int, axis: int = -1) -> np.ndarray:
    """Spectral moment m_n = int x^n S(x) dx (trapezoids on the given grid, x > 0)."""
    x = np.asarray(x, dtype=float)
    return np.trapezoid(np.asarray(S, dtype=float) * x ** n, x, axis=axis)


def spectral_hm0_te(f, S) -> tuple[np.ndarray, np.ndarray]:
    """Hm0 = 4 sqrt(m0) (m) and Te = m_-1 / m0 (s) per row of S(f) (m^2/Hz, f in Hz).

    (With omega in rad/s and S(omega) the same Hm0, and Te = 2 pi m_-1 / m0.)"""
    m0 = moment(f, S, 0)
    return 4 * np.sqrt(m0), moment(f, S, -1) / m0


@lru_cache(maxsize=64)
def te_over_tp(gamma: float = 3.3) -> float:
    """Te / Tp of a JONSWAP spectrum of peak enhancement gamma (m_-1 / m_0 over the peak
    period), by quadrature on a fine geometric grid (0.2 to 50 times the peak frequency; the
    omega^-5 tail beyond holds < 1e-7 of m_-1). gamma = 1 (Pierson-Moskowitz): 0.8572;
    gamma = 3.3: 0.9033."""
    w, pm, r = _te_grid()
    s = (1 - 0.287 * np.log(gamma)) * pm * gamma ** r   # jonswap_spectrum's density
    return float(np.trapezoid(s / w, w) / np.trapezoid(s, w))


@lru_cache(maxsize=1)
def _te_grid():
    """te_over_tp's grid (in units of the peak frequency, Tp = 2 pi), its Pierson-Moskowitz
    density and peak-shape exponent: what does not depend on gamma, computed once (the
    root search of gamma_for_te_over_tp calls te_over_tp a dozen times per sea)."""
    w = np.geomspace(0.2, 50.0, 40001)
    return (w, *_pm_and_peak_shape(w, 1.0, 2 * np.pi / (2 * math.pi)))


@lru_cache(maxsize=1024)
def gamma_for_te_over_tp(ratio: float) -> float:
    """The JONSWAP gamma (1..20) whose Te / Tp equals ratio (e.g. a site file's own Te / Tp);
    ValueError when no gamma in that range has it. Cached: a sweep asks once per sea, and
    again for the same seas in the next sweep."""
    from scipy.optimize import brentq
    lo, hi = te_over_tp(1.0), te_over_tp(20.0)
    if not lo - 1e-6 <= ratio <= hi:
        raise WaveError(f"Te/Tp = {ratio:.4g}: a JONSWAP spectrum with 1 <= gamma <= 20 has "
                        f"{lo:.4f} to {hi:.4f}")
    if ratio <= lo:
        return 1.0
    return float(brentq(lambda g: _te_over_tp_uncached(g) - ratio, 1.0, 20.0, xtol=1e-10))


def _te_over_tp_uncached(gamma: float) -> float:
    return te_over_tp.__wrapped__(gamma)
