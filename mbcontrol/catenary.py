"""Quasi-static elastic catenary mooring line: exact solve, stiffness, CasADi force Function.

Derivation. Unstretched arc length s runs from the anchor (s = 0) to the fairlead (s = L), z
up from the anchor (this 2-D frame only). Only the submerged weight w (N/m) loads the line, so
the horizontal tension H is uniform and the vertical one grows linearly, V(s) = V_A + w s,
V_A = V - w L. Hooke stretches ds into (1 + T/EA) ds, T = sqrt(H^2 + V(s)^2), along the
tangent (H, V(s))/T: dx/ds = H/T + H/EA, dz/ds = V(s)/T + V(s)/EA. Integrated over a line
clear of the seabed (V_A >= 0), with T_F, T_A the end tensions:
    XF = (H/w) [asinh(V/H) - asinh(V_A/H)] + H L/EA,   ZF = (T_F - T_A)/w + (V L - w L^2/2)/EA.
When V < w L, L_B = L - V/w lies on the flat seabed, which carries its weight, and the rest
leaves it horizontally (V_A = 0 at touchdown):
    XF = L_B + (H/w) asinh(V/H) + H L/EA + C,          ZF = (T_F - H)/w + V^2/(2 EA w).
C is the seabed friction correction (coefficient cb, at its limit): tension along the lying
part falls by cb w per metre toward the anchor, down to 0, taking stretch away; with
a = H/(cb w), C = -cb w L_B^2/(2 EA) if L_B <= a, else (H^2/(2 cb w) - H L_B)/EA. Both
cases and their Jacobians agree at V = w L, so Newton crosses touchdown smoothly.

Without friction the flexibility d(XF, ZF)/d(H, V) is symmetric positive definite: ZF grows
with V at fixed H, and XF with H along ZF = const, so a nested bracketing solve (V from ZF
inside, H from XF outside) is a guaranteed fallback for damped Newton. H -> 0: the line hangs
vertically over L_h (ZF = L_h + w L_h^2/(2 EA)), the rest lies slack, so XF <= L - L_h is
"slack" (H = 0, V = w L_h). A chord longer than L holds only by stretching: "taut", and past
the strain limit "taut-out" (still solved; the caller decides).
"""
from __future__ import annotations

import math
import numbers
import re
import warnings
from dataclasses import dataclass, field
from types import SimpleNamespace

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from .errors import SceneError

STATUSES = ("seabed contact", "suspended", "slack", "taut", "taut-out")


@dataclass(frozen=True)
class CatenarySolution:
    """Tensions and state of one line. Forces in N, lengths in m, strains dimensionless.

    H, V: tension components at the fairlead (the line pulls it toward the anchor by H and
    down by V); H_anchor, V_anchor: at the anchor (pulled toward the fairlead and up).
    lying_length: length on the seabed.
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


# The shape equations serve floats and CasADi SX alike: `ops` gives sqrt, log1p, abs and a
# select that evaluates both branches, so each must stay finite in the other's domain.
_NUM = SimpleNamespace(sqrt=math.sqrt, log1p=math.log1p, abs=abs,
                       select=lambda c, a, b: a if c else b)
_SYM = SimpleNamespace(sqrt=ca.sqrt, log1p=ca.log1p, abs=ca.fabs, select=ca.if_else)


def _shape_terms(H, V, L, EA, w, cb, ops=_NUM):
    """Fairlead offset XF, ZF (m) and flexibility d(XF, ZF)/d(H, V) (m/N) as
    (XF, ZF, dXF/dH, dXF/dV, dZF/dH, dZF/dV), for H > 0 and V > 0."""
    T = ops.sqrt(H * H + V * V)
    VA = V - w * L
    TA = ops.sqrt(H * H + VA * VA)
    clear = VA >= 0.0
    # clear of the seabed: asinh(V/H) - asinh(VA/H) = log1p((V - VA + T - TA)/(VA + TA)), with
    # T - TA = (V^2 - VA^2)/(T + TA): no cancellation for nearly vertical (H -> 0) or nearly
    # straight (T >> w L) lines; VA + TA = H^2/(TA - VA) stays positive when VA < 0
    lift = ops.select(clear, VA + TA, H * H / (TA + ops.abs(VA)))
    dasinh = ops.log1p(w * L * (1.0 + (V + VA) / (T + TA)) / lift)
    s_XF = H / w * dasinh + H * L / EA
    s_ZF = L * (V + VA) / (T + TA) + (V * L - 0.5 * w * L * L) / EA
    s_cross = H / w * (1.0 / T - 1.0 / TA)
    s_XH = dasinh / w - (V / T - VA / TA) / w + L / EA
    s_ZV = (V / T - VA / TA) / w + L / EA
    # part of the line on the seabed, L_B = L - V/w of it
    LB = L - V / w
    asn = ops.log1p((V + V * V / (T + H)) / H)              # asinh(V/H) = log((V + T)/H)
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


def _initial_guess(XF, ZF, L, EA, w):
    """Peyrot & Goulois' guess (an inextensible catenary whose sag matches the chord) or, for
    a chord longer than L, a straight elastic bar with half the weight hung at each end."""
    chord = math.hypot(XF, ZF)
    if chord >= L:
        T = EA * (chord / L - 1.0)
        return max(T * XF / chord, 1e-6 * w * L), T * ZF / chord + 0.5 * w * L
    lam = 1e6 if XF <= 0.0 else math.sqrt(3.0 * ((L * L - ZF * ZF) / (XF * XF) - 1.0))
    return max(w * XF / (2.0 * lam), 1e-6 * w * L), 0.5 * w * (ZF / math.tanh(lam) + L)


def _newton(XF, ZF, L, EA, w, cb, tol, max_iter):
    """Damped Newton on (H, V); returns (H, V, J, iterations) or None if it stalls."""
    H, V = _initial_guess(XF, ZF, L, EA, w)
    x, z, XH, XV, ZH, ZV = _shape_terms(H, V, L, EA, w, cb)
    norm = math.hypot(x - XF, z - ZF)
    for it in range(max_iter + 1):
        if norm <= tol:
            return H, V, np.array([[XH, XV], [ZH, ZV]]), it
        det = XH * ZV - XV * ZH
        if not det > 0.0:                           # the flexibility is positive definite
            return None
        dH = -(ZV * (x - XF) - XV * (z - ZF)) / det
        dV = -(XH * (z - ZF) - ZH * (x - XF)) / det
        # H and V must stay positive: never let a step take away more than 90 % of either
        t = min([1.0] + [0.9 * u / -du for u, du in ((H, dH), (V, dV)) if u + du < 0.1 * u])
        while t > 1e-10:                            # backtrack until |residual| decreases
            trial = _shape_terms(H + t * dH, V + t * dV, L, EA, w, cb)
            trial_norm = math.hypot(trial[0] - XF, trial[1] - ZF)
            if trial_norm < (1.0 - 1e-4 * t) * norm or trial_norm <= tol:
                break
            t *= 0.5
        else:
            return None
        H, V, norm = H + t * dH, V + t * dV, trial_norm
        x, z, XH, XV, ZH, ZV = trial
    return None


def _bracketed(XF, ZF, L, EA, w, cb):
    """Nested Brent solve (see the module docstring); returns (H, V, J, evaluations)."""
    count = [0]

    def height(H, V):
        count[0] += 1
        return _shape_terms(H, V, L, EA, w, cb)[1] - ZF

    def v_for(H):
        hi = w * L + H + 1.0
        while height(H, hi) < 0.0:
            hi *= 4.0
        return brentq(lambda V: height(H, V), 0.0, hi, xtol=1e-300, rtol=1e-15)

    def reach(H):
        return _shape_terms(H, v_for(H), L, EA, w, cb)[0] - XF

    lo = 1e-12 * w * L
    if reach(lo) >= 0.0:
        H = lo
    else:
        hi = max(_initial_guess(XF, ZF, L, EA, w)[0], w * L)
        while reach(hi) < 0.0:
            hi *= 4.0
        H = brentq(reach, lo, hi, xtol=1e-300, rtol=1e-15)
    V = v_for(H)
    return H, V, np.reshape(_shape_terms(H, V, L, EA, w, cb)[2:], (2, 2)), count[0]


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
    values = {"XF": XF, "ZF": ZF, "length": length, "EA": EA, "weight": weight,
              "friction": friction}
    for key, value in values.items():
        positive = key in ("length", "EA", "weight")
        if not (math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
            raise SceneError(f"{where}: {key} is {value:g}; expected a finite number "
                             f"{'> 0' if positive else '>= 0 (fairlead not below the anchor)'}")
    XF, ZF, L, w, cb = (float(values[k]) for k in ("XF", "ZF", "length", "weight", "friction"))
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
        stiffness = np.array([[EA / L if H > 0 else 0.0, 0.0], [0.0, w]])   # dV/dZF: as slack
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
        x, z = _shape_terms(H, V, L, EA, w, cb)[:2]
        miss = math.hypot(x - XF, z - ZF)
        if not miss <= 1e3 * tol:                   # also catches NaN
            raise SceneError(f"{where}: no catenary solution for XF = {XF:g} m, ZF = {ZF:g} m "
                             f"(residual {miss:.3g} m)")
        stiffness = np.linalg.inv(J)
    lying = max(L - V / w, 0.0)
    status = ("taut-out" if chord_strain > strain_limit else "taut" if chord_strain > 0.0
              else "slack" if H == 0.0 else "seabed contact" if lying > 0.0 else "suspended")
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
class ForceTable:
    """A line's CasADi force Function, the table size (points per axis) and Newton steps it
    settled on, and its max force error at 4 points in each cell / rest tension."""
    function: ca.Function
    n_grid: int
    newton_steps: int
    error: float


@dataclass(frozen=True)
class CatenaryLine:
    """One mooring line from a seabed anchor to a fairlead, with a CasADi force Function.

    anchor, fairlead: rest positions, n-frame (z down), m. length: unstretched, m. EA: N.
    weight: submerged, N/m (> 0). excursion: the force table covers fairlead displacements
    from rest up to this, m, horizontally (any direction) and vertically; None: 20 % of the
    rest fairlead height above the anchor. n_grid, newton_steps: the smallest table (points
    per axis) and number of Newton steps `force_table` tries. friction: seabed friction
    coefficient. strain_limit: chord strain beyond which the line is "taut-out".

    Measured with force_table(1e-4); error: max |F - F_exact| / rest tension at 4 points per
    cell, then at 300 random points in the envelope; cost: gcc -O3 C, 2e6 calls, ranges over
    runs on a shared machine; ~45-90 ns for the lookup plus ~40-100 ns per Newton step:
      OC3-Hywind line (L 902.2 m, EA 384 MN, w 698 N/m, XF 848.67 m, ZF 250 m, seabed
        contact), excursion 20 m: 21 x 21, 3 steps, 1.1e-9 / 3.8e-10, 200-350 ns per call.
      WEC chain (L 140 m, EA 500 MN, w 1 kN/m, XF 120 m, ZF 45 m), 10 m, reaching taut:
        41 x 41, 3 steps, 3.7e-6 / 2.7e-9. At XF 90 m, 15 m, crossing the slack boundary:
        21 x 21, 3 steps, 5e-11 / 8e-9.
      Vertical tether snapping between slack and taut (L 44.7 m, ZF 45 m, EA 20 MN), 3 m:
        21 x 21, 8 steps, 4.3e-5 / 1.9e-8, 520-840 ns per call.
    The table alone (no Newton step) errs 2e-2 (21 x 21) and 4e-3 (41 x 41) on OC3; a cubic
    "bspline" interpolant (which also works in SX graphs and codegen; ~380 ns) still errs
    8e-5 at 41 x 41, from the curvature jump at touchdown: hence bilinear + Newton.
    """
    name: str
    anchor: tuple
    fairlead: tuple
    length: float
    EA: float
    weight: float
    excursion: float | None = None
    n_grid: int = 21
    newton_steps: int = 3
    friction: float = 0.0
    strain_limit: float = 0.1

    def __post_init__(self):
        where = f"mooring '{self.name}'"
        anchor, fairlead = (_point(getattr(self, k), where, k) for k in ("anchor", "fairlead"))
        object.__setattr__(self, "anchor", anchor)      # frozen: normalise to float tuples
        object.__setattr__(self, "fairlead", fairlead)
        units = {"length": " m", "EA": " N", "weight": " N/m", "strain_limit": "",
                 "friction": ""}
        for key, unit in units.items():
            value = getattr(self, key)
            if not isinstance(value, numbers.Real) or not math.isfinite(value):
                raise SceneError(f"{where}: {key} is {value!r}; expected a finite number")
            if value <= 0.0 and key != "friction" or value < 0.0:
                raise SceneError(f"{where}: {key} is {value:g}{unit}; expected a positive "
                                 f"number" + (" or 0" if key == "friction" else ""))
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
        if not (isinstance(self.excursion, numbers.Real) and 0.0 < self.excursion < height):
            raise SceneError(f"{where}: excursion is {self.excursion!r} m; expected a number "
                             f"between 0 and the fairlead height above the anchor {height:g} m")
        for key, low in (("n_grid", 6), ("newton_steps", 0)):
            value = getattr(self, key)
            if not (isinstance(value, numbers.Integral) and value >= low):
                raise SceneError(f"{where}: {key} is {value!r}; expected an integer >= {low}")

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
        vertical = XF <= 1e-9 * self.length
        e = np.array([1.0, 0.0]) if vertical else d / XF
        # sideways the line swings about the anchor: tension H over the lever arm XF (for a
        # vertical line H/XF -> dH/dXF)
        lateral = H_X if vertical else sol.H / XF
        K = np.zeros((3, 3))
        K[:2, :2] = H_X * np.outer(e, e) + lateral * (np.eye(2) - np.outer(e, e))
        K[:2, 2] = -H_Z * e                 # dZF = -dz (z is down)
        K[2, :2] = -V_X * e
        K[2, 2] = V_Z
        return K

    # ------------------------------------------------------------------ CasADi table
    def grid(self, n: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Table nodes (uniform, n per axis, default n_grid) in XF and ZF, m: the rest offsets
        +- excursion, padded by one cell so that the envelope's edge cells have neighbours."""
        XF0, ZF0, _ = self.offsets(self.fairlead)
        n, e = n or self.n_grid, self.excursion
        pad = 2.0 * e / (n - 3)
        xs = np.linspace(max(XF0 - e - pad, 0.0), XF0 + e + pad, n)
        zs = np.linspace(max(ZF0 - e - pad, 1e-3 * ZF0), ZF0 + e + pad, n)
        return xs, zs

    def _table(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Grid (see `grid`) and exact H, V on it, N, shape (2, n, n)."""
        xs, zs = self.grid(n)
        HV = np.empty((2, n, n))
        for i, x in enumerate(xs):
            for j, z in enumerate(zs):
                sol = self.solve(np.array(self.anchor) + (x, 0.0, -z))
                HV[:, i, j] = sol.H, sol.V
        return xs, zs, HV

    def _function(self, table: tuple, steps: int) -> ca.Function:
        """The force Function from a `_table` and `steps` Newton steps (see `force_table`)."""
        L, EA, w, cb, a = self.length, self.EA, self.weight, self.friction, self.anchor
        ident = re.sub(r"[\W_]+", "_", self.name).strip("_") or "line"   # valid CasADi name
        xs, zs, HV = table
        # CasADi orders values with the output index fastest, then the first grid axis;
        # "exact" lookup finds the cell of a uniform grid arithmetically, but accepts only
        # grids spaced equally to 1e-14 of their span: offsets from the first node are
        local = [np.linspace(0.0, g[-1] - g[0], g.size) for g in (xs, zs)]
        lookup = ca.interpolant(f"mooring_{ident}_HV", "linear", local, HV.ravel(order="F"),
                                {"lookup_mode": ["exact", "exact"]})
        r = ca.SX.sym("r", 3)
        dx, dy, ZF = r[0] - a[0], r[1] - a[1], a[2] - r[2]
        # smoothed horizontal distance: a finite direction when the line is vertical (XF -> 0),
        # biased by delta^2/(2 XF) elsewhere, i.e. 5e-13 L at XF = L
        delta = 1e-6 * L
        XF = ca.sqrt(dx * dx + dy * dy + delta * delta)
        guess = lookup(ca.vertcat(XF - xs[0], ZF - zs[0]))
        # the shape equations need H > 0: start no lower than a millionth of the line weight
        h, v = ca.fmax(guess[0], 1e-6 * w * L), ca.fmax(guess[1], 1e-6 * w * L)
        for _ in range(steps):
            x, z, XH, XV, ZH, ZV = _shape_terms(h, v, L, EA, w, cb, _SYM)
            det = XH * ZV - XV * ZH
            dh = -(ZV * (x - XF) - XV * (z - ZF)) / det
            dv = -(XH * (z - ZF) - ZH * (x - XF)) / det
            # keep H and V positive, as the exact solver does (inactive near convergence)
            h, v = ca.fmax(h + dh, 0.1 * h), ca.fmax(v + dv, 0.1 * v)
        hanging = 2.0 * ZF / (1.0 + ca.sqrt(1.0 + 2.0 * w * ZF / EA))
        slack = XF <= L - hanging
        h, v = ca.if_else(slack, 0.0, h), ca.if_else(slack, w * hanging, v)
        F = ca.vertcat(-h * dx / XF, -h * dy / XF, v)
        return ca.Function(f"mooring_{ident}", [r], [F, ca.sqrt(h * h + v * v)], ["r"],
                           ["F", "T"])

    def force_table(self, tolerance: float = 1e-4, max_grid: int = 41,
                    max_steps: int = 8) -> ForceTable:
        """The force Function with the cheapest table (n_grid, doubled up to max_grid points
        per axis) and Newton steps (newton_steps up to max_steps) whose force error at 4 points
        in every cell is below `tolerance` x the rest tension; if none, warns and returns the
        most accurate.

        The Function maps r (3x1, fairlead position, n-frame, m) to F (3x1, force of the line
        on the fairlead, n-frame, N) and T (1x1, fairlead tension, N). In the slack zone
        (XF <= L - L_h(ZF)) H = 0 and V = w L_h exactly; elsewhere a bilinear table of the
        exact H, V starts Newton steps on the exact shape equations, which remove the table's
        error and give the derivative of the exact solution (up to the residual). It takes SX
        or MX (the table is a call node in SX graphs) and generates C with CodeGenerator.
        Outside the envelope the table extrapolates and Newton may not converge.
        """
        sizes = [self.n_grid]
        while sizes[-1] < max_grid:
            sizes.append(min(2 * sizes[-1] - 1, max_grid))
        tables, checks, best = {}, {}, None
        # runtime cost grows with the steps, not the grid: try every grid before a new step
        for steps in range(self.newton_steps, max(max_steps, self.newton_steps) + 1):
            for n in sizes:
                if n not in tables:
                    tables[n] = self._table(n)
                    # interpolation errs most inside cells: check 4 points in every cell
                    xs, zs, _ = tables[n]
                    X, Z = np.meshgrid(*[np.r_[0.75 * g[:-1] + 0.25 * g[1:],
                                                 0.25 * g[:-1] + 0.75 * g[1:]] for g in (xs, zs)])
                    points = np.array(self.anchor) + np.c_[X.ravel(), 0 * X.ravel(), -Z.ravel()]
                    checks[n] = points, np.array([self.force(p)[0] for p in points])
                fun = self._function(tables[n], steps)
                error = self._error(fun, *checks[n])
                if best is None or error < best.error:
                    best = ForceTable(fun, n, steps, error)
                if error <= tolerance:
                    return best
        warnings.warn(f"mooring '{self.name}': force table error {best.error:.2g} of the rest "
                      f"tension ({best.n_grid} x {best.n_grid} grid, {best.newton_steps} Newton "
                      f"steps) exceeds {tolerance:g}; reduce the excursion, or raise max_grid "
                      f"or max_steps", RuntimeWarning, stacklevel=2)
        return best

    def force_function(self, tolerance: float = 1e-4) -> ca.Function:
        """`force_table(tolerance).function`: r (3x1, m) -> (F (3x1, N), T (1x1, N))."""
        return self.force_table(tolerance).function

    def table_error(self, fun: ca.Function, n: int = 300, seed: int = 0) -> float:
        """Max |F_fun - F_exact| over n random fairlead positions in the envelope (a cylinder:
        up to `excursion` horizontally and vertically), relative to the rest tension."""
        rng = np.random.default_rng(seed)
        angle = rng.uniform(0.0, 2.0 * np.pi, n)
        radius = self.excursion * np.sqrt(rng.uniform(size=n))
        points = np.array(self.fairlead) + np.c_[radius * np.cos(angle), radius * np.sin(angle),
                                                 rng.uniform(-1.0, 1.0, n) * self.excursion]
        return self._error(fun, points, np.array([self.force(p)[0] for p in points]))

    def _error(self, fun: ca.Function, points: np.ndarray, exact: np.ndarray) -> float:
        """Max |F_fun - exact| at fairlead positions `points` (m, (k, 3)) / rest tension."""
        table = np.array(fun.map(len(points))(points.T)[0]).T
        return float(np.max(np.abs(table - exact))) / self.solve().tension
