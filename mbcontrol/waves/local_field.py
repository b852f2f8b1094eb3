"""The undisturbed incident wave field about a body, as Chebyshev series cheap enough to evaluate
at every panel of a moving body at every integrator stage (nonlinear Froude-Krylov forces).

Method. A long-crested sea of direction beta depends on position only through
xi = (x - x0) cos beta + (y - y0) sin beta (m) and, below the surface, the stretched depth d
(m). In a box xi in [-L, L], d in [0, D] each component's elevation and dynamic pressure head
(p_dyn / (rho g), m) are entire functions, expanded in Chebyshev polynomials of
xh = xi / L and dh = 2 d / D - 1 whose coefficients are known in closed form:
exp(i k L xh) = sum_m eps_m i^m J_m(k L) T_m(xh) (Jacobi-Anger; eps_0 = 1, eps_m = 2) and
exp(-k d) = sum_n eps_n (-1)^n I_n(k D / 2) exp(-k D / 2) T_n(dh); finite depth
Z(d) = cosh(k (H - d)) / cosh(k H) = (exp(-k d) + exp(-2 k H) exp(k d)) / (1 + exp(-2 k H)) is two
such exponentials (exp(k d): the same I_n without the sign). Per unit amplitude the series
coefficients are then linear in the component, so the time-dependent coefficients sum over the
components exactly as excitation does: extra rows of the plant's disturbance w, made by one FFT
(`field_rows_offsets`, `mbcontrol.waves.excitation.coefficient_offsets`). Inside the plant the
series are summed by the three-term recurrence, vectorised over points (`LocalField.pressure`).

Pressure. Wheeler stretching: a point at depth z (m, NED, z down) sees the linear dynamic
pressure at d = H (z + eta) / (H + eta) (deep water d = z + eta); the total incident pressure is
p = rho g max(z + p_dyn(d) / (rho g), 0) (Pa) with d clipped to >= 0, so it is 0 above the
incident surface (z < -eta, where the clipped d = 0 gives p_dyn = rho g eta) and
rho g z + p_dyn below it (positive there while |d p_dyn / d d| < rho g, i.e. for linear waves
of moderate steepness: the max only guards the surface).

Cost per point (flops; M = n_xi, N = n_depth, deep water): xi and its clamp 8; T_m(xh) 2 M - 3;
eta 2 M - 1; stretching and clamp 5 (finite depth 8); T_n(dh) 2 N - 3; p_dyn 2 M N + N - 1;
p 3: about 2 M N + 4 M + 3 N + 9, 161 at M = 8, N = 6 (CasADi's SX: 150 instructions a point).
Measured: a Function rows x 1000 points -> p, compiled by `mbcontrol.sim.compiled
.compile_function` (-O3), 10^4 calls, one core of the development machine:

    M x N    rows   expanded SX (C, gcc)      a never-inlined call per point
    4 x 4      20   32 us (32 ns/pt), 14 s    17 us (17 ns/pt), 3 s
    8 x 6      56   62 us (62 ns/pt), 17 s    24 us (24 ns/pt), 3 s
    16 x 9    160  127 us (127 ns/pt), 51 s   49 us (49 ns/pt), 3 s
    8 x 6, H = 30 m: expanded 67 ns/pt.

Expanding every point's series into one SX graph makes megabytes of straight-line C (2.7 MB at
8 x 6) that compiles slowly and runs slower (likely instruction-cache misses); the plant sums
the points in blocks inside one call instead (mbcontrol.hydro.mesh.surface_sums: 25 ns a point
at 8 x 6). For comparison, the direct sum of a 278-component sea
(mbcontrol.waves.direct_field) costs a cosine per component per point.

Accuracy. `truncation_error` is a rigorous bound (|T_m| <= 1); `choose_field` weights it by
amplitude, the worst case over phases. Measured against the direct sums (box +-10 m by 12 m,
2000 points x 6 times): a regular wave reaches 85% of its bound (one phase is the worst one);
a JONSWAP sea (Hs 2.5 m, Tp 9 s, 124 components) stays 13x below it (14 x 8 terms, 126 rows),
Hs 2 m, Tp 6 s (371 components, up to 4 wp: k L = 18) 5x below it, at 24 x 13 (336 rows).

Long-crested seas only: a spread sea's components each have their own direction and the field
is no longer a function of one horizontal coordinate (`choose_field` refuses one).
Tests: tests/waves/test_local_field.py (against the direct sums `direct_elevation`,
`direct_pressure`; closed-form coefficients against numerical interpolation; CasADi = numpy).
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import WaveError
from .dispersion import wavenumber
from .excitation import coefficient_offsets, coefficient_series

WARN_FACTOR = 10.0      # choose_field: a bound within this many tol is a warning, past it refused


def _wavenumbers(omega, water_depth: float, g: float) -> np.ndarray:
    return np.array([wavenumber(float(w), water_depth, g) for w in np.atleast_1d(omega)])


def _count(z_max: float, order: int) -> int:
    """Terms enough for a tail sum: past the argument (+ 10 z^(1/3) + 40) J_m(z) and
    I_n(z) e^-z are below 1e-23 (z <= 1000), far below any tolerance asked."""
    return order + int(math.ceil(z_max + 10 * z_max ** (1 / 3) + 40))


def _xi_coefficients(kl, count: int) -> np.ndarray:
    """(n, count) complex: Chebyshev coefficients in xh of exp(i k L xh), eps_m i^m J_m(k L)."""
    from scipy.special import jv       # here: only a nonlinear Froude-Krylov body needs it
    m = np.arange(count)
    eps = np.where(m == 0, 1.0, 2.0)
    i_m = np.array([1, 1j, -1, -1j])[m % 4]          # i^m exactly (1j ** m rounds)
    return eps * i_m * jv(m[None, :], np.asarray(kl, float)[:, None])


def _depth_coefficients(k, depth_range: float, water_depth: float, count: int) -> np.ndarray:
    """(n, count) real: Chebyshev coefficients in dh of Z(d), d = D (dh + 1) / 2. With
    s = k D / 2, exp(-k d) has eps_n (-1)^n I_n(s) e^-s and exp(k d) has e^(2 s) eps_n I_n(s)
    e^-s; scipy's ive (I_n e^-s) keeps both finite at any s (D <= H, so exp(-k (2 H - D))
    <= 1)."""
    from scipy.special import ive
    n = np.arange(count)
    eps = np.where(n == 0, 1.0, 2.0)
    k = np.asarray(k, float)[:, None]
    scaled = eps * ive(n[None, :], k * depth_range / 2)
    down = np.where(n % 2 == 0, 1.0, -1.0) * scaled
    if math.isinf(water_depth):
        return down
    return (down + np.exp(-k * (2 * water_depth - depth_range)) * scaled) \
        / (1 + np.exp(-2 * k * water_depth))


def depth_factor(k, d, water_depth: float):
    """Z = cosh(k (H - d)) / cosh(k H) (deep water exp(-k d)), without overflow, broadcasting
    k (rad/m) against d (m, 0 <= d <= H)."""
    if math.isinf(water_depth):
        return np.exp(-k * d)
    return (np.exp(-k * d) + np.exp(-k * (2 * water_depth - d))) \
        / (1 + np.exp(-2 * k * water_depth))


def _tails(k, field: "LocalField", order: int):
    """Per component (n, order + 1) partial sums A_M = sum_{m<M} |a_m| and tails sum_{m>=M}
    |a_m| for M = 0..order, and the same for the depth coefficients |b_n|."""
    out, k_max = [], float(np.max(k, initial=0.0))
    for coeffs in (_xi_coefficients(k * field.half_width, _count(k_max * field.half_width, order)),
                   _depth_coefficients(k, field.depth_range, field.water_depth,
                                       _count(k_max * field.depth_range / 2, order))):
        size = np.abs(coeffs)
        head = np.concatenate([np.zeros((size.shape[0], 1)), np.cumsum(size, axis=1)], axis=1)
        tail = np.cumsum(size[:, ::-1], axis=1)[:, ::-1]     # summed from the small end: exact
        tail = np.concatenate([tail, np.zeros((size.shape[0], 1))], axis=1)
        out += [head[:, :order + 1], tail[:, :order + 1]]
    return out


def _ops(*values):
    """(fmax, fmin) for CasADi symbols or numbers, else numpy's: one code path for both."""
    if any(type(v).__module__.startswith("casadi") for v in values):
        import casadi as ca
        return ca.fmax, ca.fmin
    return np.fmax, np.fmin


def _chebyshev(u, count: int) -> list:
    """T_0(u) .. T_{count-1}(u) by T_m = 2 u T_{m-1} - T_{m-2} (2 flops a term)."""
    polys = [1.0, u][:count]
    two_u = 2 * u
    while len(polys) < count:
        polys.append(two_u * polys[-1] - polys[-2])
    return polys


@dataclass(frozen=True)
class LocalField:
    """Long-crested incident field about a reference point as Chebyshev series.

    x0, y0 (m): the reference point (a body's CoG at rest, n-frame NED); direction (rad): the
    sea's beta (towards +x at 0, +y at pi/2); half_width L (m): the series hold for
    xi = (x - x0) cos beta + (y - y0) sin beta in [-L, L]; depth_range D (m): for stretched
    depths d in [0, D] (D <= water_depth); n_xi M, n_depth N: terms 0..M-1 in xh = xi / L and
    0..N-1 in dh = 2 d / D - 1; water_depth H (m, inf: deep); g (m/s^2) for the dispersion.
    Rows (`row_coefficients`): M coefficients of eta (m), then M N of p_dyn / (rho g) (m),
    row M + m N + n multiplying T_m(xh) T_n(dh). See the module docstring for the method.
    """
    x0: float
    y0: float
    direction: float
    half_width: float
    depth_range: float
    n_xi: int
    n_depth: int
    water_depth: float = math.inf
    g: float = 9.81

    def __post_init__(self):
        numbers = (self.x0, self.y0, self.direction, self.half_width, self.depth_range, self.g)
        if not all(math.isfinite(v) for v in numbers) or self.half_width <= 0 \
                or self.depth_range <= 0 or self.g <= 0:
            raise WaveError(f"local field: expected a finite reference point and direction, "
                            f"half_width > 0 m, depth_range > 0 m and g > 0; got {numbers}")
        if not self.water_depth >= self.depth_range:
            raise WaveError(f"local field: depth_range {self.depth_range:g} m reaches past the "
                            f"water depth {self.water_depth:g} m")
        if int(self.n_xi) != self.n_xi or int(self.n_depth) != self.n_depth \
                or self.n_xi < 1 or self.n_depth < 1:
            raise WaveError(f"local field: orders must be whole numbers >= 1, got "
                            f"n_xi={self.n_xi}, n_depth={self.n_depth}")

    @property
    def n_rows(self) -> int:
        """Rows of the disturbance the series take: M + M N."""
        return self.n_xi * (1 + self.n_depth)

    def row_coefficients(self, omega) -> np.ndarray:
        """(n_omega, n_rows) complex per unit amplitude (exp(-i omega t) convention, as the
        hydro data's): the first M rows are the Chebyshev coefficients in xh of eta (m/m), the
        next M N (row M + m N + n) those of p_dyn / (rho g) (m/m) in (xh, dh). omega in rad/s.
        The reference point's phase exp(i k (x0 cos beta + y0 sin beta)) is included."""
        k = _wavenumbers(omega, self.water_depth, self.g)
        offset = self.x0 * math.cos(self.direction) + self.y0 * math.sin(self.direction)
        a = _xi_coefficients(k * self.half_width, self.n_xi) * np.exp(1j * k * offset)[:, None]
        b = _depth_coefficients(k, self.depth_range, self.water_depth, self.n_depth)
        return np.concatenate([a, (a[:, :, None] * b[:, None, :]).reshape(k.size, -1)], axis=1)

    def truncation_error(self, omega) -> np.ndarray:
        """(n_omega,) per unit amplitude (m of head): a bound over the box of the series' error
        in eta and in p / (rho g), the tail of the absolute coefficients (|T_m| <= 1):
        sum_{(m, n) not kept} |a_m| |b_n| = tail_a(M) B + A_M tail_b(N), which bounds eta's
        tail_a(M) too (B = sum |b_n| >= Z(0) = 1). Left out: the error of eta moves the
        stretched depth, a second-order k eta change of p."""
        k = _wavenumbers(omega, self.water_depth, self.g)
        a_head, a_tail, _, b_tail = _tails(k, self, max(self.n_xi, self.n_depth))
        m, n = self.n_xi, self.n_depth
        return a_tail[:, m] * b_tail[:, 0] + a_head[:, m] * b_tail[:, n]

    def _xi_hat(self, x, y):
        fmax, fmin = _ops(x, y)
        xi = (x - self.x0) * math.cos(self.direction) + (y - self.y0) * math.sin(self.direction)
        return fmin(fmax(xi * (1 / self.half_width), -1.0), 1.0)

    def elevation(self, rows, x, y):
        """eta (m, up) at points (x, y) (m, n-frame; numpy arrays or CasADi rows, elementwise)
        from the n_rows values at one time (`field_rows_series`; CasADi column or numpy 1-D).
        Points past the box take its edge's value (xh clamped to [-1, 1])."""
        rows = rows if type(rows).__module__.startswith("casadi") else np.asarray(rows, float)
        polys = _chebyshev(self._xi_hat(x, y), self.n_xi)
        return sum(rows[m] * polys[m] for m in range(self.n_xi))

    def pressure(self, rows, x, y, z, rho: float, g: float):
        """Total incident pressure (Pa) at points (x, y, z) (m, NED, z down): rho g z + p_dyn at
        the stretched depth, 0 above the surface; rows as `elevation`, rho (kg/m^3), g (m/s^2).

        Elementwise over numpy arrays or CasADi SX rows, without branching on values: xh and dh
        are clamped to [-1, 1] (a point outside the box takes the boundary's value; the
        caller's validity check reports it, `outside`). Cost: the module docstring."""
        return self.pressure_and_usage(rows, x, y, z, rho, g)[0]

    def pressure_and_usage(self, rows, x, y, z, rho: float, g: float):
        """(`pressure`, `usage`) at the points, sharing the elevation and stretched depth:
        what a panel sum needs to report its field's range at little extra cost."""
        fmax, fmin = _ops(rows, x, y, z)
        rows = rows if type(rows).__module__.startswith("casadi") else np.asarray(rows, float)
        m_count, n_count = self.n_xi, self.n_depth
        xi = (x - self.x0) * math.cos(self.direction) + (y - self.y0) * math.sin(self.direction)
        tx = _chebyshev(fmin(fmax(xi * (1 / self.half_width), -1.0), 1.0), m_count)
        eta = sum(rows[m] * tx[m] for m in range(m_count))
        depth = z + eta
        if not math.isinf(self.water_depth):          # Wheeler: d = H (z + eta) / (H + eta)
            depth = depth * (self.water_depth / (self.water_depth + eta))
        td = _chebyshev(fmin(fmax(depth * (2 / self.depth_range) - 1.0, -1.0), 1.0), n_count)
        head = 0.0
        for n in range(n_count):
            inner = sum(rows[m_count + m * n_count + n] * tx[m] for m in range(m_count))
            head = head + inner * td[n]
        usage = fmax(abs(xi) * (1 / self.half_width), depth * (1 / self.depth_range))
        return (rho * g) * fmax(z + head, 0.0), usage

    def usage(self, rows, x, y, z):
        """How much of the box each point uses (dimensionless; numpy arrays or CasADi rows,
        elementwise): max(|xi| / L, d / D), d the stretched depth (negative above the surface).
        Above 1 the point lies past the box, where `pressure` used the boundary's value."""
        fmax, _ = _ops(rows, x, y, z)
        rows = rows if type(rows).__module__.startswith("casadi") else np.asarray(rows, float)
        xi = (x - self.x0) * math.cos(self.direction) + (y - self.y0) * math.sin(self.direction)
        eta = self.elevation(rows, x, y)
        depth = z + eta if math.isinf(self.water_depth) \
            else self.water_depth * (z + eta) / (self.water_depth + eta)
        return fmax(abs(xi) * (1 / self.half_width), depth * (1 / self.depth_range))

    def outside(self, rows, x, y, z) -> np.ndarray:
        """numpy: True where a point lies past the box (`usage` above 1)."""
        x, y, z = (np.asarray(v, float) for v in (x, y, z))
        return np.asarray(self.usage(rows, x, y, z)) > 1.0


def choose_field(wave, x0: float, y0: float, half_width: float, depth_range: float, *,
                 water_depth: float = math.inf, g: float = 9.81, tol: float = 1e-3,
                 max_order: int = 24) -> LocalField:
    """The field of fewest rows M (1 + N), M, N <= max_order, whose truncation bound weighted
    by the components' amplitudes, sum_j a_j err_j (m of head: `LocalField.truncation_error`,
    the worst case over phases), is at most tol (m); ties go to the smaller M.

    wave: a long-crested `Wave` (its direction is the field's); x0, y0 (m) the reference point;
    half_width, depth_range (m) the box (see `LocalField`); water_depth (m), g (m/s^2).
    When no orders up to max_order meet tol, the max_order field is returned with a
    RuntimeWarning if its bound is within WARN_FACTOR tol, else WaveError: both name the
    numbers (the fixes: a smaller box, a larger max_order or tol, or the sea's band cut)."""
    if wave.directional:
        raise WaveError("a local field is long-crested only for now: this wave spreads over "
                        "directions (a short-crested sea); expected one direction")
    if not (tol > 0 and int(max_order) == max_order and max_order >= 1):
        raise WaveError(f"choose_field: expected tol > 0 and max_order >= 1, got tol={tol}, "
                        f"max_order={max_order}")
    field = LocalField(x0, y0, float(wave.direction), half_width, depth_range, 1, 1,
                       water_depth, g)
    k = _wavenumbers(wave.omega, water_depth, g)
    bound = _bounds(field, k, np.asarray(wave.amplitude, float), max_order)
    orders = _fewest_rows(bound, tol)
    if orders is not None:
        return dataclasses.replace(field, n_xi=orders[0], n_depth=orders[1])
    best = float(bound[-1, -1])
    what = (f"a local field over +-{half_width:g} m by {depth_range:g} m deep reaches a "
            f"truncation bound of {best:.3g} m at orders {max_order} x {max_order}, above "
            f"tol {tol:.3g} m (the sea's shortest component: k = {np.max(k):.3g} rad/m, "
            f"k L = {np.max(k) * half_width:.3g})")
    if best > WARN_FACTOR * tol:
        raise WaveError(what + "; expected a smaller box, a larger max_order or tol, or a "
                        "narrower band of components")
    warnings.warn(what + "; using those orders", RuntimeWarning, stacklevel=2)
    return LocalField(x0, y0, float(wave.direction), half_width, depth_range, max_order,
                      max_order, water_depth, g)


def band_field(x0: float, y0: float, direction: float, half_width: float, depth_range: float,
               omega, *, water_depth: float = math.inf, g: float = 9.81, tol: float = 1e-3,
               max_order: int = 24) -> LocalField:
    """The field of fewest rows whose truncation bound per unit amplitude is at most tol (m)
    at every omega (rad/s): any sea in that band, before it is known. max_order x max_order
    when none is (the caller reports it). Box and units as `choose_field`."""
    field = LocalField(x0, y0, direction, half_width, depth_range, 1, 1, water_depth, g)
    bound = _bounds(field, _wavenumbers(omega, water_depth, g), None, max_order)
    m, n = _fewest_rows(bound, tol) or (max_order, max_order)
    return dataclasses.replace(field, n_xi=m, n_depth=n)


def _bounds(field: LocalField, k, weights, max_order: int) -> np.ndarray:
    """bound[M - 1, N - 1], M, N = 1..max_order: the truncation bound tail_a(M) B +
    A_M tail_b(N) per component, summed with ``weights`` (amplitudes), or its max (None)."""
    a_head, a_tail, _, b_tail = _tails(k, field, max_order)
    err = a_tail[:, 1:, None] * b_tail[:, :1, None] + a_head[:, 1:, None] * b_tail[:, None, 1:]
    return err.max(axis=0) if weights is None else np.tensordot(weights, err, 1)


def _fewest_rows(bound: np.ndarray, tol: float):
    """(M, N) of the fewest rows M (1 + N) with bound <= tol (ties: the smaller M), or None."""
    orders = np.arange(1, bound.shape[0] + 1)
    rows = orders[:, None] * (1 + orders[None, :])
    ok = bound <= tol
    if not ok.any():
        return None
    cost = np.where(ok, rows * (bound.shape[0] + 1) + orders[:, None], np.iinfo(int).max)
    m, n = np.unravel_index(np.argmin(cost), cost.shape)
    return int(m + 1), int(n + 1)


def field_rows_series(field: LocalField, wave, t) -> np.ndarray:
    """The field's rows (len(t), n_rows) at times t (s), ramp included: the series'
    coefficients for `LocalField.elevation` and `pressure` at each time."""
    _check_direction(field, wave)
    return coefficient_series(wave, field.row_coefficients(wave.omega), t)


def field_rows_offsets(field: LocalField, wave, n: int, dt: float, offsets) -> np.ndarray:
    """The rows (n, len(offsets), n_rows) at the integrators' stage times t = (i + c) dt (s)
    for each offset c, by `coefficient_offsets` (one FFT, as the excitation's rows of w)."""
    _check_direction(field, wave)
    return coefficient_offsets(wave, field.row_coefficients(wave.omega), n, dt, offsets)


def _check_direction(field: LocalField, wave) -> None:
    if wave.directional or abs(math.remainder(float(wave.direction) - field.direction,
                                              2 * math.pi)) > 1e-12:
        raise WaveError(f"local field: made for direction {field.direction:g} rad, given a "
                        f"wave of direction {wave.mean_direction:g} rad"
                        + (" spread over directions" if wave.directional else ""))
