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
from dataclasses import dataclass, field
from types import SimpleNamespace

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from ..errors import SceneError

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
SYMBOLIC_OPS = SimpleNamespace(sqrt=ca.sqrt, log1p=ca.log1p, abs=ca.fabs, select=ca.if_else)


def shape_terms(H, V, L, EA, w, cb, ops=_NUM):
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
    x, z, XH, XV, ZH, ZV = shape_terms(H, V, L, EA, w, cb)
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
            trial = shape_terms(H + t * dH, V + t * dV, L, EA, w, cb)
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
        return shape_terms(H, V, L, EA, w, cb)[1] - ZF

    def v_for(H):
        hi = w * L + H + 1.0
        while height(H, hi) < 0.0:
            hi *= 4.0
        return brentq(lambda V: height(H, V), 0.0, hi, xtol=1e-300, rtol=1e-15)

    def reach(H):
        return shape_terms(H, v_for(H), L, EA, w, cb)[0] - XF

    lo = 1e-12 * w * L
    if reach(lo) >= 0.0:
        H = lo
    else:
        hi = max(_initial_guess(XF, ZF, L, EA, w)[0], w * L)
        while reach(hi) < 0.0:
            hi *= 4.0
        H = brentq(reach, lo, hi, xtol=1e-300, rtol=1e-15)
    V = v_for(H)
    return H, V, np.reshape(shape_terms(H, V, L, EA, w, cb)[2:], (2, 2)), count[0]


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
        x, z = shape_terms(H, V, L, EA, w, cb)[:2]
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
