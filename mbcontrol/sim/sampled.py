"""Is a sampled (zero-order-hold) closed loop stable? The plant's exact Jacobians at rest,
discretised over the controller's period, with the controller's static law closed around them.

simulate holds a controller's command over its period: at t_k = k h it samples
y_k = h(x_k, u_{k-1}) (the outputs with the command still applied) and applies u_k = law(y_k)
over [t_k, t_k + h). Linearised about rest, with u = K y (K = d law / d y):

    x_{k+1} = Phi x_k + Gamma u_k,   Phi = exp(A h),   Gamma = int_0^h exp(A s) ds B_u,
    u_k = K (C x_k + D_u u_{k-1}),

exact for the linear plant (no step error: Phi and Gamma from one matrix exponential). The loop
is stable when every eigenvalue z of the closed-loop map lies inside the unit circle; a pole z
decays like exp(t ln|z| / h), so -ln(rho) / h (rho the spectral radius) is its equivalent
continuous decay rate (1/s), comparable with a continuous loop's pole margin. A hold of h lags
the command by about h / 2: on a spring-damper u = -(c v + k x) that is a damping c - k h / 2,
so a positive stiffness removes damping and, with h long enough, destabilises a loop whose
continuous version is stable.

`check` is what simulate calls for a controller with a period and a CasADi law: the verdict
goes into the Dataset's attrs["sampled_loop"] (the run record) and analysis.validity marks the result
invalid when the loop is unstable.
"""
from __future__ import annotations

import numpy as np

from ..lti import zoh
from . import diagnose
from .protocol import period_of, uses_state


def closed_loop_map(A, B, C, D, K, period: float) -> np.ndarray:
    """The closed-loop map of the sampled loop u_k = K (C x_k + D u_{k-1}) (see the module doc),
    on [x; u_{k-1}]; on x alone when K D = 0 (outputs without feedthrough, as positions and
    velocities)."""
    Phi, Gamma = zoh(A, B, period)
    K, C = np.atleast_2d(K), np.atleast_2d(C)
    D = np.zeros((C.shape[0], B.shape[1])) if D is None else np.atleast_2d(D)
    KC, KD = K @ C, K @ D
    if not np.any(KD):
        return Phi + Gamma @ KC
    return np.block([[Phi + Gamma @ KC, Gamma @ KD], [KC, KD]])


def verdict(z_poles, period: float, open_z=None, *, what: str = "the loop",
            strict: bool = False) -> dict:
    """Stability of a sampled loop from its poles z (JSON-ready).

    Keys: period_s; stable (every |z| < 1, and none beyond the unit circle that the open
    loop `open_z` lacks counts against it when `open_z` is given, as diagnose does for the
    continuous loop); spectral_radius; decay_rate_1_s, -ln(rho) / period (< 0: the loop grows
    e-fold in 1 / |rate| s); worst_pole (z, [re, im]) and its equivalent s = ln(z) / period
    (1/s); unstable_poles (z beyond the unit circle); message. strict: any |z| >= 1 is
    unstable (no tolerance, no open-loop comparison).
    """
    z = np.asarray(z_poles, complex)
    rho = float(np.max(np.abs(z), initial=0.0))
    rate = -np.log(rho) / period if rho > 0 else np.inf
    outside = z[np.abs(z) >= 1] if strict else _outside(z, period)
    stable = outside.size == 0
    if not stable and open_z is not None and not strict:   # the plant's own growth: not the loop's
        stable = _outside(np.asarray(open_z, complex), period).size >= outside.size
    worst = z[np.argmax(np.abs(z))] if z.size else 0j
    s = np.log(worst) / period if worst != 0 else complex(-np.inf)
    head = f"{what}, sampled at {period:g} s (zero-order hold)"
    if stable and outside.size:
        message = (f"{head}, adds no unstable mode to the plant's own (spectral radius "
                   f"{rho:.6g})")
    elif stable:
        message = (f"{head}, is stable: spectral radius {rho:.6g}, the slowest mode decays "
                   f"at {rate:.3g} 1/s")
    else:
        message = (f"{head}, is UNSTABLE: spectral radius {rho:.6g} > 1, a mode grows e-fold "
                   f"every {1 / max(-rate, 1e-300):.3g} s (z = {_z(worst)}, s = {_z(s)} 1/s); "
                   f"a shorter period, more damping or less stiffness cures it (a held "
                   f"spring -k x lags about period / 2: it removes a damping k period / 2)")
    return {"period_s": float(period), "stable": bool(stable), "spectral_radius": rho,
            "decay_rate_1_s": float(rate), "worst_pole": [float(worst.real), float(worst.imag)],
            "worst_pole_s": [float(s.real), float(s.imag)],
            "unstable_poles": [[float(p.real), float(p.imag)] for p in outside],
            "message": message}


def _outside(z, period):
    """The poles beyond the unit circle, with the tolerance diagnose uses on s = ln(z) / h
    (relative to the fastest pole: a rigid-body mode at z = 1 is not growth)."""
    z = z[np.abs(z) > 0]                     # a pole at z = 0 is a pure delay: no growth
    s = np.log(z) / period
    scale = max(1.0, float(np.max(np.abs(s), initial=0.0)))
    return z[s.real > diagnose.POLE_TOLERANCE * scale]


def _z(value) -> str:
    return f"{value.real:+.4g} {'+' if value.imag >= 0 else '-'} {abs(value.imag):.4g}i"


def check(plant, controller, p, dt: float):
    """The sampled-loop verdict (`verdict`) of a controller with a period and a static CasADi
    law, linearised at rest with parameters p; None when there is nothing to check (no
    controller, no period, no law, or full-state feedback)."""
    period = period_of(controller)
    if not period or uses_state(controller):
        return None
    law = diagnose.static_law(plant, controller)
    if law is None:
        return None
    try:
        A, Bu, C, Du, K = diagnose.law_loop(plant, law, p)
    except (RuntimeError, ValueError):       # a law CasADi cannot differentiate: no check
        return None
    closed = np.linalg.eigvals(closed_loop_map(A, Bu, C, Du, K, float(period)))
    open_z = np.exp(np.linalg.eigvals(A) * float(period))
    out = verdict(closed, float(period), open_z,
                  what=f"the closed loop with controller {diagnose.controller_name(controller)}")
    out["dt_s"] = float(dt)
    return out
