"""The pseudo-spectral bound's limits between its collocation points.

The QP holds |F| <= force_max and |x| <= stroke_max only at n_t collocation times; the optimal
force pushes against the limit at those times and bulges between them (WecOptTool's WaveBot,
750 N: 800.7 N at our then-default 2x density). A sparser grid only loosens the QP, so the
figure stays an upper bound, but a reader must see how far the force it describes breaks the
limit. Here the optimal force and position are evaluated on a grid `DENSE_FACTOR` times finer,
by one FFT each (the signals are trigonometric polynomials on the repeat period).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError

# The default collocation density, points per 2 k_max + 1 (the pseudo-spectral QP's n_t). A
# sparser grid loosens the QP, so the figure falls towards its dense-grid limit as points are
# added; measured excess over a dense grid (ov 32-64), %, [force overshoot between points, %]:
#   sphere regular, 8 harmonics, 2 MN:   ov 2 +0.20 [0.5], 4 +0.03 [0.1], 6 +0.006
#   sphere T 6 s H 1 m, 8 harm., 200 kN: ov 2 +0.12 [1.0], 4 +0.03 [0.2], 6 +0.013 [0.1]
#   sphere Hs 2.5 Tp 6 120 s sea, 500 kN / 1 m (tight): ov 2 +0.56 [9.9], 3 +0.23 [5.4],
#     4 +0.16 [2.9], 6 +0.056 [1.2], 8 +0.025 [0.7]
#   sphere Hs 3.5 Tp 9.67 300 s sea to 12 rad/s, 2 MN / 4 m (570 frequencies, IPM, quiet
#     machine; against ov 8): ov 2 +0.028 [11] 4.4 s, 4 +0.006 [3.2] 7.7 s, 6 +0.001 [1.3] 10.7 s
# WecOptTool's WaveBot sat 1.1 % high at ov 2 (issue 20). 4 (WecOptTool's nsubsteps = 4) is
# within 0.2 % but by a thin margin in a tight sea; 6 keeps a 3x margin for 1.4x the time.
OVERSAMPLE = 6.0
# 16x the collocation grid (itself >= 2 samples per shortest period at oversample 1): the
# sampled maximum of a harmonic of the top frequency is then within 1 - cos(pi / 32) = 0.5 %
# of its amplitude, and of the whole signal far closer (its top harmonics are small)
DENSE_FACTOR = 16


def trig_samples(harmonic, coefficients, n: int) -> np.ndarray:
    """Re sum_k Y_k exp(-2 pi i k_k j / n), j = 0..n-1: a periodic signal from its phasors
    (exp(-i omega t), omega_k = 2 pi k_k / T) at n equally spaced times over T; n > max k."""
    harmonic = np.asarray(harmonic, int)
    if n <= harmonic.max():
        raise InputError(f"trig_samples: {n} samples alias harmonic {harmonic.max()}")
    spectrum = np.zeros(n, complex)
    np.add.at(spectrum, harmonic, np.asarray(coefficients, complex))
    return np.fft.fft(spectrum).real       # numpy's forward FFT carries exp(-2 pi i k j / n)


def dense_extremes(problem, F_k, force_max: float, stroke_max: float,
                   factor: int = DENSE_FACTOR) -> dict:
    """Largest |force| (N or N m) and |position| (m or rad) of the force with phasors F_k on
    `factor` times the problem's collocation grid, and their overshoots of the limits in %
    (100 (max / limit - 1), <= 0 when the limit holds; nan for an infinite limit). The force
    is the one the limit acts on: the machine's F_k, or with the limit on the hull the force
    the drivetrain puts on it (the problem's force_offset + force_gain F_k)."""
    k = np.rint(problem.omega * problem.period / (2 * np.pi)).astype(int)
    n = factor * problem.time.size
    X_k = 1j * (problem.E + F_k) / (problem.thevenin.impedance * problem.omega)
    L_k = problem.force_offset + problem.force_gain * F_k
    out = {"max_force_dense": float(np.max(np.abs(trig_samples(k, L_k, n)))),
           "max_position_dense": float(np.max(np.abs(trig_samples(k, X_k, n))))}
    for name, key, limit in (("force", "max_force_dense", force_max),
                             ("position", "max_position_dense", stroke_max)):
        out[f"{name}_overshoot_pct"] = (100.0 * (out[key] / limit - 1.0)
                                       if math.isfinite(limit) else math.nan)
    return out
