"""Waves: regular and irregular (JONSWAP, Pierson-Moskowitz) seas, ramps, excitation series.

Convention (as the hydro data, `exp(-i omega t)`): a wave of components (omega_i, a_i, phi_i)
has the elevation at the n-frame origin eta(t) = sum a_i cos(omega_i t + phi_i) (m, positive
up) and the excitation F(t) = Re sum a_i F_hat(omega_i) exp(-i(omega_i t + phi_i)), with F_hat
the excitation per unit amplitude from the hydro data. Irregular seas use a uniform frequency
grid d_omega = 2 pi / T_repeat, so a record shorter than T_repeat never repeats and the series
is synthesised exactly with one FFT.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Wave:
    """A sum of regular components: frequencies (rad/s), amplitudes (m), phases (rad)."""
    kind: str                                    # "regular" | "jonswap" | "pm" | "components"
    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    direction: float = 0.0                       # rad, NED: travelling towards +x, +y starboard
    ramp_time: float = 0.0                       # s, half-cosine ramp from zero
    settings: dict = field(default_factory=dict)  # what made it (for provenance), incl. seed
    d_omega: float | None = None                 # uniform grid spacing, when on one

    def elevation(self, t) -> np.ndarray:
        """Wave elevation at the n-frame origin (m, positive up), ramp included."""
        t = np.asarray(t, dtype=float)
        weights = (self.amplitude * np.exp(-1j * self.phase))[:, None]
        return ramp(t, self.ramp_time) * _synthesise(self, weights, np.atleast_1d(t))[:, 0]

    @property
    def period(self) -> float:
        """Regular wave period, or the peak period of a spectrum (s)."""
        return self.settings.get("period") or self.settings.get("tp")

    def describe(self) -> dict:
        return {"type": self.kind, **self.settings, "direction_rad": self.direction,
                "ramp_s": self.ramp_time, "n_components": int(self.omega.size)}


def wavenumber(omega: float, depth: float, g: float = 9.81) -> float:
    """k (rad/m) of the linear dispersion relation omega^2 = g k tanh(k h), omega in rad/s and
    the water depth h in m (Newton's method from the deep-water guess)."""
    k = omega ** 2 / g
    for _ in range(50):
        f = g * k * math.tanh(k * depth) - omega ** 2
        kh = k * depth
        df = g * math.tanh(kh) + (g * kh / math.cosh(kh) ** 2 if kh < 350 else 0.0)
        k, step = k - f / df, f / df
        if abs(step) < 1e-14 * k:
            break
    return k


def group_velocity(omega: float, depth: float, g: float = 9.81) -> float:
    """c_g (m/s) in water of depth h (m): (omega / k) (1 + 2 k h / sinh 2 k h) / 2."""
    k = wavenumber(omega, depth, g)
    kh2 = 2 * k * depth
    return omega / k * 0.5 * (1 + (kh2 / math.sinh(kh2) if kh2 < 700 else 0.0))  # deep: 1/2


def ramp(t, ramp_time: float) -> np.ndarray:
    """Half-cosine ramp 0 -> 1 over ramp_time seconds (1 everywhere if ramp_time == 0)."""
    t = np.asarray(t, dtype=float)
    if ramp_time <= 0:
        return np.ones_like(t)
    x = np.clip(t / ramp_time, 0.0, 1.0)
    return 0.5 * (1.0 - np.cos(np.pi * x))


def regular(height: float, period: float, *, phase: float = 0.0, direction: float = 0.0,
            ramp_time: float | None = None) -> Wave:
    """A regular wave of height H (m, crest to trough) and period T (s); ramp 2 T by default."""
    if height < 0 or period <= 0:
        raise ValueError(f"regular wave: expected height >= 0 and period > 0, got "
                         f"H={height}, T={period}")
    ramp_time = 2 * period if ramp_time is None else ramp_time
    return Wave("regular", np.array([2 * np.pi / period]), np.array([height / 2]),
                np.array([phase]), direction, ramp_time,
                {"height": height, "period": period})


def jonswap_spectrum(omega, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """One-sided JONSWAP spectral density S(omega) (m^2 s/rad), DNV-RP-C205 form.

    gamma = 1 gives Pierson-Moskowitz. sigma = 0.07 below the peak, 0.09 above.
    """
    omega = np.asarray(omega, dtype=float)
    wp = 2 * np.pi / tp
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        pm = 5 / 16 * hs**2 * wp**4 * omega**-5.0 * np.exp(-1.25 * (wp / omega) ** 4)
        sigma = np.where(omega <= wp, 0.07, 0.09)
        peak = gamma ** np.exp(-0.5 * ((omega - wp) / (sigma * wp)) ** 2)
    density = (1 - 0.287 * np.log(gamma)) * pm * peak
    return np.where(omega > 0, np.nan_to_num(density), 0.0)


def irregular(hs: float, tp: float, *, gamma: float = 3.3, seed: int = 0,
              duration: float = 600.0, band: tuple[float, float] = (0.3, 4.0),
              direction: float = 0.0, ramp_time: float | None = None,
              kind: str = "jonswap") -> Wave:
    """An irregular sea with random phases (seeded) on a uniform grid covering `duration`.

    Components span band[0]..band[1] times the peak frequency; amplitudes a = sqrt(2 S dw)
    are scaled so that 4 sqrt(m0) equals hs exactly on the grid. Ramp: 2 Tp by default.
    """
    if hs <= 0 or tp <= 0 or gamma < 1:
        raise ValueError(f"{kind}: expected hs > 0, tp > 0, gamma >= 1; got {hs}, {tp}, {gamma}")
    wp = 2 * np.pi / tp
    repeat = max(duration, 20 * tp)
    d_omega = 2 * np.pi / repeat
    k = np.arange(math.ceil(band[0] * wp / d_omega), math.floor(band[1] * wp / d_omega) + 1)
    omega = k * d_omega
    density = jonswap_spectrum(omega, hs, tp, gamma if kind == "jonswap" else 1.0)
    amplitude = np.sqrt(2 * density * d_omega)
    amplitude *= hs / (4 * np.sqrt(0.5 * np.sum(amplitude**2)))
    phase = np.random.default_rng(seed).uniform(0, 2 * np.pi, omega.size)
    ramp_time = 2 * tp if ramp_time is None else ramp_time
    settings = {"hs": hs, "tp": tp, "gamma": gamma if kind == "jonswap" else 1.0, "seed": seed}
    return Wave(kind, omega, amplitude, phase, direction, ramp_time, settings, d_omega)


def from_args(kind: str, *, height=None, period=None, hs=None, tp=None, gamma=3.3, seed=0,
              duration=600.0, data_band=None) -> Wave:
    """The wave a CLI or config describes: 'regular', 'jonswap' or 'pm'.

    data_band: (lo, hi) rad/s of the model's hydro data; an irregular sea's components are kept
    inside it (Hs stays exact on the kept components; settings["spectrum_outside_data"] records
    the fraction of the spectrum's variance that fell outside)."""
    if kind == "regular":
        if height is None or period is None:
            raise ValueError("a regular wave needs --height and --period")
        return regular(height, period)
    if kind in ("jonswap", "pm"):
        if hs is None or tp is None:
            raise ValueError(f"a {kind} sea needs --hs and --tp")
        band = (0.3, 4.0)
        if data_band is None:
            return irregular(hs, tp, gamma=gamma, seed=seed, duration=duration, kind=kind)
        wp = 2 * np.pi / tp
        lo, hi = max(band[0], data_band[0] / wp), min(band[1], data_band[1] / wp)
        if not lo < hi:
            raise ValueError(f"a {kind} sea with tp = {tp} s lies outside the hydro data's band "
                             f"{data_band[0]:.3g}..{data_band[1]:.3g} rad/s")
        wave = irregular(hs, tp, gamma=gamma, seed=seed, duration=duration, band=(lo, hi), kind=kind)
        w = np.linspace(band[0] * wp, band[1] * wp, 4001)
        S = jonswap_spectrum(w, hs, tp, gamma if kind == "jonswap" else 1.0)
        inside = (w >= lo * wp) & (w <= hi * wp)
        wave.settings["spectrum_outside_data"] = float(1 - np.trapezoid(S * inside, w) / np.trapezoid(S, w))
        return wave
    raise ValueError(f"unknown wave type {kind!r}; expected regular, jonswap or pm")


def from_elevation(t, eta, *, band: tuple[float, float] | None = None,
                   ramp_time: float = 0.0, direction: float = 0.0) -> Wave:
    """A wave reproducing a measured elevation record eta(t) at the n-frame origin (m, up).

    t must be uniform. The record is decomposed by FFT into components omega_k = 2 pi k / T
    (T = record length): exactly the periodic extension of the record. Components outside
    `band` (rad/s; e.g. the hydro data's) and the mean are dropped, and the fraction of the
    variance dropped is recorded in settings["dropped_variance"]. Excitation from this wave
    equals the (non-causal) convolution of the record with the excitation impulse response.
    """
    t, eta = np.asarray(t, float), np.asarray(eta, float)
    if t.ndim != 1 or t.size != eta.size or t.size < 4:
        raise ValueError("from_elevation: expected 1-D t and eta of equal length (>= 4)")
    step = t[1] - t[0]
    if not np.allclose(np.diff(t), step, rtol=1e-6, atol=0):
        raise ValueError("from_elevation: t must be uniformly spaced")
    n = t.size
    spectrum = np.fft.rfft(eta - eta.mean())
    k = np.arange(spectrum.size)
    d_omega = 2 * np.pi / (n * step)
    omega = k * d_omega
    amplitude = 2 * np.abs(spectrum) / n
    if n % 2 == 0:
        amplitude[-1] /= 2                       # the Nyquist term is not doubled
    phase = np.angle(spectrum) - omega * t[0]    # the record may start at t0 != 0
    keep = k > 0
    if band is not None:
        keep &= (omega >= band[0]) & (omega <= band[1])
    total = np.sum(amplitude[k > 0] ** 2)
    dropped = 1 - np.sum(amplitude[keep] ** 2) / total if total > 0 else 0.0
    settings = {"record_s": float(n * step), "samples": int(n), "mean_m": float(eta.mean()),
                "dropped_variance": float(dropped)}
    return Wave("elevation", omega[keep], amplitude[keep], phase[keep], direction, ramp_time,
                settings, d_omega)


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
    weights = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs
    out = np.empty((n, len(offsets), weights.shape[1]))
    for j, c in enumerate(offsets):
        t = (np.arange(n) + c) * dt
        series = _synthesise_uniform(wave, weights, n, dt, c * dt)
        out[:, j] = ramp(t, wave.ramp_time)[:, None] * series
    return out


def _synthesise_uniform(wave: Wave, weights, n: int, step: float, t0: float = 0.0):
    """The sum at t0 + k step, k < n: by FFT when the step divides the wave's repeat period,
    else in blocks that share one table of phasors (a matrix product per block, no
    exponentials per sample)."""
    if wave.omega.size <= 16:              # a few components: exact phases, cheap anyway
        return _synthesise_direct(wave.omega, weights, t0 + np.arange(n) * step)
    if t0 != 0.0:            # shift the phases to the grid's first time
        weights = weights * np.exp(-1j * wave.omega * t0)[:, None]
    n_fft = int(round(2 * np.pi / (wave.d_omega * step))) if wave.d_omega else 0
    k = np.rint(wave.omega / wave.d_omega).astype(int) if wave.d_omega else None
    if (n_fft < 2 or abs(n_fft * wave.d_omega * step - 2 * np.pi) > 1e-9
            or k.max() >= n_fft // 2):
        return _synthesise_blocks(wave.omega, weights, n, step)
    spectrum = np.zeros((n_fft, weights.shape[1]), dtype=complex)
    spectrum[k] = weights
    # numpy's fft sums x_k exp(-2 pi i k n / N) = exp(-i omega_k t_n): our convention
    period = np.fft.fft(spectrum, axis=0).real
    # the sum is exactly periodic in n_fft samples: longer records wrap around
    return period[np.arange(n) % n_fft]


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


def interpolate_complex(omega_data, values, omega) -> np.ndarray:
    """Linear interpolation of complex values (n_omega_data, ...) to omega; no extrapolation."""
    lo, hi = omega_data[0], omega_data[-1]
    outside = (omega < lo * (1 - 1e-9)) | (omega > hi * (1 + 1e-9))
    if np.any(outside):
        bad = omega[outside]
        raise ValueError(f"wave components at {bad.min():.3g}..{bad.max():.3g} rad/s lie "
                         f"outside the hydro data's band {lo:.3g}..{hi:.3g} rad/s")
    flat = values.reshape(values.shape[0], -1)
    out = np.empty((omega.size, flat.shape[1]), dtype=complex)
    for j in range(flat.shape[1]):
        out[:, j] = (np.interp(omega, omega_data, flat[:, j].real)
                     + 1j * np.interp(omega, omega_data, flat[:, j].imag))
    return out.reshape((omega.size,) + values.shape[1:])


def _synthesise(wave: Wave, weights, t) -> np.ndarray:
    """Re sum_i weights_i exp(-i omega_i t) at times t: FFT on a uniform grid when possible."""
    uniform_t = t.size > 2 and np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=1e-12)
    if uniform_t and wave.omega.size > 16:     # a few components: exact phases, cheap anyway
        return _synthesise_uniform(wave, weights, t.size, t[1] - t[0], t[0])
    return _synthesise_direct(wave.omega, weights, t)


def _synthesise_direct(omega, weights, t) -> np.ndarray:
    out = np.zeros((t.size, weights.shape[1]))
    for start in range(0, t.size, 4096):        # bounded memory for long records
        block = t[start:start + 4096]
        out[start:start + 4096] = (np.exp(-1j * np.multiply.outer(block, omega))
                                   @ weights).real
    return out
