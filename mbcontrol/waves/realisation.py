"""Wave realisations: regular waves, irregular seas with seeded random phases (measured records,
files or series: `waves.record`); and the one rule that keeps a spectrum's components inside a
band (`band_limits`).

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

from .. import defaults
from ..errors import WaveError
from .spectra import jonswap_spectrum
from .spreading import Spreading, component_directions
from .synthesis import _synthesise, ramp

DEFAULT_BAND = (0.3, 4.0)       # an irregular sea's components: 0.3 to 4 times the peak frequency


@dataclass(frozen=True)
class Wave:
    """A sum of regular components: frequencies (rad/s), amplitudes (m), phases (rad)."""
    kind: str                            # "regular" | "jonswap" | "pm" | "record" | "components"
    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    direction: float | np.ndarray = 0.0          # rad, NED: travelling towards +x, +y starboard;
                                                 # per component (array) in a spread sea
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

    @property
    def directional(self) -> bool:
        """True when each component has its own direction (a short-crested sea)."""
        return np.ndim(self.direction) > 0

    @property
    def mean_direction(self) -> float:
        """The sea's direction (rad): the float one, or its spreading's mean direction."""
        if not self.directional:
            return float(self.direction)
        return float(self.settings.get("mean_direction_rad",
                                       np.angle(np.sum(self.amplitude ** 2
                                                       * np.exp(1j * self.direction)))))

    def describe(self) -> dict:
        direction = self.mean_direction if self.directional else self.direction   # as given
        return {"type": self.kind, **self.settings, "direction_rad": direction,
                "ramp_s": self.ramp_time, "n_components": int(self.omega.size)}


# A wave steeper than this breaks (Michell 1893: H/L = 0.142 in deep water); no sea holds one,
# and linear theory, which every model here builds on, holds only far below it.
# BREAKING_STEEPNESS: the default "waves.breaking_steepness" (mbcontrol.defaults)
MAX_PERIOD_S = 1000.0       # ocean swell stays below 30 s; past 1000 s it is a tide, not a wave
# A sea's components: 600 s of a Tp 8 s sea is 276, three hours 5,000; 1e5 is 60 hours, while
# "--duration 1e308" would ask numpy for more than memory holds
MAX_COMPONENTS = 100_000


def check_steepness(height: float, period: float, what: str) -> None:
    """Refuse a wave (or a sea's Hs over its peak wavelength) steeper than BREAKING_STEEPNESS,
    measured against the deep-water wavelength g T^2 / (2 pi): in finite depth the wave is
    shorter and steeper still, so this refuses only what cannot exist anywhere."""
    if not (math.isfinite(height) and 0 < period <= MAX_PERIOD_S):
        raise WaveError(f"{what}: expected a finite height and a period of at most "
                        f"{MAX_PERIOD_S:g} s, got {height} m, {period} s")
    wavelength = 9.80665 * period ** 2 / (2 * math.pi)
    if height > defaults.get("waves.breaking_steepness") * wavelength:
        raise WaveError(f"{what}: {height:g} m over a {period:g} s period is steeper than a "
                        f"wave can be (it breaks at H/L = 1/7; the deep-water wavelength is "
                        f"{wavelength:.4g} m, so at most {defaults.get('waves.breaking_steepness') * wavelength:.4g} m); "
                        f"expected a smaller height or a longer period")


def regular(height: float, period: float, *, phase: float = 0.0, direction: float = 0.0,
            ramp_time: float | None = None) -> Wave:
    """A regular wave of height H (m, crest to trough) and period T (s); ramp 2 T by default."""
    if not height >= 0 or not period > 0:
        raise WaveError(f"regular wave: expected height >= 0 and period > 0, got "
                        f"H={height}, T={period}")
    check_steepness(height, period, "regular wave: --height against --period")
    ramp_time = 2 * period if ramp_time is None else ramp_time
    return Wave("regular", np.array([2 * np.pi / period]), np.array([height / 2]),
                np.array([phase]), direction, ramp_time,
                {"height": height, "period": period})


def band_limits(tp: float, data_band=None, band=DEFAULT_BAND, what: str = "a sea"):
    """The band (lo, hi) in multiples of the peak frequency 2 pi / tp that a spectrum's
    components span: `band`, cut to the hydro data's band data_band = (lo, hi) rad/s when
    given. ValueError when nothing is left (the sea lies outside the data).

    This is the one place a spectrum is clipped; `irregular` (and so `from_args`, the CLI and
    sweeps) calls it."""
    if data_band is None:
        return (float(band[0]), float(band[1]))
    wp = 2 * math.pi / tp
    lo, hi = max(band[0], data_band[0] / wp), min(band[1], data_band[1] / wp)
    if not lo < hi:
        raise WaveError(f"{what} with Tp {tp:g} s lies outside the hydro data's band "
                        f"{data_band[0]:.3g}..{data_band[1]:.3g} rad/s")
    return (float(lo), float(hi))


def variance_outside(hs: float, tp: float, gamma: float, band, kept) -> float:
    """Share of a JONSWAP spectrum's variance over `band` (multiples of the peak frequency)
    that falls outside `kept` (4001-point trapezoids)."""
    wp = 2 * np.pi / tp
    w = np.linspace(band[0] * wp, band[1] * wp, 4001)
    S = jonswap_spectrum(w, hs, tp, gamma)
    inside = (w >= kept[0] * wp) & (w <= kept[1] * wp)
    return float(1 - np.trapezoid(S * inside, w) / np.trapezoid(S, w))


def irregular(hs: float, tp: float, *, gamma: float = 3.3, seed: int = 0,
              duration: float = 600.0, band: tuple[float, float] = DEFAULT_BAND,
              direction: float = 0.0, ramp_time: float | None = None,
              kind: str = "jonswap", data_band=None,
              amplitudes: str = "deterministic", spreading: Spreading | None = None) -> Wave:
    """An irregular sea with random phases (seeded) on a uniform grid covering `duration`.

    Components span band[0]..band[1] times the peak frequency, cut to data_band (rad/s, the
    hydro data's) when given (`band_limits`; settings["spectrum_outside_data"] then records
    the share of the variance left out). amplitudes "deterministic" (the default, the
    expected power): a = sqrt(2 S dw), scaled so that 4 sqrt(m0) equals hs exactly on the kept
    grid, so over a repeat period a linear model's mean power does not depend on the seed;
    "random" (a record's statistics): a = sqrt(2 S dw) R with R Rayleigh, E[R^2] = 1, drawn
    after the phases from the same seed (the phases are those of the deterministic sea), no
    rescaling, so each record's Hs and power scatter as a measured record's do (Tucker,
    Challenor & Carter 1984); settings["amplitudes"] says so. Ramp: 2 Tp by default.

    spreading (`waves.Spreading`): a short-crested sea, each component travelling in its own
    direction (`spreading.component_directions`, from the same seed, its own stream: phases and
    amplitudes are those of the long-crested sea) around spreading.mean, which replaces
    `direction`; settings record the spreading (`Spreading.describe`) and, with a sector
    narrower than the circle, "spreading_outside" (the largest share of D cut off).
    """
    if not (hs > 0 and tp > 0 and gamma >= 1) or not math.isfinite(gamma):
        raise WaveError(f"{kind}: expected hs > 0, tp > 0, gamma >= 1; got {hs}, {tp}, {gamma}")
    check_steepness(hs, tp, f"{kind} sea: --hs against --tp")
    gamma_used = gamma if kind == "jonswap" else 1.0
    kept = band_limits(tp, data_band, band, what=f"a {kind} sea")
    wp = 2 * np.pi / tp
    repeat = max(duration, 20 * tp)
    d_omega = 2 * np.pi / repeat
    first, last = math.ceil(kept[0] * wp / d_omega), math.floor(kept[1] * wp / d_omega)
    if not math.isfinite(repeat) or last - first + 1 > MAX_COMPONENTS:
        raise WaveError(f"{kind} sea: a repeat period of {repeat:g} s holds "
                        f"{(kept[1] - kept[0]) * wp / d_omega:.3g} components, more than "
                        f"{MAX_COMPONENTS}; expected a shorter --duration (or --repeat)")
    k = np.arange(first, last + 1)
    omega = k * d_omega
    density = jonswap_spectrum(omega, hs, tp, gamma_used)
    if amplitudes not in ("deterministic", "random"):
        raise WaveError(f"{kind}: amplitudes must be 'deterministic' or 'random', got "
                        f"{amplitudes!r}")
    amplitude = np.sqrt(2 * density * d_omega)
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * np.pi, omega.size)
    if amplitudes == "random":                 # Rayleigh: a^2 exponential about 2 S dw
        amplitude = amplitude * np.sqrt(rng.exponential(1.0, omega.size))
    else:
        amplitude *= hs / (4 * np.sqrt(0.5 * np.sum(amplitude**2)))
    ramp_time = 2 * tp if ramp_time is None else ramp_time
    settings = {"hs": hs, "tp": tp, "gamma": gamma_used, "seed": seed}
    if amplitudes == "random":
        settings["amplitudes"] = "random"
    if data_band is not None:
        settings["spectrum_outside_data"] = variance_outside(hs, tp, gamma_used, band, kept)
    if spreading is not None:
        direction = component_directions(spreading, omega, wp, seed)
        settings.update(spreading.describe())
        if spreading.sector < math.pi:
            settings["spreading_outside"] = float(np.max(spreading.outside(omega, wp)))
    return Wave(kind, omega, amplitude, phase, direction, ramp_time, settings, d_omega)


def from_args(kind: str, *, height=None, period=None, hs=None, tp=None, gamma=3.3, seed=0,
              duration=600.0, data_band=None) -> Wave:
    """The wave a CLI or config describes: 'regular', 'jonswap' or 'pm'.

    data_band: (lo, hi) rad/s of the model's hydro data; an irregular sea's components are kept
    inside it (Hs stays exact on the kept components; settings["spectrum_outside_data"] records
    the fraction of the spectrum's variance that fell outside)."""
    if kind == "regular":
        if height is None or period is None:
            raise WaveError("a regular wave needs --height and --period")
        return regular(height, period)
    if kind in ("jonswap", "pm"):
        if hs is None or tp is None:
            raise WaveError(f"a {kind} sea needs --hs and --tp")
        return irregular(hs, tp, gamma=gamma, seed=seed, duration=duration, kind=kind,
                         data_band=data_band)
    raise WaveError(f"unknown wave type {kind!r}; expected regular, jonswap or pm")


def repeat_period(wave) -> tuple[float, np.ndarray]:
    """(T, k): the wave's repeat period (s) and its components' harmonic numbers on 2 pi / T.

    Regular waves repeat over their period; irregular seas made on a uniform grid (Wave.d_omega)
    over 2 pi / d_omega. Raises ValueError for waves that are not periodic on such a grid.
    """
    omega = np.asarray(wave.omega, float)
    if omega.size == 1:
        return 2 * np.pi / float(omega[0]), np.array([1])
    if wave.d_omega is None:
        raise WaveError("a repeat period: an irregular wave needs a uniform frequency "
                        "grid (Wave.d_omega) to be periodic")
    k = omega / wave.d_omega
    if np.max(np.abs(k - np.rint(k))) > 1e-6 or np.any(np.rint(k) < 1):
        raise WaveError("a repeat period: the wave's frequencies are not positive "
                        "multiples of its d_omega")
    return 2 * np.pi / wave.d_omega, np.rint(k).astype(int)
