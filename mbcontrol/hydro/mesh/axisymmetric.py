"""Nonlinear hydrostatics and Froude-Krylov (FK) forces on a body of revolution with a vertical
axis in a long-crested sea, cheap enough for a compiled plant (the "analytic path").

Conventions: n-frame NED (z down, origin on the undisturbed surface), SI. Component j:
eta = Re A_j exp(i k_j xi) (m, up), A_j = a_j exp(-i(w_j t + phi_j)), xi = x cos b + y sin b;
incident pressure (Wheeler) p = rho g (z + Re sum_j A_j exp(i k_j xi) Z_j(d)), d = z + eta,
Z = exp(-k d) (finite depth H: cosh k(H - d) / cosh kH), p = 0 above the surface.

Model (flat local waterline). The body: a profile r(zeta) (zeta down from the reference point
c, top zeta_t to keel zeta_k) revolved about the vertical through c. eta_c: eta at the axis,
s = z_c + eta_c; the wet part zeta > -s is closed by the lid z = -eta_c (radius r_wl(s)) and the
pressure takes d = z + eta_c (finite depth: a shift, without Wheeler's factor H / (H + eta)),
which on the lid is rho g (eta(x) - eta_c), O(k r a). With W(k, r) = int_disc exp(i k rho cos th)
dA = 2 pi r J1(k r) / k (-> pi r^2 as k -> 0), G_j(s) = int_wet Z_j(zeta + s) W(k_j, r(zeta))
dzeta (m^3; V(s) as k -> 0 in deep water) and Phi(xi, s) = Re sum_j A_j exp(i k_j xi) G_j(s),
the hull force -int_V grad p dV + int_lid p n dS is, as G' = W(r_wl) Z(0) + int_wet Z' W dzeta,
    F_z  = -rho g V(s) + F_dyn,   F_dyn = rho g (pi r_wl(s)^2 eta_c - dPhi/ds)   (+ down)
    F_xi = -rho g dPhi/dxi + eta'_c F_dyn      (F_x = cos b F_xi, F_y = sin b F_xi)
Signs: the volume term -int dp_dyn/dz dV = rho g Re sum A exp(i k xi) k G (deep water) is down
under a crest, where the dynamic pressure decays with depth; the lid term removes the pressure
a lid would feel. To first order F_z - F_z(calm) = -rho g Re sum A exp(i k xi) G'(s_0), the
linear FK force of the mean wetted hull (a cylinder: its bottom's, -rho g a exp(-kT) W(k, R)).
The last term (eta'_c = d eta / d xi at the axis) stretches with the local plane
eta_c + eta'_c (xi - xi_c), to first order and up to O((k r)^2): on a sphere R 5 m in
H/(g T^2) = 0.01, T = 8 s it cuts the surge error from 14 % to 1 % of the surge amplitude; the
heave error, from the flat wetting, stays 1-2 % (tests/features/hydro/test_axisymmetric_fk.py).
Moments: zero about c, exact for a sphere; other bodies' buoyancy acts on the axis, but their
dynamic moment is NOT modelled: use this path for spheres or bodies without rotational freedom.

Rows (`row_coefficients`, per unit amplitude): n_xi Chebyshev coefficients of eta in
xh = xi_c / L (xi_c = xi(c) - xi(c_rest), L = half_width): eps_m i^m J_m(k L) exp(i k xi(c_rest));
then for each piece [a, b] of the s range n_xi x n_p rows: those times the Chebyshev
coefficients in sh = (2 s - a - b) / (b - a) of G_j(s) - G_j(a), interpolated at n_p
Chebyshev-Lobatto points (G_j by Gauss-Legendre quadrature). Pieces: dry (s = -zeta_k) to fully
wet (-zeta_t), cut at profile corners (turns over 15 deg, flat steps), then submerged to
-zeta_t + margin; inside each G_j is analytic (a sphere's W is a function of r^2 = R^2 - zeta^2),
so the series converge geometrically. Phi sums the pieces at s clipped to each (telescoping);
dPhi/ds weights each piece's derivative by its indicator, a ramp of width 1e-3 x height at each
cut (where a flat keel or top wets at once the model's force jumps: smoothed over that width).
Past s_max or |xi_c| > L the series take the boundary's value (`outside`). V(s), r_wl(s): exact
(sphere cap; frusta: each segment's wet length clipped with fmin/fmax, volume cubic in it).
Orders (`choose_orders`): each series' truncation error below tol / 2 of pi r_max^2 (the FK
heave rho g a pi r_max^2 per unit amplitude a) for every k <= k_max, checked against quadrature.
Cost (sphere R 5 m, L 3 m, tol 1e-3, k_max at 2.5 x the peak of Tp 8 s: 7 x (1 + 9 + 6) = 112
rows): the compiled wrench takes 80-110 ns (0.02-0.03 s for the 240,000 RK4 stages of 600 s
at 0.01 s); the rows at those stages (`waves.coefficient_offsets`) take about 0.4 s and 160 MB.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass, field

import casadi as ca
import numpy as np
from numpy.polynomial import chebyshev as C
from scipy.special import j1, jv

from mbcontrol.errors import HydroError
from mbcontrol.scene import profile_problem
from mbcontrol.waves import wavenumber

CORNER_DEG = 15.0     # a profile vertex turning by more than this cuts the s range
MAX_ORDER = 40        # per series; past it the tolerance is reported as not reached
_GL = np.polynomial.legendre.leggauss(64)


def _casadi(*values) -> bool:
    return any(type(v).__module__.startswith("casadi") for v in values)


def _clip(u, lo, hi, symbolic):
    return ca.fmin(ca.fmax(u, lo), hi) if symbolic else np.fmin(np.fmax(u, lo), hi)


def _chebyshev(u, n: int):
    """T_0..T_{n-1}(u) and their derivatives, by the three-term recurrence."""
    t, dt = [1.0, u][:n], [0.0, 1.0][:n]
    while len(t) < n:
        dt.append(2 * t[-1] + 2 * u * dt[-1] - dt[-2])
        t.append(2 * u * t[-1] - t[-2])
    return t, dt


def _disc(k, r2):
    """W(k, r) = pi r^2 2 J1(k r)/(k r) (m^2), from r^2."""
    x = k * np.sqrt(r2)
    safe = np.where(x > 1e-6, x, 1.0)
    return math.pi * r2 * np.where(x > 1e-6, 2 * j1(safe) / safe, 1 - x * x / 8)


def _kernels(k, d, depth: float):
    """Z(d) and dZ/dd of the dynamic pressure head per unit amplitude."""
    down = np.exp(-k * d)
    if math.isinf(depth):
        return down, -k * down
    up = np.exp(-k * (2 * depth - d))
    norm = 1 + np.exp(-2 * k * depth)
    return (down + up) / norm, -k * (down - up) / norm


def _xi_coefficients(kl, count: int) -> np.ndarray:
    """(n, count): Chebyshev coefficients in xh of exp(i k L xh), eps_m i^m J_m(k L)."""
    m = np.arange(count)
    return np.where(m == 0, 1.0, 2.0) * 1j ** m * jv(m[None, :], np.asarray(kl, float)[:, None])


@dataclass(frozen=True)
class AxisymmetricFK:
    """A body of revolution with a vertical axis in a long-crested sea: rows and force evaluation.

    profile ((r, zeta), ...) m, top to keel, zeta down from the centre (closed by discs at the
    ends, as a geometry "revolution"); radius > 0: the exact sphere of that radius instead
    (`sphere`). centre_rest (x, y, z) n-frame at rest (m); direction b (rad); half_width L (m,
    horizontal motion along b allowed); n_xi terms in xh; n_s terms per piece of the s range
    (an int for all, or one per piece: `pieces`); margin (m): the range reaches that far past
    full submergence; water_depth (m); g (m/s^2) for the dispersion. See the module docstring.
    """
    profile: tuple
    centre_rest: tuple
    direction: float
    half_width: float
    n_xi: int
    n_s: int | tuple
    water_depth: float = math.inf
    margin: float = 0.0
    radius: float = 0.0
    g: float = 9.81
    _cuts: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        numbers = (*self.centre_rest, self.direction, self.half_width, self.margin, self.g)
        if len(self.centre_rest) != 3 or not all(math.isfinite(v) for v in numbers) \
                or self.half_width <= 0 or self.margin < 0 or self.g <= 0 \
                or not self.water_depth > 0 or self.radius < 0 or int(self.n_xi) < 1:
            raise HydroError(f"analytic FK body: expected a finite centre (3 m) and direction, "
                             f"half_width > 0, margin >= 0, g > 0, water_depth > 0, n_xi >= 1; "
                             f"got {numbers}, depth {self.water_depth}, n_xi {self.n_xi}")
        problem = None if self.radius else profile_problem([list(p) for p in self.profile])
        if problem is not None:
            raise HydroError(f"analytic FK body: {problem[0]}: {problem[1]}")
        r, z = self._closed()
        cuts = {-z[0], -z[-1]}
        for i in range(1, len(r) - 1 if self.radius == 0 else 1):
            u, v = np.array([r[i] - r[i - 1], z[i] - z[i - 1]]), np.array([r[i + 1] - r[i], z[i + 1] - z[i]])
            turn = math.degrees(math.atan2(abs(u[0] * v[1] - u[1] * v[0]), u @ v))
            if z[0] < z[i] < z[-1] and (u[1] == 0 or v[1] == 0 or turn > CORNER_DEG):
                cuts.add(-z[i])
        cuts = sorted(cuts) + ([-z[0] + self.margin] if self.margin > 0 else [])
        count = len(cuts) - 1
        n_s = (self.n_s,) * count if np.ndim(self.n_s) == 0 else tuple(self.n_s)
        if len(n_s) != count or min(n_s) < 2:
            raise HydroError(f"analytic FK body: n_s = {self.n_s!r}; expected one order >= 2, or "
                             f"one per piece of the s range ({count})")
        if cuts[-1] + z[-1] >= self.water_depth:
            raise HydroError(f"analytic FK body: the keel reaches {cuts[-1] + z[-1]:g} m deep at "
                             f"the end of the range, past the water depth {self.water_depth:g} m")
        object.__setattr__(self, "_cuts", tuple(zip(cuts[:-1], cuts[1:], n_s)))

    # ------------------------------------------------------------------ geometry
    def _closed(self):
        """(r, zeta) of the profile closed to the axis; a sphere: its three extreme points."""
        if self.radius > 0:
            return np.array([0.0, self.radius, 0.0]), np.array([-self.radius, 0.0, self.radius])
        p = np.array(self.profile, float)
        r, z = p[:, 0], p[:, 1]
        if r[0] > 0:
            r, z = np.r_[0.0, r], np.r_[z[0], z]
        if r[-1] > 0:
            r, z = np.r_[r, 0.0], np.r_[z, z[-1]]
        return r, z

    @property
    def pieces(self) -> tuple:
        """The s ranges (m) and their orders, as ((a, b, n), ...)."""
        return self._cuts

    @property
    def height(self) -> float:
        return float(np.ptp(self._closed()[1]))

    @property
    def n_rows(self) -> int:
        return self.n_xi * (1 + sum(n for _, _, n in self._cuts))

    def _statics(self, s, symbolic):
        """(V(s) m^3, r_wl(s)^2 m^2): exact, branch-free (fmin/fmax)."""
        if self.radius > 0:
            big = self.radius
            h = _clip(big + s, 0.0, 2 * big, symbolic)
            return math.pi * h * h * (3 * big - h) / 3, h * (2 * big - h)
        r, z = self._closed()
        eps = 1e-3 * self.height
        volume, r_wl = 0.0, 0.0
        for i in range(len(r) - 1):
            h = z[i + 1] - z[i]
            if h > 0:
                slope = (r[i + 1] - r[i]) / h
                w = _clip(z[i + 1] + s, 0.0, h, symbolic)
                volume = volume + math.pi * w * (r[i + 1] ** 2 + w * (-r[i + 1] * slope + w * slope ** 2 / 3))
                r_wl = r_wl + (r[i + 1] - r[i]) * _clip((-s - z[i]) / h, 0.0, 1.0, symbolic)
            else:
                r_wl = r_wl + (r[i + 1] - r[i]) * _clip((-s - z[i]) / eps + 0.5, 0.0, 1.0, symbolic)
        return volume, r_wl * r_wl

    def _wet_nodes(self, s):
        """Gauss-Legendre nodes of the wet profile for each s: zeta, weights, r^2 (n_s, q)."""
        x, w = _GL
        s = np.asarray(s, float)[:, None]
        r, z = self._closed()
        segments = [(0, 2)] if self.radius > 0 else [(i, i + 1) for i in range(len(r) - 1)
                                                     if z[i + 1] > z[i]]
        out = []
        for i, j in segments:
            h = z[j] - z[i]
            length = np.clip(z[j] + s, 0.0, h)
            zeta = z[j] - length * (1 - x) / 2
            if self.radius > 0:
                r2 = np.maximum(self.radius ** 2 - zeta ** 2, 0.0)
            else:
                r2 = (r[j] + (r[i] - r[j]) * (z[j] - zeta) / h) ** 2
            out.append((zeta, length / 2 * w, r2))
        return [np.concatenate(parts, axis=1) for parts in zip(*out)]

    def g_function(self, k, s, slope: bool = False):
        """G_j(s) (n_k, n_s) m^3 by quadrature; with slope, also dG/ds (m^2)."""
        k, s = np.atleast_1d(np.asarray(k, float)), np.atleast_1d(np.asarray(s, float))
        zeta, w, r2 = self._wet_nodes(s)
        depth = zeta + s[:, None]
        G, dG = np.empty((k.size, s.size)), np.empty((k.size, s.size))
        r_wl2 = self._statics(s, False)[1]
        for lo in range(0, k.size, 64):
            kk = k[lo:lo + 64, None, None]
            disc = _disc(kk, r2[None]) * w[None]
            Z, dZ = _kernels(kk, depth[None], self.water_depth)
            G[lo:lo + 64] = np.sum(Z * disc, axis=2)
            if slope:
                dG[lo:lo + 64] = np.sum(dZ * disc, axis=2) + _disc(kk[:, :, 0], r_wl2[None])
        return (G, dG) if slope else G

    def _piece_coefficients(self, k, a, b, n):
        """(n_k, n) Chebyshev coefficients in sh of G(s) - G(a) on [a, b]."""
        x = np.cos(math.pi * np.arange(n) / (n - 1))       # Chebyshev-Lobatto points
        values = self.g_function(k, (a + b) / 2 + (b - a) / 2 * x) - self.g_function(k, [a])
        return np.linalg.solve(C.chebvander(x, n - 1), values.T).T

    # ------------------------------------------------------------------ rows and force
    def row_coefficients(self, omega) -> np.ndarray:
        """(n_omega, n_rows) complex per unit amplitude: n_xi rows of eta (m/m), then per
        piece n_xi x n (row offset + m n + l) of Phi (m^4/m) multiplying T_m(xh) T_l(sh)."""
        k = np.array([wavenumber(float(w), self.water_depth, self.g) for w in np.atleast_1d(omega)])
        x0, y0, _ = self.centre_rest
        phase = np.exp(1j * k * (x0 * math.cos(self.direction) + y0 * math.sin(self.direction)))
        xi = _xi_coefficients(k * self.half_width, self.n_xi) * phase[:, None]
        blocks = [xi]
        for a, b, n in self._cuts:
            q = self._piece_coefficients(k, a, b, n)
            blocks.append((xi[:, :, None] * q[:, None, :]).reshape(k.size, -1))
        return np.concatenate(blocks, axis=1)

    def _xi(self, centre):
        """xi_c (m): the centre's offset from its rest position along the sea's direction."""
        x0, y0, _ = self.centre_rest
        return (centre[0] - x0) * math.cos(self.direction) + (centre[1] - y0) * math.sin(self.direction)

    def _series(self, rows, centre, symbolic):
        """(eta_c, eta'_c, dPhi/dxi, dPhi/ds) from the rows at the centre."""
        tm, dtm = _chebyshev(_clip(self._xi(centre) * (1 / self.half_width), -1.0, 1.0, symbolic),
                             self.n_xi)
        eta = sum(rows[m] * tm[m] for m in range(self.n_xi))
        s = centre[2] + eta
        eps, dxi, ds, row = 1e-3 * self.height, 0.0, 0.0, self.n_xi
        for a, b, n in self._cuts:
            tl, dtl = _chebyshev(_clip((2 * s - a - b) / (b - a), -1.0, 1.0, symbolic), n)
            block = [[rows[row + m * n + l] for l in range(n)] for m in range(self.n_xi)]
            row += self.n_xi * n
            value = [sum(c[l] * tl[l] for l in range(n)) for c in block]
            slope = [sum(c[l] * dtl[l] for l in range(n)) for c in block]
            dxi = dxi + sum(value[m] * dtm[m] for m in range(self.n_xi))
            indicator = _clip((s - a) / eps + 0.5, 0.0, 1.0, symbolic)
            if (a, b, n) != self._cuts[-1]:
                indicator = indicator - _clip((s - b) / eps + 0.5, 0.0, 1.0, symbolic)
            ds = ds + indicator * (2 / (b - a)) * sum(slope[m] * tm[m] for m in range(self.n_xi))
        tilt = sum(rows[m] * dtm[m] for m in range(self.n_xi))
        return eta, tilt * (1 / self.half_width), dxi * (1 / self.half_width), ds

    def wrench(self, rows, centre, rho, g) -> tuple:
        """(force (3,) N, moment about c (3,) N m; zero: see the module docstring), n-frame,
        from the n_rows values at this instant (none: calm water) and the current geometric
        centre (n-frame, m). numpy or CasADi alike, no branching on values: xh and the pieces'
        sh clamped to [-1, 1]."""
        symbolic = _casadi(rows, rho, g, *(centre[i] for i in range(3)))
        if not symbolic:
            rows, centre = np.asarray(rows, float).ravel(), np.asarray(centre, float).ravel()
        calm = (rows.numel() if hasattr(rows, "numel") else np.size(rows)) == 0
        eta, tilt, dxi, ds = (0.0,) * 4 if calm else self._series(rows, centre, symbolic)
        volume, r_wl2 = self._statics(centre[2] + eta, symbolic)
        f_dyn = rho * g * (math.pi * r_wl2 * eta - ds)        # F_z but the buoyancy
        f_xi = -rho * g * dxi + tilt * f_dyn
        f_z = f_dyn - rho * g * volume
        force = [math.cos(self.direction) * f_xi, math.sin(self.direction) * f_xi, f_z]
        if symbolic:
            force = ca.vertcat(*force)
            return force, type(force).zeros(3, 1)
        return np.array(force, float), np.zeros(3)

    def outside(self, rows, centre) -> bool:
        """numpy: True when the state lies past the series' box (|xi_c| > L or s past the range),
        where `wrench` used the boundary's values."""
        rows, centre = np.asarray(rows, float), np.asarray(centre, float)
        xi = self._xi(centre)
        tm, _ = _chebyshev(float(np.clip(xi / self.half_width, -1, 1)), self.n_xi)
        s = centre[2] + float(np.dot(rows[:self.n_xi], tm))
        return bool(abs(xi) > self.half_width or s > self._cuts[-1][1])


# ---------------------------------------------------------------------- orders and factories
def _xi_order(half_width: float, k_max: float, tol: float) -> int:
    """Fewest terms whose tail in value and in (1/k) d/dxi stays below tol for k <= k_max."""
    kl = np.linspace(1e-3, 1.0, 200) * k_max * half_width
    count = int(kl[-1] + 10 * kl[-1] ** (1 / 3) + 40)
    m = np.arange(count)
    size = np.abs(_xi_coefficients(kl, count)) * np.maximum(1.0, m * m / kl[:, None])
    tail = np.cumsum(size[:, ::-1], axis=1)[:, ::-1].max(axis=0)
    return int(np.argmax(tail < tol)) if np.any(tail < tol) else count


def _piece_error(body, k, a, b, n) -> float:
    """Worst error of a piece's series in dG/ds and k G (m^2) on a fine grid, over k."""
    x = np.cos(math.pi * (np.arange(48) + 0.5) / 48) * (1 - 2e-3 * body.height / (b - a))
    s = (a + b) / 2 + (b - a) / 2 * x            # clear of the cuts' ramps (r_wl's jumps)
    G, dG = body.g_function(k, s, slope=True)
    G = G - body.g_function(k, [a])
    q = body._piece_coefficients(k, a, b, n)
    fit = C.chebval(x, q.T)
    slope = C.chebval(x, C.chebder(q.T)) * (2 / (b - a))
    return float(max(np.max(np.abs(slope - dG)), np.max(np.abs(fit - G) * k[:, None])))


def choose_orders(body: AxisymmetricFK, k_max: float, tol: float = 1e-3) -> AxisymmetricFK:
    """`body` with the fewest n_xi and per-piece n_s whose truncation errors stay below tol / 2
    each, relative to pi r_max^2 (rho g a pi r_max^2 of force per unit amplitude a) for
    every wavenumber up to k_max (rad/m); a series that misses it at MAX_ORDER warns."""
    if not (k_max > 0 and 0 < tol < 1):
        raise HydroError(f"analytic FK orders: expected k_max > 0 and 0 < tol < 1, got {k_max}, {tol}")
    scale = math.pi * float(np.max(body._closed()[0])) ** 2
    n_xi = max(1, _xi_order(body.half_width, k_max, tol / 2))
    k = k_max * np.array([1.0, 0.6, 0.3, 0.1, 0.02])
    orders = []
    for a, b, _ in body.pieces:
        n = 2
        while (error := _piece_error(body, k, a, b, n) / scale) > tol / 2 and n < MAX_ORDER:
            n += 1
        if error > tol / 2:
            warnings.warn(f"analytic FK: the s range {a:.3g}..{b:.3g} m reaches {error:.2g} "
                          f"(not {tol / 2:.2g}) with {n} terms", RuntimeWarning, stacklevel=2)
        orders.append(n)
    return dataclasses.replace(body, n_xi=n_xi, n_s=tuple(orders))


def sphere(radius, centre_rest, direction, half_width, k_max, **options) -> AxisymmetricFK:
    """The exact sphere (cap volumes V = pi h^2 (3R - h)/3, h = clip(R + s, 0, 2R)) about
    centre_rest; orders for k <= k_max (rad/m); options as `from_geometry`'s."""
    return from_geometry({"type": "sphere", "radius": radius, "center": list(centre_rest)},
                         None, direction, half_width, k_max, **options)


def from_geometry(geometry: dict, cog, direction, half_width, k_max, *, tol=1e-3, margin=None,
                  water_depth=math.inf, g=9.81) -> AxisymmetricFK:
    """The analytic-path body of a geometry dict (as `geometry.BemBody`'s): "sphere",
    "cylinder" (axis "z") or "revolution"; its "center" (default: cog) is c at rest (`wrench`
    gives the moment about c: about the CoG add (c - cog) x F). Orders
    for k <= k_max (rad/m) and tol (`choose_orders`); margin (m) past full submergence,
    default half the height (more for a body submerged at rest)."""
    kind = geometry.get("type") if isinstance(geometry, dict) else None
    radius = 0.0
    if kind == "sphere":
        radius = float(geometry.get("radius", math.nan))
        if not (math.isfinite(radius) and radius > 0):
            raise HydroError(f"analytic FK sphere: radius = {radius!r}; expected a finite number > 0")
        profile = ((0.0, -radius), (radius, 0.0), (0.0, radius))
    elif kind == "cylinder" and geometry.get("axis", "z") == "z":
        r, length = float(geometry.get("radius", math.nan)), float(geometry.get("length", math.nan))
        profile = ((r, -length / 2), (r, length / 2))
    elif kind == "revolution":
        profile = tuple((float(r), float(z)) for r, z in geometry.get("profile", ()))
    else:
        raise HydroError(f"the analytic FK path needs a body of revolution with a vertical axis "
                         f"(sphere, cylinder with axis 'z', revolution), got {kind!r}"
                         + (f" with axis {geometry.get('axis')!r}" if kind == "cylinder" else ""))
    centre = tuple(float(v) for v in geometry.get("center", (0.0, 0.0, 0.0) if cog is None else cog))
    if margin is None:
        height = profile[-1][1] - profile[0][1]
        margin = max(height / 2, centre[2] + profile[0][1] + height / 2)
        if math.isfinite(water_depth):                  # the keel stays above the sea bed
            margin = min(margin, max(0.0, 0.99 * (water_depth - height)))
    body = AxisymmetricFK(profile, centre, float(direction), float(half_width), 1, 2,
                          water_depth, float(margin), radius, g)
    return choose_orders(body, k_max, tol)
