"""PTO force limits shared by every controller: per-PTO limits, saturation (numeric and
CasADi) and their report."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
from mbcontrol.errors import ControllerError

from .base import per_pto

# default stroke limit of a PTO whose scene sets none: this share of the range where linear
# hydrodynamics hold (analysis.validity's: 30 deg of roll or pitch; the mean draft of the
# shallowest surface-piercing body). Unlimited, an optimiser chases motions no linear model
# describes: measured on the OSWEC (JONSWAP Hs 2 m, Tp 10 s) the oracle MPC pitched the flap
# 85 deg and "absorbed" 130 % of the complex-conjugate bound, the AR one diverged 14 s after
# its warm-up (at 0.8 x 30 deg all three test seas run, stroke on the limit); flap_pair's
# jointly tuned reactive laws at T 4 s pitched the flaps 64 deg
LINEAR_RANGE_SHARE = 0.8


def force_limits(plant, force_max=None) -> np.ndarray:
    """Per-PTO force limit (N or N m, > 0, inf: none), scene order.

    force_max None: each scene PTO's own force_max on its machine (`command_limit`); a number:
    that limit on every PTO; a dict by PTO name: those PTOs' limits, the others keep their
    scene limit.
    """
    ptos = plant.scene.ptos
    limits = np.array([command_limit(p) for p in ptos], float)
    if isinstance(force_max, dict):
        per_pto(plant, force_max, "force_max")          # rejects unknown PTO names
        limits = np.array([float(force_max.get(p.name, command_limit(p))) for p in ptos])
    elif force_max is not None:
        limits = np.full(len(ptos), float(force_max))
    if not np.all(limits > 0):                           # NaN fails too
        raise ControllerError(f"{plant.name}: force_max must be > 0 (inf: none), got {limits}")
    return limits


def command_limit(pto) -> float:
    """The limit a scene PTO puts on the machine's force, the controller's command (N or N m):
    its force_max, or none (inf) when force_max_on = "hull" with a drivetrain, where the limit
    is on the force the drivetrain puts on the hull (the machine's less gear^2 (J a + b v +
    K x)),
    which a command clip does not bound: the tuners keep the predicted hull force inside it
    and the metrics check the simulated one."""
    return math.inf if pto.limited_force() == "hull" else float(pto.force_max)


def hull_limits(ptos, names, force_max=None) -> list:
    """The MPC's hull-force rows: (index in `names`, gear^2 J, gear^2 b, gear^2 K, limit) per
    PTO whose scene limit acts on the force its drivetrain puts on the hull; none when the
    controller is given its own force_max (a limit on the machine, its command)."""
    if force_max is not None:
        return []
    out = []
    for p in ptos:
        if p.limited_force() == "hull":
            d, g2 = p.drivetrain, p.drivetrain.gear_ratio ** 2
            out.append((names.index(p.name), g2 * d.inertia, g2 * d.friction,
                        g2 * d.stiffness, float(p.force_max)))
    return out


def saturate(u: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """u clipped to +-limits (inf limits leave u unchanged)."""
    return np.clip(u, -limits, limits)


def casadi_saturate(u, limits: np.ndarray):
    """The CasADi expression of `saturate`: fmin/fmax on the PTOs with a finite limit only,
    so a law without limits is the very expression it was before limits existed."""
    if np.all(np.isinf(limits)):
        return u
    return ca.vertcat(*[u[i] if math.isinf(f) else ca.fmin(ca.fmax(u[i], -f), f)
                        for i, f in enumerate(limits)])


def linear_law_parametric(plant, velocity, position, limits):
    """u = -(c v + k x) per PTO, saturated, with [c..., k...] as parameters: the passive law
    (k = 0) and the reactive law share it, so one compiled simulation chunk serves both, and
    every gain (sim.simulate embeds it). velocity, position: the PTOs' output indices."""
    n = len(velocity)
    y = ca.SX.sym("y", len(plant.outputs))
    g = ca.SX.sym("gains", 2 * n)
    u = -(g[:n] * y[velocity] + g[n:] * y[position])
    return ca.Function("linear_law_p", [y, g], [casadi_saturate(u, limits)])


def limits_report(limits) -> list | None:
    """describe()'s view of the force limits: one per PTO, None where there is none (JSON
    has no infinity); None before reset."""
    if limits is None:
        return None
    return [float(f) if math.isfinite(f) else None for f in limits]


def linear_range(plant, pto: str) -> float:
    """Default stroke limit (rad or m) of a PTO the scene leaves unlimited: LINEAR_RANGE_SHARE
    of the range where linear hydrodynamics hold ("validity.angle_max" for a rotary PTO, the
    shallowest body's mean draft for a linear one); inf without hydro data."""
    from mbcontrol import defaults
    from mbcontrol.analysis import mean_draft
    if plant.units(f"{pto}__position") == "rad":
        return LINEAR_RANGE_SHARE * defaults.get("validity.angle_max")
    data = plant.hydro.data if plant.hydro is not None else None
    if data is None or "body" not in data.coords:
        return math.inf
    drafts = [d for d in (mean_draft(data, str(b)) for b in data["body"].values) if d]
    return LINEAR_RANGE_SHARE * min(drafts) if drafts else math.inf


def per_pto_values(plant, value, scene_values, what) -> np.ndarray:
    """Per-PTO values of an MPC setting (limits, efficiency): the setting (a number, or a
    dict by PTO name) or the scene's; > 0."""
    if value is None:
        out = np.asarray(scene_values, float)
    elif isinstance(value, dict):    # the PTOs it names; the others keep the scene's value
        names = [p.name for p in plant.scene.ptos][:len(scene_values)]
        per_pto(plant, value, f"mpc {what}")                    # unknown names: KeyError
        out = np.array([float(value.get(n, s)) for n, s in zip(names, scene_values)])
    else:
        out = per_pto(plant, value, f"mpc {what}")[:len(scene_values)]
    if np.any(out <= 0):
        raise ControllerError(f"mpc: {what} must be > 0, got {out}")
    return out
