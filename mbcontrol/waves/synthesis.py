"""Summing wave components in time: the half-cosine ramp, and Re sum_i w_i exp(-i omega_i t)
by one FFT on a uniform grid (when the step divides the repeat period) or by blocks of
phasors, for elevations and excitation alike (convention exp(-i omega t), as the hydro data).
`wave` below is any object with omega, d_omega (a `Wave`).
"""
from __future__ import annotations

import numpy as np


def ramp(t, ramp_time: float) -> np.ndarray:
    """Half-cosine ramp 0 -> 1 over ramp_time seconds (1 everywhere if ramp_time == 0)."""
    t = np.asarray(t, dtype=float)
    out = np.ones_like(t)
    if ramp_time <= 0:
        return out
    rising = t < ramp_time                  # 1 exactly after it (cos pi = -1): no cosines there
    out[rising] = 0.5 * (1.0 - np.cos(np.pi * np.clip(t[rising] / ramp_time, 0.0, None)))
    return out


def _synthesise(wave, weights, t) -> np.ndarray:
    """Re sum_i weights_i exp(-i omega_i t) at times t: FFT on a uniform grid when possible."""
    uniform_t = t.size > 2 and np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=1e-12)
    if uniform_t and wave.omega.size > 16:     # a few components: exact phases, cheap anyway
        return _synthesise_uniform(wave, weights, t.size, t[1] - t[0], t[0])
    return _synthesise_direct(wave.omega, weights, t)


def _synthesise_uniform(wave, weights, n: int, step: float, t0: float = 0.0):
    """The sum at t0 + k step, k < n: by FFT when the step divides the wave's repeat period,
    else in blocks that share one table of phasors (a matrix product per block, no
    exponentials per sample)."""
    if wave.omega.size <= 16:              # a few components: exact phases, cheap anyway
        return _synthesise_direct(wave.omega, weights, t0 + np.arange(n) * step)
    if t0 != 0.0:            # shift the phases to the grid's first time
        weights = weights * np.exp(-1j * wave.omega * t0)[:, None]
    period = repeat_period(wave, weights, step)
    if period is None:
        return _synthesise_blocks(wave.omega, weights, n, step)
    # the sum is exactly periodic in n_fft samples: longer records wrap around
    return period[np.arange(n) % period.shape[0]]


def repeat_period(wave, weights, step: float):
    """Re sum_i weights_i exp(-i omega_i k step) for k < N, one repeat period 2 pi / d_omega
    of N samples, by one real inverse FFT; None when the step does not divide the period (or
    the components reach its Nyquist frequency). Exact: every omega_i is a whole multiple
    k_i d_omega, so the sum is sum_i Re conj(w_i) exp(+2 pi i k_i n / N), what irfft computes
    from the half spectrum X_k = N conj(w_k) / 2 (tests: against the direct sum)."""
    if not wave.d_omega or wave.omega.size == 0:
        return None
    n_fft = int(round(2 * np.pi / (wave.d_omega * step)))
    k = np.rint(wave.omega / wave.d_omega).astype(int)
    if n_fft < 2 or abs(n_fft * wave.d_omega * step - 2 * np.pi) > 1e-9 or k.max() >= n_fft // 2 \
            or k.min() < 1:
        return None
    half = np.zeros((n_fft // 2 + 1, weights.shape[1]), dtype=complex)
    np.add.at(half, k, np.conj(weights) * (0.5 * n_fft))
    return np.fft.irfft(half, n=n_fft, axis=0)


def _synthesise_blocks(omega, weights, n: int, step: float, block: int = 512) -> np.ndarray:
    """Re sum_i weights_i exp(-i omega_i (j + k) step) for block starts j: the table
    exp(-i omega k step), k < block, is computed once and each block rotates the weights."""
    table = np.exp(-1j * np.multiply.outer(np.arange(min(block, n)) * step, omega))
    out = np.empty((n, weights.shape[1]))
    for start in range(0, n, block):
        stop = min(start + block, n)
        rotated = np.exp(-1j * omega * start * step)[:, None] * weights
        out[start:stop] = (table[:stop - start] @ rotated).real
    return out


def _synthesise_direct(omega, weights, t) -> np.ndarray:
    out = np.zeros((t.size, weights.shape[1]))
    for start in range(0, t.size, 4096):        # bounded memory for long records
        block = t[start:start + 4096]
        out[start:start + 4096] = (np.exp(-1j * np.multiply.outer(block, omega))
                                   @ weights).real
    return out
