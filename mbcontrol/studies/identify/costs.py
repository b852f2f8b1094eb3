"""Measures of a periodic response that the identification costs compare.

All take samples y(t) over a steady window holding whole periods of the wave (the window is
cut to an integer number of periods first), so model and measurement are measured alike.

- `harmonic`: the complex first-harmonic amplitude Y, y(t) ~ c + d t + Re(Y e^{i omega t})
  (least squares on cos, sin, a constant and a trend: a slow drift, e.g. a soft sway mode still
  settling, leaks into the harmonic otherwise), in the signal's unit;
- `peaks_and_lows`: the seed's Eq. 67 vector: per wave period in the window, the largest and
  the smallest value, [peak_1, low_1, peak_2, low_2, ...], in the signal's unit;
- `eq67_error`: the seed's error, sum |f_hat_i - f_i|^2 over peaks and lows (unit squared).
"""
from __future__ import annotations

import numpy as np

from ...errors import InputError


def whole_periods(t, omega: float, start: float, end: float) -> tuple[float, float, int]:
    """(start, end, n): the window [start, end] shortened at its end to n >= 1 whole periods.
    ValueError when it holds less than one period."""
    period = 2 * np.pi / omega
    n = int(np.floor((end - start) / period + 1e-9))
    if n < 1:
        raise InputError(f"window {start:.3f}..{end:.3f} s is shorter than one wave period "
                         f"({period:.3f} s)")
    return start, start + n * period, n


def _in(t, start, end):
    t = np.asarray(t, float)
    return (t >= start - 1e-9) & (t < end - 1e-9)


def harmonic(t, y, omega: float, start: float, end: float) -> complex:
    """First-harmonic complex amplitude Y (signal unit) of y over whole periods of
    [start, end]: y ~ c + d t + Re(Y exp(i omega t)), least squares. |Y| is the amplitude."""
    start, end, _ = whole_periods(t, omega, start, end)
    keep = _in(t, start, end)
    tt, yy = np.asarray(t, float)[keep], np.asarray(y, float)[keep]
    (a, b, _, _), *_ = np.linalg.lstsq(_basis(tt, omega, start, end), yy, rcond=None)
    return complex(a, b)


def _basis(tt, omega, start, end):
    """cos, -sin, 1 and the trend (t - mid) / half-length over the window."""
    trend = (tt - 0.5 * (start + end)) / (0.5 * (end - start))
    return np.column_stack([np.cos(omega * tt), -np.sin(omega * tt), np.ones_like(tt), trend])


def harmonic_weights(t, omega: float, start: float, end: float) -> np.ndarray:
    """(2, n) rows: Re and Im of the first harmonic as linear weights on the samples y(t)
    (zero outside the window), so that [Re Y, Im Y] = W @ y and derivatives follow linearly."""
    start, end, _ = whole_periods(t, omega, start, end)
    t = np.asarray(t, float)
    keep = _in(t, start, end)
    weights = np.zeros((2, t.size))
    weights[:, keep] = np.linalg.pinv(_basis(t[keep], omega, start, end))[:2]
    return weights


def peaks_and_lows(t, y, omega: float, start: float, end: float) -> np.ndarray:
    """[peak_1, low_1, peak_2, low_2, ...]: max and min of y in each wave period of the
    window (whole periods only), in the signal's unit (the seed's Eq. 67 vector)."""
    start, end, n = whole_periods(t, omega, start, end)
    t, y = np.asarray(t, float), np.asarray(y, float)
    period = 2 * np.pi / omega
    out = []
    for k in range(n):
        seg = y[_in(t, start + k * period, start + (k + 1) * period)]
        if seg.size == 0:
            raise InputError(f"no sample in period {k} of the window {start:.3f}..{end:.3f} s")
        out += [seg.max(), seg.min()]
    return np.array(out)


def peak_low_indices(t, y, omega: float, start: float, end: float) -> np.ndarray:
    """Sample indices of `peaks_and_lows` (for derivatives: d peak / d p = dy/dp there)."""
    start, end, n = whole_periods(t, omega, start, end)
    t, y = np.asarray(t, float), np.asarray(y, float)
    period = 2 * np.pi / omega
    out = []
    for k in range(n):
        idx = np.flatnonzero(_in(t, start + k * period, start + (k + 1) * period))
        out += [idx[np.argmax(y[idx])], idx[np.argmin(y[idx])]]
    return np.array(out, int)


def eq67_error(measured, model) -> float:
    """The seed's Eq. 67: sum_i |f_hat_i - f_i|^2 over the peaks and lows (unit squared)."""
    measured, model = np.asarray(measured, float), np.asarray(model, float)
    if measured.shape != model.shape:
        raise InputError(f"peaks and lows differ in number: {measured.size} measured, "
                         f"{model.size} modelled")
    return float(np.sum((measured - model) ** 2))
