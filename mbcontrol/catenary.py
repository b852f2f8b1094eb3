"""Quasi-static elastic catenary mooring line: exact solve, stiffness, and a CasADi force table.

Derivation. Let s be the unstretched arc length from the anchor (s = 0) to the fairlead
(s = L), and z point up from the anchor (this module's 2-D frame only). Only the submerged
weight w (N/m) loads the line, so the horizontal tension H is uniform and the vertical tension
grows linearly, V(s) = V_A + w s with V_A = V - w L. Hooke's law stretches ds into
(1 + T/EA) ds, T = sqrt(H^2 + V(s)^2), along the tangent (H, V(s))/T, so

    dx/ds = H/T + H/EA,        dz/ds = V(s)/T + V(s)/EA.

Integrating over the whole line when it hangs clear of the seabed (V_A >= 0):

    XF = (H/w) [asinh(V/H) - asinh(V_A/H)] + H L/EA
    ZF = (T_F - T_A)/w + (V L - w L^2/2)/EA,      T_F = sqrt(H^2+V^2), T_A = sqrt(H^2+V_A^2).

When V < w L a length L_B = L - V/w lies on the (flat) seabed, which carries its weight; the
hanging part starts horizontal at the touchdown point (V_A = 0 there), so

    XF = L_B + (H/w) asinh(V/H) + H L/EA + C,      ZF = (T_F - H)/w + V^2/(2 EA w).

C is the seabed-friction correction (coefficient cb, friction at its limit, pointing toward the
anchor): the tension along the lying part falls by cb w per metre, to zero at most, which takes
stretch away. With a = H/(cb w): C = -cb w L_B^2/(2 EA) if L_B <= a, else (H^2/(2 cb w) -
H L_B)/EA. Both branches and their Jacobians agree at V = w L, so Newton can cross touchdown.

The flexibility d(XF, ZF)/d(H, V) is symmetric positive definite (without friction), so ZF
grows with V at fixed H and, along ZF = const, XF grows with H. That makes a nested bracketing
solve (V from ZF inside, H from XF outside) a guaranteed fallback for damped Newton.

Limits. H -> 0: the line hangs vertically over a hanging length L_h (ZF = L_h + w L_h^2/(2EA))
and the rest lies slack, so any XF <= L - L_h is "slack" with H = 0, V = w L_h. A chord
sqrt(XF^2 + ZF^2) longer than L holds only by stretching: "taut", and past the strain limit
"taut-out" (still solved; the caller decides).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from types import SimpleNamespace

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from .errors import SceneError

_FLOOR = 0.1
STATUSES = ("seabed contact", "suspended", "slack", "taut", "taut-out")


@dataclass(frozen=True)
class CatenarySolution:
    """Tensions and state of one line. Forces in N, lengths in m, strains dimensionless.

    H, V: horizontal and vertical tension at the fairlead (the line pulls the fairlead toward
    the anchor by H and down by V). H_anchor, V_anchor: at the anchor (pulled toward the
    fairlead by H_anchor and up by V_anchor). lying_length: length on the seabed.
    strain: peak axial strain T_F/EA (at the fairlead, where tension is largest).
    chord_strain: chord/L - 1, > 0 iff "taut". stiffness: d(H, V)/d(XF, ZF) (N/m), 2x2.
    iterations: Newton iterations, or function evaluations if the bracketing fallback ran.
    """
    H: float
    V: float
    H_anchor: float
    V_anchor: float
    lying_length: float
    status: str
    strain: float
    chord_strain: float
    iterations: int
    stiffness: np.ndarray = field(repr=False)

    @property
    def tension(self) -> float:
        """Fairlead tension magnitude, N."""
        return math.hypot(self.H, self.V)


# The shape equations are written once for floats and for CasADi SX: `ops` supplies sqrt, log
# and a two-way select (both branches are evaluated, so each must stay finite in the other's
# domain; that is why the suspended branch's VA + TA has a cancellation-free form for VA < 0).
_NUM = SimpleNamespace(sqrt=math.sqrt, log=math.log, select=lambda c, a, b: a if c else b)
_SYM = SimpleNamespace(sqrt=ca.sqrt, log=ca.log, select=ca.if_else)


def _shape_terms(H, V, L, EA, w, cb, ops=_NUM):
    """Fairlead offset XF, ZF (m) and flexibility d(XF, ZF)/d(H, V) (m/N) as
    (XF, ZF, dXF/dH, dXF/dV, dZF/dH, dZF/dV), for H > 0 and V > 0."""
    T = ops.sqrt(H * H + V * V)
    VA = V - w * L
    TA = ops.sqrt(H * H + VA * VA)
    clear = VA >= 0.0
    # clear of the seabed: asinh(V/H) - asinh(VA/H) in log form, T - TA as
    # (V^2 - VA^2)/(T + TA); both stay accurate as H -> 0 (nearly vertical line)
    lift = ops.select(clear, VA + TA, H * H / (TA - VA))
    dasinh = ops.log((V + T) / lift)
    s_XF = H / w * dasinh + H * L / EA
    s_ZF = L * (V + VA) / (T + TA) + (V * L - 0.5 * w * L * L) / EA
    s_cross = H / w * (1.0 / T - 1.0 / TA)
    s_XH = dasinh / w - (V / T - VA / TA) / w + L / EA
    s_ZV = (V / T - VA / TA) / w + L / EA
    # part of the line on the seabed, L_B = L - V/w of it
    LB = L - V / w
    asn = ops.log((V + T) / H)
    b_XF = LB + H / w * asn + H * L / EA
    b_ZF = V * V / (w * (T + H)) + V * V / (2.0 * EA * w)    # (T - H)/w without cancellation
    b_cross = -V * V / (w * T * (T + H))                     # (H/T - 1)/w likewise
    b_XH = asn / w - V / (w * T) + L / EA
    b_XV = b_cross
    b_ZV = V / (w * T) + V / (EA * w)
    if cb > 0.0:
        reach = H / (cb * w)            # length over which friction takes the tension to 0
        short = LB <= reach
        b_XF = b_XF + ops.select(short, -cb * w * LB * LB / (2.0 * EA),
                                 (H * H / (2.0 * cb * w) - H * LB) / EA)
        b_XH = b_XH - ops.select(short, 0.0, (LB - reach) / EA)
        b_XV = b_XV + ops.select(short, cb * LB / EA, H / (w * EA))
    pick = ops.select
    return (pick(clear, s_XF, b_XF), pick(clear, s_ZF, b_ZF), pick(clear, s_XH, b_XH),
            pick(clear, s_cross, b_XV), pick(clear, s_cross, b_cross), pick(clear, s_ZV, b_ZV))


def _shape(H, V, L, EA, w, cb):
    """Numeric XF, ZF (m) and the 2x2 flexibility d(XF, ZF)/d(H, V) (m/N)."""
    XF, ZF, XH, XV, ZH, ZV = _shape_terms(H, V, L, EA, w, cb)
    return XF, ZF, np.array([[XH, XV], [ZH, ZV]])


def _initial_guess(XF, ZF, L, w):
    """Peyrot & Goulois' guess: an inextensible catenary whose sag matches the chord."""
    if XF <= 0.0:
        lam = 1e6
    elif XF * XF + ZF * ZF >= L * L:
        lam = 0.2
    else:
        lam = math.sqrt(3.0 * ((L * L - ZF * ZF) / (XF * XF) - 1.0))
    H = max(abs(w * XF / (2.0 * lam)), 1e-6 * w * L)
    V = 0.5 * w * (ZF / math.tanh(lam) + L)
    return H, V


def _newton(XF, ZF, L, EA, w, cb, tol, max_iter):
    """Damped Newton on (H, V); returns (H, V, J, iterations) or None if it stalls."""
    H, V = _initial_guess(XF, ZF, L, w)
    x, z, J = _shape(H, V, L, EA, w, cb)
    res = np.array([x - XF, z - ZF])
    norm = float(np.hypot(*res))
    for it in range(max_iter + 1):
        if norm <= tol:
            return H, V, J, it
        try:
            dH, dV = -np.linalg.solve(J, res)
        except np.linalg.LinAlgError:
            return None
        # H and V must stay positive: never let a step take away more than 90 % of either
        t = 1.0
        for value, step in ((H, dH), (V, dV)):
            if value + t * step < 0.1 * value:
                t = 0.9 * value / -step
        while t > 1e-10:                            # backtrack until |residual| decreases
            Ht, Vt = H + t * dH, V + t * dV
            x, z, Jt = _shape(Ht, Vt, L, EA, w, cb)
            rt = np.array([x - XF, z - ZF])
            nt = float(np.hypot(*rt))
            if nt < (1.0 - 1e-4 * t) * norm or nt <= tol:
                break
            t *= 0.5
        else:
            return None
        H, V, J, res, norm = Ht, Vt, Jt, rt, nt
    return None


def _bracketed(XF, ZF, L, EA, w, cb):
    """Nested Brent solve (see the module docstring); returns (H, V, J, evaluations)."""
    count = [0]

    def height(H, V):
        count[0] += 1
        return _shape(H, V, L, EA, w, cb)[1] - ZF

    def v_for(H):
        hi = w * L + H + 1.0
        while height(H, hi) < 0.0:
            hi *= 4.0
        return brentq(lambda V: height(H, V), 0.0, hi, xtol=1e-300, rtol=1e-15)

    def reach(H):
        V = v_for(H)
        return _shape(H, max(V, 1e-300), L, EA, w, cb)[0] - XF

    lo = 1e-12 * w * L
    if reach(lo) >= 0.0:
        H = lo
    else:
        hi = max(_initial_guess(XF, ZF, L, w)[0], w * L)
        while reach(hi) < 0.0:
            hi *= 4.0
        H = brentq(reach, lo, hi, xtol=1e-300, rtol=1e-15)
    V = v_for(H)
    return H, V, _shape(H, V, L, EA, w, cb)[2], count[0]


def solve_catenary(XF: float, ZF: float, length: float, EA: float, weight: float, *,
                   friction: float = 0.0, strain_limit: float = 0.1, rtol: float = 1e-11,
                   max_iter: int = 100, name: str = "catenary",
                   method: str = "newton") -> CatenarySolution:
    """Solve one line: anchor on a flat seabed, fairlead XF (m) across and ZF (m) above it.

    length: unstretched length L, m. EA: axial stiffness, N. weight: submerged weight w, N/m.
    friction: seabed friction coefficient (0: none). strain_limit: chord strain beyond which
    the status is "taut-out". rtol: tolerance on the fairlead position, as a fraction of L.
    method: "newton" (damped Newton, bracketing if it stalls) or "bracket" (fallback only).
    Raises SceneError naming `name` on bad input or if no solution is found.
    """
    where = f"mooring '{name}'"
    values = dict(XF=XF, ZF=ZF, length=length, EA=EA, weight=weight, friction=friction)
    for key, value in values.items():
        if not math.isfinite(value):
            raise SceneError(f"{where}: {key} is {value}; expected a finite number")
    for key in ("length", "EA", "weight"):
        if values[key] <= 0.0:
            raise SceneError(f"{where}: {key} is {values[key]:g}; expected a positive number")
    if XF < 0.0 or ZF < 0.0 or friction < 0.0:
        raise SceneError(f"{where}: XF = {XF:g} m, ZF = {ZF:g} m, friction = {friction:g}; "
                         f"expected all >= 0 (fairlead not below the anchor)")
    L, w, cb = float(length), float(weight), float(friction)
    XF, ZF = float(XF), float(ZF)
    chord_strain = math.hypot(XF, ZF) / L - 1.0
    # hanging length of a vertical line reaching ZF, in a form without cancellation
    hanging = 2.0 * ZF / (1.0 + math.sqrt(1.0 + 2.0 * w * ZF / EA))
    iterations = 0
    if ZF == 0.0:                                   # the whole line lies on the seabed
        V, stretch = 0.0, XF - L
        if stretch <= 0.0:
            H = 0.0
        elif cb == 0.0 or stretch >= cb * w * L * L / (2.0 * EA):
            H = EA * stretch / L + 0.5 * cb * w * L
        else:                                       # friction holds the tension off the anchor
            H = math.sqrt(2.0 * cb * w * EA * stretch)
        stiffness = np.array([[EA / L if H > 0 else 0.0, 0.0], [0.0, w]])
    elif hanging <= L and XF <= L - hanging:        # slack: vertical hang, the rest lying
        H, V = 0.0, w * hanging
        stiffness = np.array([[0.0, 0.0], [0.0, w / (1.0 + w * hanging / EA)]])
    elif XF == 0.0:                                 # vertical and clear of the seabed
        H, V = 0.0, 0.5 * w * L + EA * (ZF - L) / L
        lateral = solve_catenary(1e-6 * L, ZF, L, EA, w, rtol=rtol, name=name)
        stiffness = np.array([[lateral.H / (1e-6 * L), 0.0], [0.0, EA / L]])
    else:
        tol = rtol * L
        found = _newton(XF, ZF, L, EA, w, cb, tol, max_iter) if method == "newton" else None
        if found is None:
            try:
                found = _bracketed(XF, ZF, L, EA, w, cb)
            except (ValueError, RuntimeError, OverflowError, ZeroDivisionError) as err:
                raise SceneError(f"{where}: no catenary solution for XF = {XF:g} m, "
                                 f"ZF = {ZF:g} m ({err})") from err
        H, V, J, iterations = found
        x, z, _ = _shape(H, V, L, EA, w, cb)
        if not (math.isfinite(H) and math.isfinite(V)) or math.hypot(x - XF, z - ZF) > 1e3 * tol:
            raise SceneError(f"{where}: no catenary solution for XF = {XF:g} m, ZF = {ZF:g} m "
                             f"(residual {math.hypot(x - XF, z - ZF):.3g} m)")
        stiffness = np.linalg.inv(J)
    lying = max(L - V / w, 0.0)
    if chord_strain > strain_limit:
        status = "taut-out"
    elif chord_strain > 0.0:
        status = "taut"
    elif H == 0.0:
        status = "slack"
    elif lying > 0.0:
        status = "seabed contact"
    else:
        status = "suspended"
    return CatenarySolution(H=H, V=V, H_anchor=max(H - cb * w * lying, 0.0),
                            V_anchor=max(V - w * L, 0.0), lying_length=lying, status=status,
                            strain=math.hypot(H, V) / EA, chord_strain=chord_strain,
                            iterations=iterations, stiffness=stiffness)


def _point(value, where, key):
    """A 3-vector of finite floats (m, n-frame), or a SceneError naming the field."""
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise SceneError(f"{where}: {key} is {value!r}; expected 3 finite numbers "
                         f"(x, y, z in m, n-frame, z down)")
    return tuple(float(v) for v in arr)


def _fmt(p) -> str:
    return "(" + ", ".join(f"{v:g}" for v in p) + ")"


@dataclass(frozen=True)
class CatenaryLine:
    """One mooring line from a seabed anchor to a fairlead, with a CasADi force table.

    anchor, fairlead: positions at rest, n-frame (NED, z down), m; fairlead is the rest
    position the table is centred on. length: unstretched length, m. EA: axial stiffness, N.
    weight: submerged weight per metre, N/m (> 0). excursion: the table covers fairlead
    displacements up to this much horizontally (any direction) and vertically from rest, m;
    None means 20 % of the rest fairlead height above the anchor. n_grid: table points per
    axis. friction: seabed friction coefficient (quasi-static, at its limit).
    strain_limit: chord strain that makes the line "taut-out".

    Table accuracy and cost (measured with `table_error` and a compiled `force_function`, on
    the OC3-Hywind line: L = 902.2 m, EA = 384.243 MN, w = 698.094 N/m, XF = 848.67 m,
    ZF = 250 m, excursion 20 m, default n_grid): see TABLE_NOTE below this class.
    """
    name: str
    anchor: tuple
    fairlead: tuple
    length: float
    EA: float
    weight: float
    excursion: float | None = None
    n_grid: int = 21
    interpolation: str = "linear"
    newton_steps: int = 2
    friction: float = 0.0
    strain_limit: float = 0.1

    def __post_init__(self):
        where = f"mooring '{self.name}'"
        anchor = _point(self.anchor, where, "anchor")
        fairlead = _point(self.fairlead, where, "fairlead")
        object.__setattr__(self, "anchor", anchor)
        object.__setattr__(self, "fairlead", fairlead)
        units = {"length": "m", "EA": "N", "weight": "N/m", "strain_limit": "",
                 "friction": ""}
        for key, unit in units.items():
            value = getattr(self, key)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise SceneError(f"{where}: {key} is {value!r}; expected a finite number")
        for key in ("length", "EA", "weight", "strain_limit"):
            if getattr(self, key) <= 0.0:
                unit = f" {units[key]}" if units[key] else ""
                raise SceneError(f"{where}: {key} is {getattr(self, key):g}{unit}; expected a "
                                 f"positive number")
        if self.friction < 0.0:
            raise SceneError(f"{where}: friction is {self.friction:g}; expected >= 0")
        height = anchor[2] - fairlead[2]
        if height <= 0.0:
            raise SceneError(f"{where}: anchor {_fmt(anchor)} is not below the fairlead "
                             f"{_fmt(fairlead)}; expected the anchor's z (down) to be greater")
        distance = math.dist(anchor, fairlead)
        if distance > self.length * (1.0 + self.strain_limit):
            raise SceneError(f"{where}: anchor {_fmt(anchor)} is {distance:.0f} m from the "
                             f"fairlead, beyond the line's reach {self.length:g} m x "
                             f"(1 + {self.strain_limit:g} strain limit)")
        if self.excursion is None:
            object.__setattr__(self, "excursion", 0.2 * height)
        if not (isinstance(self.excursion, (int, float)) and 0.0 < self.excursion < height):
            raise SceneError(f"{where}: excursion is {self.excursion!r} m; expected a number "
                             f"between 0 and the fairlead height above the anchor {height:g} m")
        if not (isinstance(self.n_grid, int) and self.n_grid >= 6):
            raise SceneError(f"{where}: n_grid is {self.n_grid!r}; expected an integer >= 6")
        if self.interpolation not in ("linear", "bspline"):
            raise SceneError(f"{where}: interpolation is {self.interpolation!r}; expected "
                             f"'linear' or 'bspline'")
        if not (isinstance(self.newton_steps, int) and self.newton_steps >= 0):
            raise SceneError(f"{where}: newton_steps is {self.newton_steps!r}; expected an "
                             f"integer >= 0")

    # ------------------------------------------------------------------ exact quasi-statics
    def offsets(self, r) -> tuple[float, float, np.ndarray]:
        """(XF, ZF, d): horizontal distance and height of fairlead position r above the anchor,
        m, and d = (r - anchor) in the horizontal plane (2,)."""
        r = np.asarray(r, dtype=float).reshape(3)
        d = r[:2] - np.asarray(self.anchor[:2])
        return float(np.hypot(*d)), self.anchor[2] - float(r[2]), d

    def solve(self, r=None) -> CatenarySolution:
        """Exact solution with the fairlead at r (n-frame, m; default: at rest)."""
        XF, ZF, _ = self.offsets(self.fairlead if r is None else r)
        return solve_catenary(XF, ZF, self.length, self.EA, self.weight, friction=self.friction,
                              strain_limit=self.strain_limit, name=self.name)

    def force(self, r=None) -> tuple[np.ndarray, float]:
        """Exact force of the line on the fairlead at r (3,), N, n-frame, and tension, N."""
        XF, _, d = self.offsets(self.fairlead if r is None else r)
        sol = self.solve(r)
        e = d / XF if XF > 0.0 else np.zeros(2)
        return np.array([-sol.H * e[0], -sol.H * e[1], sol.V]), sol.tension

    def stiffness(self, r=None) -> np.ndarray:
        """Linearised stiffness K = -dF/dr (3x3, N/m, n-frame) at fairlead position r, by
        implicit differentiation of the exact solution."""
        XF, _, d = self.offsets(self.fairlead if r is None else r)
        sol = self.solve(r)
        (H_X, H_Z), (V_X, V_Z) = sol.stiffness
        e = d / XF if XF > 1e-9 * self.length else np.array([1.0, 0.0])
        # sideways, the line swings about the anchor: tension H over the lever arm XF
        lateral = sol.H / XF if XF > 1e-9 * self.length else H_X
        K = np.zeros((3, 3))
        K[:2, :2] = H_X * np.outer(e, e) + lateral * (np.eye(2) - np.outer(e, e))
        K[:2, 2] = -H_Z * e                 # dZF = -dz: raising the fairlead pulls harder
        K[2, :2] = -V_X * e
        K[2, 2] = V_Z
        return K

    # ------------------------------------------------------------------ CasADi table
    def grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Table nodes (uniform) in XF and ZF, m: the rest offsets +- excursion, padded by
        one cell so that the envelope's edge cells have neighbours on both sides."""
        XF0, ZF0, _ = self.offsets(self.fairlead)
        n, e = self.n_grid, self.excursion
        pad = 2.0 * e / (n - 3)
        xs = np.linspace(max(XF0 - e - pad, 0.0), XF0 + e + pad, n)
        zs = np.linspace(max(ZF0 - e - pad, 1e-3 * ZF0), ZF0 + e + pad, n)
        return xs, zs

    def _tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        xs, zs = self.grid()
        H = np.empty((xs.size, zs.size))
        V = np.empty_like(H)
        for i, x in enumerate(xs):
            for j, z in enumerate(zs):
                sol = solve_catenary(x, z, self.length, self.EA, self.weight,
                                     friction=self.friction, strain_limit=self.strain_limit,
                                     name=self.name)
                H[i, j], V[i, j] = sol.H, sol.V
        return xs, zs, H, V

    def force_function(self) -> ca.Function:
        """CasADi Function r (3x1, fairlead position, n-frame, m) -> (F (3x1, N, force of the
        line on the fairlead, n-frame), T (1x1, fairlead tension, N)).

        Inside the slack zone (XF <= L - L_h(ZF)) H = 0 and V = w L_h exactly. Elsewhere a
        table of the exact H, V over `grid()` (casadi.interpolant, `interpolation` kind)
        gives the start of `newton_steps` undamped Newton steps on the shape equations,
        which remove the table's error and make the derivative that of the exact solution
        (up to the residual). Callable on SX or MX (the table enters as a call node) and
        C-generated by CodeGenerator. Outside the envelope the table extrapolates and Newton
        corrects it, but convergence is not guaranteed: keep the motion inside.
        """
        L, EA, w, cb, a = self.length, self.EA, self.weight, self.friction, self.anchor
        ident = re.sub(r"\W", "_", self.name)
        xs, zs, H, V = self._tables()
        # uniform grids: "exact" lookup finds the cell arithmetically (bspline has no such mode)
        opts = {"lookup_mode": ["exact", "exact"]} if self.interpolation == "linear" else {}
        # CasADi orders values with the output index fastest, then the first grid axis
        table = ca.interpolant(f"mooring_{ident}_HV", self.interpolation, [xs, zs],
                               np.stack([H, V]).ravel(order="F"), opts)
        r = ca.SX.sym("r", 3)
        dx, dy, ZF = r[0] - a[0], r[1] - a[1], a[2] - r[2]
        # smoothed horizontal distance: a finite direction when the line is vertical (XF -> 0),
        # biased by delta^2/(2 XF) elsewhere, i.e. 5e-13 L at XF = L
        delta = 1e-6 * L
        XF = ca.sqrt(dx * dx + dy * dy + delta * delta)
        guess = table(ca.vertcat(XF, ZF))
        # the shape equations need H > 0: start no lower than a millionth of the line weight
        h, v = ca.fmax(guess[0], 1e-6 * w * L), ca.fmax(guess[1], 1e-6 * w * L)
        for _ in range(self.newton_steps):
            x, z, XH, XV, ZH, ZV = _shape_terms(h, v, L, EA, w, cb, _SYM)
            det = XH * ZV - XV * ZH
            dh = -(ZV * (x - XF) - XV * (z - ZF)) / det
            dv = -(XH * (z - ZF) - ZH * (x - XF)) / det
            # keep H and V positive, as in the exact solver (inactive near convergence)
            h, v = ca.fmax(h + dh, _FLOOR * h), ca.fmax(v + dv, _FLOOR * v)
        hanging = 2.0 * ZF / (1.0 + ca.sqrt(1.0 + 2.0 * w * ZF / EA))
        slack = XF <= L - hanging
        h, v = ca.if_else(slack, 0.0, h), ca.if_else(slack, w * hanging, v)
        F = ca.vertcat(-h * dx / XF, -h * dy / XF, v)
        return ca.Function(f"mooring_{ident}", [r], [F, ca.sqrt(h * h + v * v)], ["r"],
                           ["F", "T"])

    def table_error(self, fun: ca.Function | None = None, n: int = 400, seed: int = 0) -> float:
        """Max |F_fun - F_exact| over n random fairlead positions in the envelope (a cylinder:
        up to `excursion` horizontally and vertically), relative to the rest tension; `fun`
        defaults to a new `force_function()`."""
        fun = self.force_function() if fun is None else fun
        rng = np.random.default_rng(seed)
        worst = 0.0
        for _ in range(n):
            angle = rng.uniform(0.0, 2.0 * np.pi)
            radius = self.excursion * math.sqrt(rng.uniform())
            r = np.array(self.fairlead) + np.array([radius * math.cos(angle),
                                                    radius * math.sin(angle),
                                                    rng.uniform(-1.0, 1.0) * self.excursion])
            exact, _ = self.force(r)
            worst = max(worst, float(np.max(np.abs(np.array(fun(r)[0]).ravel() - exact))))
        return worst / self.solve().tension
