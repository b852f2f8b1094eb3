"""Where methods fail: the largest stable step of each integration method on a plant.

Two independent routes:
  - `linear_stability_limit`: the spectral radius of the linearised one-step map
    G(h) = d x_{n+1} / d x_n at rest (CasADi's exact Jacobian of the compiled step), found by
    bisection on rho(G(h)) <= 1. For a linear plant this is the exact limit; it sees fast
    radiation poles and stiff joints, but not switching loads.
  - `stability_limit`: bisection on dt over simulated runs (waves, controller, end stops and
    all), stable meaning the run finished without SimulationError (non-finite state or
    energy beyond the input). It sees everything the simulation does.
`stability_table` runs both over methods and the scenarios that stiffen the equations:
a tighter radiation fit (more, faster poles), an end stop, and latching control.
"""
from __future__ import annotations

import dataclasses
import warnings

import casadi as ca
import numpy as np

from ..console import progress_bar
from ..errors import SimulationError
from ..plant import derived
from . import integrators

def _step_jacobian(plant, method: str):
    """(d x_next / d x as a Function of the step's inputs, the step)."""
    step = integrators.step_function(plant, method)
    args = [ca.SX.sym(step.name_in(i), step.sparsity_in(i)) for i in range(step.n_in())]
    return ca.Function("G", args, [ca.jacobian(step(*args)[0], args[0])]), step


def step_map_radius(plant, method: str, dt: float, params=None, x=None, u=None) -> float:
    """Spectral radius of the one-step map linearised at (x, u) (default rest, u = 0; w = 0),
    step dt (s). (x, u) should be an equilibrium (see `held_equilibrium`)."""
    jac, step = derived(plant, ("sim.step_jacobian", method), lambda: _step_jacobian(plant, method))
    p = plant.p0 if params is None else (plant.params(**params) if isinstance(params, dict)
                                         else np.asarray(params, float))
    extras = [ca.DM(step.sparsity_in(5 + i), e) for i, e in
              enumerate(integrators.step_extras(plant, method, dt))]
    W = np.zeros(step.size_in(2))
    x = plant.x0() if x is None else np.asarray(x, float)
    u = np.zeros(len(plant.inputs)) if u is None else np.asarray(u, float)
    G = np.array(jac(x, u, W, p, dt, *extras))
    return float(np.max(np.abs(np.linalg.eigvals(G)))) if G.size else 0.0


def linear_stability_limit(plant, method: str, dt_max: float, params=None,
                           rel_tol: float = 1e-3, x=None, u=None) -> float:
    """Largest dt <= dt_max (s) with rho(G(dt)) <= 1 + 1e-9; dt_max if none fails.

    Scans a geometric ladder up from dt_max / 1e4 for the first unstable step, then bisects:
    the stable set of an explicit method is an interval from 0 for the modes a plant has.
    """
    def stable(h):
        return step_map_radius(plant, method, h, params, x, u) <= 1 + 1e-9

    ladder = dt_max * 2.0 ** -np.arange(14, -1, -1)
    lo = None
    for h in ladder:
        if not stable(h):
            break
        lo = h
    else:
        return dt_max
    if lo is None:
        raise SimulationError(f"{plant.name}: method {method!r} is unstable even at "
                              f"dt = {ladder[0]:.3g} s at rest; check the model's eigenvalues")
    hi = 2 * lo
    while hi - lo > rel_tol * lo:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


def held_equilibrium(plant, coordinate: str, value: float):
    """(x, u): the plant at rest but for `coordinate` = value (m or rad), held there by the
    PTO commands u (least squares); None if the PTOs cannot hold it. The step map is then
    linearised at an equilibrium, e.g. with an end stop engaged."""
    from ..plant import jacobians
    x = plant.x0()
    x[plant.states.index(coordinate)] = value
    zeros_u, zeros_w = np.zeros(len(plant.inputs)), np.zeros(len(plant.disturbances))
    f0 = np.asarray(plant.f(x, zeros_u, zeros_w, plant.p0)).ravel()
    B_u = np.array(jacobians(plant)(x, zeros_u, zeros_w, plant.p0)[1])
    u, *_ = np.linalg.lstsq(B_u, -f0, rcond=None)       # f is affine in u
    residual = np.asarray(plant.f(x, u, zeros_w, plant.p0)).ravel()
    if np.max(np.abs(residual)) > 1e-8 * max(1.0, np.max(np.abs(f0))):
        return None
    return x, u


def stability_limit(plant, method: str, wave=None, *, duration: float, dt_lo: float,
                    dt_hi: float, controller=None, params=None, x0=None,
                    rel_tol: float = 0.02) -> tuple[float, float]:
    """(largest stable dt, smallest unstable dt) in s, by bisection on simulated runs.

    dt_lo must give a stable run; dt_hi an unstable one (if it is stable, (dt_hi, inf) is
    returned). The controller, if any, is sampled every step. A run counts as unstable when
    simulate raises SimulationError: a slowly growing instability that stays within the
    audit's bounds for `duration` s is missed, so the limit found is an upper estimate.
    """
    def stable(h):
        if controller is not None:
            controller.period = h
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                simulate_fn(plant, wave, duration=duration, dt=h, method=method,
                            controller=controller, params=params, x0=x0)
            return True
        except SimulationError:
            return False

    from .run import simulate as simulate_fn
    if not stable(dt_lo):
        raise SimulationError(f"{plant.name}: method {method!r} already fails at dt_lo = "
                              f"{dt_lo:g} s; give a smaller dt_lo")
    if stable(dt_hi):
        return dt_hi, np.inf
    lo, hi = dt_lo, dt_hi
    while hi / lo > 1 + rel_tol:
        mid = np.sqrt(lo * hi)                        # bisect in log: limits span decades
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo, hi


def _tighter_fit(scene, plant, tol: float):
    """(name, plant, None) for the first of tol, tol/5, tol/25 whose fit has more radiation
    states than the scene's (more and faster poles); None if none has."""
    from ..plant import build_plant
    for t in (tol, tol / 5, tol / 25):
        tight = build_plant(scene, radiation_tol=t)
        if tight.nx > plant.nx:
            return (f"radiation tol {t:g}", tight, None)
    return None


def with_end_stop(scene, joint: str, travel: float, stiffness: float):
    """The scene with a symmetric end stop at +-travel (m or rad) on `joint`: a stiff,
    one-sided spring (N/m or N m/rad) engaged only beyond the travel."""
    from ..scene import EndStop
    stop = EndStop(name=f"{joint}_stop", joint=joint, lower=-travel, upper=travel,
                   stiffness=stiffness)
    return dataclasses.replace(scene, end_stops=scene.end_stops + (stop,))


def stability_table(scene, wave, *, methods=("rk3", "rk4", "dopri5", "exp-rk4"),
                    duration: float = 60.0, dt_hi: float | None = None,
                    end_stop: tuple[str, float, float] | None = None, latching=None,
                    tight_radiation_tol: float | None = None, progress: bool = False) -> list:
    """Largest stable step per method and scenario, by linear analysis and by search.

    Scenarios: "scene" (as given), "radiation tol X" (the first of tight_radiation_tol, /5,
    /25 that adds states: more, faster poles), "end stop" (end_stop = (joint, travel,
    stiffness), engaged by the wave; linear analysis at 1.5 x travel, held by the PTO), and
    one named after the controller `latching` (a controllers.Latching, sampled every step; no
    linear analysis: it switches). dt_hi: the largest step tried
    (default: a quarter of the wave's period). Rows are dicts: scenario, method, states,
    linear_limit_s (None where the analysis does not apply), stable_s, unstable_s.
    """
    from ..plant import build_plant
    from ..scene import load_scene
    scene = load_scene(scene) if isinstance(scene, str) else scene
    dt_hi = dt_hi or wave.period / 4
    scenarios = [("scene", build_plant(scene), None)]
    if tight_radiation_tol:
        tight = _tighter_fit(scene, scenarios[0][1], tight_radiation_tol)
        if tight is not None:
            scenarios.append(tight)
    if end_stop:
        scenarios.append(("end stop", build_plant(with_end_stop(scene, *end_stop)), None))
    if latching is not None:
        scenarios.append((latching.name, scenarios[0][1], latching))
    rows, jobs = [], [(s, m) for s in scenarios for m in methods]
    bar = None
    if progress:
        bar = progress_bar(total=len(jobs), desc="stability", leave=False)
    for (name, plant, controller), method in jobs:
        linear = None                     # switching control: no linear analysis applies
        if name == "end stop":            # the step map with the stop engaged, held there
            held = held_equilibrium(plant, end_stop[0], 1.5 * end_stop[1])
            if held is not None:
                linear = linear_stability_limit(plant, method, dt_hi, x=held[0], u=held[1])
        elif controller is None:
            linear = linear_stability_limit(plant, method, dt_hi)
        stable, unstable = stability_limit(plant, method, wave, duration=duration,
                                           dt_lo=dt_hi / 256, dt_hi=dt_hi,
                                           controller=controller)
        rows.append({"scenario": name, "method": method, "states": plant.nx,
                     "linear_limit_s": linear, "stable_s": stable, "unstable_s": unstable})
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    return rows
