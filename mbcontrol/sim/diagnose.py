"""Why did a closed-loop run diverge: the time step, or the loop itself?

A run that blows up with a controller in the loop has two possible causes with opposite
remedies: the integration step (numerical instability: a smaller dt or another method cures
it) or the closed loop (physical instability: the controller destabilises the device, and no
step cures it). `explainer` returns the function simulate's checks call on a divergence; it
decides, in this order:

1. A controller with a static CasADi law of the outputs (`casadi_law`: passive, reactive,
   ...): the plant's exact Jacobians at rest (mbcontrol.plant.jacobians, the plant's own
   CasADi functions) with the law closed around them, A_cl = A + B_u (I - K D_u)^-1 K C,
   K = d law / d y at rest. A pole with Re > POLE_TOLERANCE (relative to the fastest) that the
   open loop (no command) does not have makes the controller the cause.
2. Otherwise, or when that loop is stable: the run is repeated at half the step up to a
   little past the divergence. Diverging again at about the same time (within RERUN_MARGIN
   of it) is physical: a numerical instability moves, or vanishes, with the step.

It returns a sentence naming the controller as the cause (with the pole, 1/s, when known),
or None when the step is to blame (the caller keeps its time-step remedy).
"""
from __future__ import annotations

import contextvars

import casadi as ca
import numpy as np

from .protocol import name_of

POLE_TOLERANCE = 1e-6        # Re(pole) above this times max(1, |fastest pole|), 1/s: unstable
RERUN_MARGIN = 0.5           # the half-step rerun diverging before (1 + this) t_fail: physical
RERUN_EXTRA_S = 5.0          # ... or within this many seconds of it

_RERUN = contextvars.ContextVar("mbcontrol_sim_diagnose_rerun", default=False)


def controller_name(controller) -> str:
    return repr(name_of(controller))


def law_loop(plant, law, p, x=None):
    """(A, B_u, C, D_u, K): the plant's exact Jacobians at x (default: rest, no command,
    still water) and K = d law / d y there (u = K y), for the continuous loop here and the
    sampled one (sim.sampled)."""
    from ..plant import jacobians
    x = plant.x0() if x is None else np.asarray(x, float)
    nu, nw = len(plant.inputs), len(plant.disturbances)
    u0, w0 = np.zeros(nu), np.zeros(nw)
    A, Bu, _, C, Du, _ = (np.asarray(M) for M in jacobians(plant)(x, u0, w0, p))
    y0 = np.asarray(plant.h(x, u0, w0, p)).ravel()
    ys = ca.SX.sym("y", y0.size)
    K = np.asarray(ca.Function("dlaw", [ys], [ca.jacobian(law(ys), ys)])(y0))
    return A, Bu, C, Du, K.reshape(nu, y0.size)


def closed_loop_poles(plant, law, p, x=None) -> tuple[np.ndarray, np.ndarray]:
    """(closed-loop poles, open-loop poles), 1/s: the plant linearised at x (default: rest,
    no command, still water) with u = law(y) closed around it and without it."""
    A, Bu, C, Du, K = law_loop(plant, law, p, x)
    closed = A + Bu @ np.linalg.solve(np.eye(Bu.shape[1]) - K @ Du, K @ C)
    return np.linalg.eigvals(closed), np.linalg.eigvals(A)


def unstable(poles) -> np.ndarray:
    """The poles in the right half-plane (beyond POLE_TOLERANCE of the fastest)."""
    poles = np.asarray(poles)
    scale = max(1.0, float(np.max(np.abs(poles), initial=0.0)))
    return poles[poles.real > POLE_TOLERANCE * scale]


def explainer(plant, wave, controller, p, x0, dt, method, duration, simulate=None):
    """The function (t_fail s -> message or None) simulate's checks call when a run
    diverges; None (no diagnosis) for open-loop runs and inside a diagnostic rerun.
    simulate: the function that reruns the run at half the step (simulate passes itself;
    None: no rerun)."""
    if controller is None or _RERUN.get():
        return None

    def explain(t_fail: float):
        try:
            return _explain(plant, wave, controller, p, x0, dt, method, duration,
                            float(t_fail), simulate)
        except Exception:                    # noqa: BLE001 - a diagnosis never hides the error
            return None
    return explain


def _explain(plant, wave, controller, p, x0, dt, method, duration, t_fail, simulate):
    who = f"controller {controller_name(controller)}"
    law = static_law(plant, controller)
    if law is not None:
        closed, open_ = closed_loop_poles(plant, law, p)
        bad = unstable(closed)
        if bad.size and unstable(open_).size < bad.size:
            pole = bad[np.argmax(bad.real)]
            return (f"the closed loop with {who} is unstable (pole at {_pole(pole)} 1/s, "
                    f"growing e-fold every {1 / pole.real:.3g} s; the plant alone is stable), "
                    f"so no time step cures it. Remedy: a stable setting of {who} (e.g. less "
                    f"negative stiffness; controllers.reactive.closed_loop_stability or "
                    f"`mbcontrol design` check it before simulating)")
    if simulate is None:
        return None
    t_half = _rerun_half_step(simulate, plant, wave, controller, p, x0, dt, method, duration,
                              t_fail)
    if t_half is not None and t_half <= max((1 + RERUN_MARGIN) * t_fail, t_fail + RERUN_EXTRA_S):
        return (f"the closed loop with {who} is unstable: the run diverges again at "
                f"t = {t_half:.4g} s with half the step (dt = {dt / 2:g} s), so the step is "
                f"not the cause. Remedy: the settings of {who} (its gains, limits or "
                f"forecast), not a smaller dt")
    return None


def static_law(plant, controller):
    try:
        return controller.casadi_law(plant)
    except Exception:                        # noqa: BLE001 - no law, no linear check
        return None


def _rerun_half_step(simulate, plant, wave, controller, p, x0, dt, method, duration, t_fail):
    """When the run at dt / 2 diverges (s), or None if it does not (or cannot be rerun)."""
    from ..errors import SimulationError
    half = dt / 2
    end = min(duration, max((1 + RERUN_MARGIN) * t_fail, t_fail + RERUN_EXTRA_S))
    end = max(half, round(end / dt) * dt)
    token = _RERUN.set(True)
    try:
        simulate(plant, wave, duration=end, dt=half, controller=controller, method=method,
                 x0=x0, params=p)
    except SimulationError as exc:
        return getattr(exc, "t_fail", end)
    except (ValueError, RuntimeError):      # e.g. a controller period dt / 2 cannot divide
        return None
    finally:
        _RERUN.reset(token)
    return None


def _pole(pole) -> str:
    if abs(pole.imag) < 1e-12 * max(1.0, abs(pole)):
        return f"{pole.real:+.4g}"
    return f"{pole.real:+.4g} {'+' if pole.imag >= 0 else '-'} {abs(pole.imag):.4g}i"
