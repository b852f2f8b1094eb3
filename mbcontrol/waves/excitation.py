"""Wave excitation from per-unit-amplitude coefficients: time series at any times or at the
integrators' stage times, the non-causal excitation impulse response, and the linear complex
interpolation that refuses to extrapolate beyond the hydro data's band.
"""
from __future__ import annotations

import numpy as np

from ..errors import WaveError
from .realisation import Wave
from .synthesis import _synthesise, _synthesise_uniform, ramp, repeat_period


def excitation_impulse_response(omega_data, force_data, t) -> np.ndarray:
    """Non-causal excitation impulse response K_e(t) (N/m per s), shape (len(t), n_dof).

    K_e(t) = (1/pi) Re int_0^inf F(omega) exp(-i omega t) d omega, so that the excitation is
    the convolution F(t) = int K_e(tau) eta(t - tau) d tau (exp(-i omega t) convention).
    Trapezoidal quadrature on the data's grid; t may be negative (the response is non-causal).
    """
    omega_data = np.asarray(omega_data, float)
    phases = np.exp(-1j * np.multiply.outer(np.asarray(t, float), omega_data))
    integrand = phases[:, :, None] * np.asarray(force_data)[None, :, :]
    return np.trapezoid(integrand, omega_data, axis=1).real / np.pi


def excitation_series(wave: Wave, omega_data, force_data, t) -> np.ndarray:
    """Excitation time series (len(t), n_dof) from per-unit-amplitude complex coefficients.

    force_data (n_omega_data, n_dof) is interpolated (real and imaginary parts, linearly) to
    the wave's frequencies; components outside the data's band raise ValueError, because
    extrapolating excitation silently would corrupt the result.
    """
    omega_data = np.asarray(omega_data, dtype=float)
    coeffs = interpolate_complex(omega_data, np.asarray(force_data), wave.omega)
    return coefficient_series(wave, coeffs, t)


def coefficient_series(wave: Wave, coeffs, t) -> np.ndarray:
    """Excitation time series (len(t), n_dof) from each component's own coefficients
    (n_components, n_dof), complex per unit amplitude (a spread sea's, one direction each)."""
    weights = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs   # (n_comp, n_dof)
    t = np.asarray(t, dtype=float)
    series = _synthesise(wave, weights, t)
    return ramp(t, wave.ramp_time)[:, None] * series


def excitation_at_offsets(wave: Wave, omega_data, force_data, n: int, dt: float,
                          offsets) -> np.ndarray:
    """Excitation (n, len(offsets), n_dof) at t = (i + c) dt, i < n, for each offset c.

    The integrators' stage times: one interpolation of the coefficients, then an FFT per
    offset (a phase shift of the weights), so a 600 s record costs milliseconds.
    """
    coeffs = interpolate_complex(np.asarray(omega_data, float), np.asarray(force_data),
                                 wave.omega)
    return coefficient_offsets(wave, coeffs, n, dt, offsets)


def coefficient_offsets(wave: Wave, coeffs, n: int, dt: float, offsets) -> np.ndarray:
    """`excitation_at_offsets` from each component's own coefficients (n_components, n_dof).

    When every offset lies on the grid of sub-steps dt / s (s = 1 or 2: RK4's 0, 1/2, 1 take
    s = 2) and the repeat period is a whole number of sub-steps: one real inverse FFT over the
    period (`repeat_period`) gives the sum at every sub-step, and each offset is a strided
    slice of it. Otherwise an FFT (or blocks of phasors) per offset. The ramp is applied only
    where it rises (it is exactly 1 after ramp_time)."""
    weights = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs
    out = np.empty((n, len(offsets), weights.shape[1]))
    sub = next((s for s in (1, 2) if all(abs(c * s - round(c * s)) < 1e-12 for c in offsets)),
               None)
    period = repeat_period(wave, weights, dt / sub) \
        if sub is not None and wave.omega.size > 16 else None
    for j, c in enumerate(offsets):
        if period is not None:             # periodic in its length: longer records wrap
            first = int(round(c * sub))
            if first + sub * (n - 1) < period.shape[0]:     # a strided view: no index arrays
                out[:, j] = period[first:first + sub * (n - 1) + 1:sub]
            else:
                out[:, j] = np.take(period, first + sub * np.arange(n), axis=0, mode="wrap")
        else:
            out[:, j] = _synthesise_uniform(wave, weights, n, dt, c * dt)
        t = (np.arange(n) + c) * dt
        rising = t < wave.ramp_time
        out[rising, j] *= ramp(t[rising], wave.ramp_time)[:, None]
    return out


def interpolate_complex(omega_data, values, omega) -> np.ndarray:
    """Linear interpolation of complex values (n_omega_data, ...) to omega; no extrapolation."""
    lo, hi = omega_data[0], omega_data[-1]
    outside = (omega < lo * (1 - 1e-9)) | (omega > hi * (1 + 1e-9))
    if np.any(outside):
        bad = omega[outside]
        raise WaveError(f"wave components at {bad.min():.3g}..{bad.max():.3g} rad/s lie "
                        f"outside the hydro data's band {lo:.3g}..{hi:.3g} rad/s")
    flat = values.reshape(values.shape[0], -1)
    out = np.empty((omega.size, flat.shape[1]), dtype=complex)
    for j in range(flat.shape[1]):
        out[:, j] = (np.interp(omega, omega_data, flat[:, j].real)
                     + 1j * np.interp(omega, omega_data, flat[:, j].imag))
    return out.reshape((omega.size,) + values.shape[1:])
