"""Directional spreading: how a short-crested sea's energy at one frequency is shared over
directions, D(theta | omega) with the integral of D over (-pi, pi] equal to 1 (1/rad).

Two forms, both cos-2s: D = C(s) cos^(2s)((theta - mean) / 2), with
C(s) = Gamma(s + 1) / (2 sqrt(pi) Gamma(s + 1/2)) so that D integrates to one:
- "cos2s": one s at every frequency;
- "mitsuyasu": Goda's form of Mitsuyasu et al. (1975), s = s_max (omega / omega_p)^5 below the
  peak frequency omega_p and s_max (omega / omega_p)^-2.5 above it.

The one public spread parameter is sigma (rad), the circular standard deviation
sigma = sqrt(2 (1 - m1)), m1 = |E[exp(i theta)]| (Kuik, van Vledder & Holthuijsen 1988). For
cos-2s, m1 = s / (s + 1), so sigma = sqrt(2 / (s + 1)) and s = 2 / sigma^2 - 1: sigma lies in
(0, sqrt 2) rad (0 to 81 deg; sqrt 2 is the uniform distribution, s = 0). For "mitsuyasu", sigma
is the spread at the peak frequency (s_max = 2 / sigma^2 - 1); away from the peak the sea
spreads wider. Goda's s_max 10 (wind sea), 25 and 75 (swell) are sigma 24, 16 and 9.3 deg.

A sea realised with spreading keeps one direction per frequency (`component_directions`), so
its components stay distinct in frequency and a linear device's mean power over a repeat period
is exactly the sum over components. `sector` (rad) keeps directions within mean +- sector (the
distribution renormalised there; the share of D cut off is `outside`); the default, pi, keeps
the whole circle. Directions follow the NED convention: the direction waves travel to, from +x
towards +y.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import WaveError

KINDS = ("cos2s", "mitsuyasu")
SIGMA_MAX = math.sqrt(2.0)      # rad: s = 0, the uniform distribution
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0   # the Weyl sequence's step (`component_directions`)
GRID = 4001                     # points of the numerical CDF over the sector


@dataclass(frozen=True)
class Spreading:
    """A spreading function: kind ("cos2s" | "mitsuyasu"), mean direction (rad, NED), spread
    sigma (rad, circular standard deviation; at the peak frequency for "mitsuyasu") and the
    half-width `sector` (rad, <= pi) of the directions kept around the mean."""
    kind: str
    mean: float
    spread: float
    sector: float = math.pi

    def __post_init__(self):
        if self.kind not in KINDS:
            raise WaveError(f"spreading: kind must be one of {KINDS}, got {self.kind!r}")
        if not (math.isfinite(self.mean) and 0 < self.spread < SIGMA_MAX):
            raise WaveError(f"spreading: expected a finite mean direction (rad) and a spread "
                            f"sigma in (0, {SIGMA_MAX:.4f}) rad (0 to 81 deg), got mean "
                            f"{self.mean!r}, spread {self.spread!r}")
        if not 0 < self.sector <= math.pi:
            raise WaveError(f"spreading: sector must lie in (0, pi] rad, got {self.sector!r}")

    @property
    def s_peak(self) -> float:
        """The cos-2s exponent s at the peak (all frequencies for "cos2s"): 2 / sigma^2 - 1."""
        return 2.0 / self.spread ** 2 - 1.0

    def s(self, omega=None, omega_p: float | None = None) -> np.ndarray:
        """The exponent s at each omega (rad/s); omega_p (rad/s) the spectrum's peak."""
        omega = np.atleast_1d(np.asarray(1.0 if omega is None else omega, float))
        if self.kind == "cos2s":
            return np.full(omega.shape, self.s_peak)
        if omega_p is None or omega_p <= 0:
            raise WaveError("mitsuyasu spreading: needs the peak frequency omega_p > 0 (rad/s)")
        r = omega / omega_p
        return self.s_peak * np.where(r <= 1.0, r ** 5, r ** -2.5)

    def density(self, theta, omega=None, omega_p: float | None = None) -> np.ndarray:
        """D(theta | omega) (1/rad), shape (n_omega, n_theta), normalised over the circle
        (analytically: C(s)); zero outside the sector, where it is renormalised numerically."""
        s = self.s(omega, omega_p)[:, None]
        x = wrap(np.atleast_1d(np.asarray(theta, float)) - self.mean)[None, :]
        from scipy.special import gammaln    # here: a long-crested sea never needs it
        log_c = gammaln(s + 1) - gammaln(s + 0.5) - math.log(2 * math.sqrt(math.pi))
        d = np.exp(log_c) * np.cos(x / 2) ** (2 * s)
        if self.sector < math.pi:
            d = np.where(np.abs(x) <= self.sector, d, 0.0) / (1.0 - self.outside(omega, omega_p))[:, None]
        return d

    def _cdf(self, s):
        """(x, F): relative directions over the sector and the (unnormalised over the sector)
        CDF of D per s, exact at the points: the share of cos^(2s)(u/2) within |u| <= |x| is
        I(sin^2(x/2); 1/2, s + 1/2) (the regularised incomplete beta function; t = sin^2).
        Computed once per distinct s (cos-2s: one)."""
        from scipy.special import betainc
        x = np.linspace(-self.sector, self.sector, GRID)
        distinct, back = np.unique(s, return_inverse=True)
        F = 0.5 + 0.5 * np.sign(x)[None, :] * betainc(0.5, distinct[:, None] + 0.5,
                                                      np.sin(x / 2)[None, :] ** 2)
        return x, (F - F[:, :1])[back.reshape(-1)]

    def outside(self, omega=None, omega_p: float | None = None) -> np.ndarray:
        """Share of D beyond the sector at each omega (0 for the whole circle)."""
        s = self.s(omega, omega_p)
        if self.sector >= math.pi:
            return np.zeros(s.shape)
        from scipy.special import betainc
        return 1.0 - betainc(0.5, s + 0.5, math.sin(self.sector / 2) ** 2)

    def quantile(self, u, omega=None, omega_p: float | None = None) -> np.ndarray:
        """The direction theta (rad, mean + offset, not wrapped) below which a share u of D
        (over the sector) lies, for each (u_i, omega_i) pair."""
        u = np.atleast_1d(np.asarray(u, float))
        s = self.s(omega, omega_p) * np.ones(u.shape)
        x, F = self._cdf(s)
        return self.mean + np.array([np.interp(ui * Fi[-1], Fi, x) for ui, Fi in zip(u, F)])

    def bin_weights(self, headings, omega=None, omega_p: float | None = None) -> np.ndarray:
        """(n_omega, n_headings): the share of D in each heading's bin (bounded by the
        midpoints between sorted neighbouring headings and by the sector), rows summing to
        one. headings (rad) lie within the sector around the mean and are given sorted by
        their offset from the mean."""
        h = np.asarray(headings, float)
        offset = wrap(h - self.mean)
        if np.any(np.diff(offset) <= 0):
            raise WaveError("bin_weights: headings must increase in their offset from the mean")
        edges = np.concatenate([[-self.sector], 0.5 * (offset[1:] + offset[:-1]), [self.sector]])
        edges = np.clip(edges, -self.sector, self.sector)
        x, F = self._cdf(self.s(omega, omega_p))
        mass = np.array([np.diff(np.interp(edges, x, Fi)) for Fi in F])
        return mass / mass.sum(axis=1, keepdims=True)

    def describe(self) -> dict:
        return {"spreading": self.kind, "mean_direction_rad": float(self.mean),
                "spread_rad": float(self.spread), "sector_rad": float(self.sector)}


def wrap(angle):
    """Angles (rad) wrapped to [-pi, pi)."""
    return (np.asarray(angle, float) + math.pi) % (2 * math.pi) - math.pi


def spread_from_s(s: float) -> float:
    """cos-2s: the circular standard deviation sigma = sqrt(2 / (s + 1)) (rad) of exponent s."""
    return math.sqrt(2.0 / (s + 1.0))


def from_settings(settings: dict) -> Spreading | None:
    """The Spreading a wave's settings record (`Spreading.describe`), or None."""
    if "spreading" not in settings:
        return None
    return Spreading(settings["spreading"], settings["mean_direction_rad"],
                     settings["spread_rad"], settings.get("sector_rad", math.pi))


def component_directions(spreading: Spreading, omega, omega_p: float, seed: int) -> np.ndarray:
    """One direction per component (rad, mean + offset): component i takes the quantile
    u_i = frac(u_0 + i (sqrt 5 - 1) / 2) of D(theta | omega_i), u_0 drawn from `seed` (its own
    stream: the phases are those of the long-crested sea). This Weyl (golden-ratio) sequence
    is equidistributed over every run of consecutive components (discrepancy O(log m / m) over
    m of them), so the realisation's sum over components is a low-discrepancy quadrature of
    the spreading-weighted power: a linear device's mean power over a repeat period lies close
    to the expected one. Measured on the OSWEC (a damper, cos-2s sigma 30 deg, four seeds):
    within 0.4 % for 600 s records at Tp 6-12 s, 1.6 % at Tp 16 s (127 components), 0.2 % at
    1200 s; random permutations in blocks of 16 components scattered by 4-16 %."""
    omega = np.asarray(omega, float)
    u0 = np.random.default_rng([int(seed), 0xD1]).uniform()
    u = (u0 + np.arange(omega.size) * GOLDEN) % 1.0
    return spreading.quantile(u, omega, omega_p)
