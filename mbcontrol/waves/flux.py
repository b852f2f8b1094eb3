"""Wave energy flux (W per metre of crest) of any spectrum in water of finite depth:
J = rho g int S(omega) c_g(omega) d omega, with c_g from the linear dispersion relation; in
deep water it reduces to J = rho g^2 Hm0^2 Te / (64 pi) for any spectral shape (IEC TS
62600-101), Te = m_-1 / m_0 in period.
"""
from __future__ import annotations

import math

import numpy as np

from .dispersion import group_velocities
from .spectra import jonswap_spectrum

RHO = 1025.0           # kg/m^3, sea water
G = 9.81               # m/s^2


def spectrum_energy_flux(omega, S, depth: float = math.inf, rho: float = RHO,
                         g: float = G) -> np.ndarray:
    """J (W/m) of a spectrum S(omega) (m^2 s/rad; rows along the last axis) in water of depth
    h (m), by trapezoids on the given grid. For S(f) in m^2/Hz, pass omega = 2 pi f and
    S / (2 pi)."""
    omega = np.asarray(omega, dtype=float)
    cg = group_velocities(omega, depth, g)
    return rho * g * np.trapezoid(np.asarray(S, dtype=float) * cg, omega, axis=-1)


def deep_water_flux(hm0, te, rho: float = RHO, g: float = G):
    """J = rho g^2 Hm0^2 Te / (64 pi) (W/m): deep water, any spectral shape."""
    return rho * g ** 2 * np.asarray(hm0, float) ** 2 * np.asarray(te, float) / (64 * math.pi)


def energy_flux(hs: float, tp: float, gamma: float = 3.3, depth: float = math.inf,
                rho: float = RHO, g: float = G) -> float:
    """J (W/m) of a JONSWAP sea (Hm0 hs in m, peak period tp in s, peak enhancement gamma) in
    water of `depth` m: 4000 points from 0.2 to 6 times the peak frequency, m0 scaled to
    (hs / 4)^2 on that grid (deep water: J = rho g^2 Hm0^2 Te / (64 pi),
    Te = tp * te_over_tp(gamma))."""
    wp = 2 * math.pi / tp
    w = np.linspace(0.2 * wp, 6.0 * wp, 4000)
    s = jonswap_spectrum(w, hs, tp, gamma)
    s *= (hs / 4) ** 2 / np.trapezoid(s, w)               # exact m0 on the grid
    return float(spectrum_energy_flux(w, s, depth, rho, g))
