"""Reference formulas for the wave tests, written out independently of mbcontrol.waves: the
Pierson-Moskowitz and JONSWAP (DNV) spectra, the half-cosine ramp, spectral moments by
quadrature and a direct sum of wave components."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad

HS, TP = 2.0, 8.0                     # a moderate North Sea state (m, s)
WP = 2 * math.pi / TP                 # peak angular frequency (rad/s)


# --------------------------------------------------------------------- reference formulas

def pm_reference(w, hs=HS, tp=TP):
    """Pierson-Moskowitz, DNV-RP-C205 Eq. (3.5.5.1) in omega form:
    S = 5/16 Hs^2 wp^4 w^-5 exp(-5/4 (wp/w)^4)."""
    wp = 2 * math.pi / tp
    w = np.asarray(w, dtype=float)
    return 5.0 / 16.0 * hs**2 * wp**4 * w**-5 * np.exp(-5.0 / 4.0 * (wp / w) ** 4)


def jonswap_reference(w, gamma, hs=HS, tp=TP):
    """JONSWAP, DNV-RP-C205 (3.5.5.2): A_g S_PM gamma^exp(-(w - wp)^2 / (2 s^2 wp^2)),
    A_g = 1 - 0.287 ln(gamma), s = 0.07 for w <= wp and 0.09 above."""
    wp = 2 * math.pi / tp
    w = np.asarray(w, dtype=float)
    s = np.where(w <= wp, 0.07, 0.09)
    r = np.exp(-((w - wp) ** 2) / (2 * s**2 * wp**2))
    return (1 - 0.287 * math.log(gamma)) * pm_reference(w, hs, tp) * gamma**r


def half_cosine(t, ramp_time):
    """0.5 (1 - cos(pi t / T_r)) = sin^2(pi t / (2 T_r)) on [0, T_r], 0 before, 1 after."""
    x = np.clip(np.asarray(t, dtype=float) / ramp_time, 0.0, 1.0)
    return np.sin(0.5 * np.pi * x) ** 2


def m0_quad(spectrum):
    """Zeroth moment by adaptive quadrature, split where the integrand bends (the peak,
    where JONSWAP's sigma jumps) so each piece is smooth; relative tolerance 1e-11."""
    edges = [0.0, 0.5 * WP, WP, 2 * WP, 10 * WP, np.inf]
    return sum(quad(spectrum, a, b, epsabs=0.0, epsrel=1e-11, limit=200)[0]
               for a, b in zip(edges[:-1], edges[1:]))


def direct_sum(omega, amplitude, phase, coeffs, t):
    """F(t) = Re sum_i a_i F_i exp(-i (w_i t + phi_i)) = sum_i a_i (Re F_i cos + Im F_i sin),
    written with real trigonometry so it shares no code path with the module's complex one."""
    theta = np.multiply.outer(t, omega) + phase                  # (n_t, n_comp)
    return (np.cos(theta) * amplitude) @ coeffs.real + (np.sin(theta) * amplitude) @ coeffs.imag
