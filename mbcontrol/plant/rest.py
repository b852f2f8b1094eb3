"""Rest as an equilibrium: the static loads at rest, how far weight and buoyancy disagree along
each coordinate, and the PTO preloads (preload = "balance") that may hold the small remainder.

The measure. At rest (q = s = u = w = chi = 0) the generalised load r_j on coordinate j is what
is left of weight, buoyancy and the other static loads. Its scale is what the weight and the
buoyancy could do along j: W_j = sum_b m_b g |v_b,j| and B_j = sum_b rho g V_b |v'_b,j|, with
v_b,j (v'_b,j) the velocity of body b's CoG (centre of buoyancy) per unit velocity of j: the
weight and the buoyancy themselves for a heave coordinate (N), the weight and the buoyancy
times their lever arms about a hinge (N m). The imbalance is |r_j| / max(W_j, B_j).

Above IMBALANCE_TOL the scene is wrong (a mass, a draft, a BEM file mapped to the wrong body)
and a preload would only hide it: refused, with the weight, the buoyancy and the difference in
N and %. Below it a preload may balance it, and the amount balanced is recorded in the plant's
notes ("rest_balance") and said (console status).
"""
from __future__ import annotations

import warnings

import casadi as ca
import numpy as np

from .. import defaults
from ..console import status
from ..errors import SceneError

# What the catalogue needs balanced, measured by `balance_record` (share of the weight or
# buoyancy scale along the coordinate): wavestar 6.0e-2 (WECCCOMP's published masses: the float
# floats 12 % light and the dry arm hangs on the pivot; the motor holds the 1.13 N m left),
# the README tank buoy 4.4e-3 (its 4 cm mesh's volume), array_grid 1.9e-2 at its default
# parameters (its scene file says 0.5 %), oswec 9.8e-6 (its STL's centre of buoyancy 0.04 mm off the
# CoG line). 10 % keeps wavestar with a margin of 1.7 and still refuses a mass 10 % off or a
# wrong body (1.6 MN on the sphere: 38 % of its weight).
# IMBALANCE_TOL: the default "plant.imbalance_tol" (mbcontrol.defaults)
EQUILIBRIUM_TOL = 1e-9   # relative to the largest body weight: rest is an equilibrium
# ... and what is left below this share of the weight is not worth a warning: a BEM file's
# displaced volume printed to 7 digits (WEC-Sim's rm3.out: 6.5 N on 15.8 MN, 4e-7)
# EQUILIBRIUM_WARN: the default "plant.equilibrium_warn" (mbcontrol.defaults)


def _loads_at_rest(scene, topo, q, s, u, w, chi, tau, params):
    tree = topo.tree
    args = [np.zeros(tree.n_q), np.zeros(tree.n_s), np.zeros(u.shape[0]), np.zeros(w.shape[0]),
            np.zeros(chi.shape[0]), np.array(params.values) if params.names else np.zeros(0)]
    rest = ca.Function("rest", [q, s, u, w, chi, params.vector], [tau])
    return np.asarray(rest(*args)).ravel()


def _scales(scene, topo, buoyancy) -> tuple[np.ndarray, np.ndarray, dict]:
    """(W_j, B_j) per coordinate (module docs) and, per coordinate, the bodies it moves with
    their weight and buoyancy (N)."""
    tree = topo.tree
    q0 = ca.DM.zeros(tree.n_q)
    P = np.asarray(ca.Function("P", [], [tree.P(q0)])()["o0"])      # (n_s, 6 N)
    W, B, moved = np.zeros(tree.n_s), np.zeros(tree.n_s), {}
    g = scene.water.g
    for body in scene.bodies:
        k = topo.body_index(body.name)
        v, omega = P[:, 6 * k:6 * k + 3], P[:, 6 * k + 3:6 * k + 6]
        R = np.asarray(ca.Function("R", [], [tree.rotation(q0, k)])()["o0"])
        speed = np.linalg.norm(v, axis=1)
        W += body.mass * g * speed
        lift = 0.0
        if body.name in buoyancy:
            lift, centre = buoyancy[body.name]
            arm = R.T @ (np.asarray(centre, float) - np.asarray(body.cog, float))
            B += lift * np.linalg.norm(v + np.cross(omega, arm), axis=1)
        for j in np.flatnonzero(speed + np.linalg.norm(omega, axis=1) > 1e-12):
            moved.setdefault(int(j), []).append((body.name, body.mass * g, lift))
    return W, B, moved


def balance_record(scene, topo, residual, buoyancy) -> list[dict]:
    """Per coordinate with a static load at rest: the load (N or N m), its share of the weight
    or buoyancy scale, and the bodies it moves with their weight and buoyancy (N)."""
    W, B, moved = _scales(scene, topo, buoyancy)
    floor = EQUILIBRIUM_TOL * max([b.mass * scene.water.g for b in scene.bodies] + [1.0])
    out = []
    for j, name in enumerate(topo.tree.coordinate_names):
        if abs(residual[j]) <= floor:
            continue
        scale = max(W[j], B[j])
        out.append({"coordinate": name, "load": float(residual[j]), "weight_scale": float(W[j]),
                    "buoyancy_scale": float(B[j]),
                    "share": float(abs(residual[j]) / scale) if scale > 0 else float("inf"),
                    "bodies": [{"body": b, "weight_N": float(m), "buoyancy_N": float(lift)}
                               for b, m, lift in moved.get(j, [])]})
    return out


def _unit(scene, coordinate: str) -> str:
    """N for a sliding coordinate, N m for a turning one."""
    joint = next((j for j in scene.joints if j.name == coordinate.split("__")[0]), None)
    if joint is None:
        return "N or N m"
    if joint.type == "free":
        return "N m" if coordinate.split("__")[-1] in ("Roll", "Pitch", "Yaw") else "N"
    return "N m" if joint.type == "revolute" else "N"


def _describe(scene, entry) -> str:
    unit = _unit(scene, entry["coordinate"])
    bodies = "; ".join(
        f"{b['body']}: weight {b['weight_N']:.6g} N, buoyancy {b['buoyancy_N']:.6g} N, difference "
        f"{b['buoyancy_N'] - b['weight_N']:+.6g} N ({(b['buoyancy_N'] - b['weight_N']) / max(b['weight_N'], 1e-300):+.2%} "
        f"of the weight)" for b in entry["bodies"])
    return (f"{entry['coordinate']}: static load {entry['load']:.6g} {unit} at rest = {entry['share']:.2%} of "
            f"max(weight {entry['weight_scale']:.6g} {unit}, buoyancy {entry['buoyancy_scale']:.6g} {unit}) along it ({bodies})")


def preloads(scene, topo, parts, pto_signals, params, buoyancy):
    """Constant PTO forces that make rest an equilibrium (PTOs with preload = "balance"), as
    parameters <pto>__preload (N or N m) that identification may change, and the record of
    the imbalance (plant notes "rest_balance"). ``parts`` = (q, s, u, w, chi, tau).

    An imbalance above IMBALANCE_TOL is a SceneError whether or not a preload would hold it;
    rest that is still not an equilibrium (no preload, or one that cannot act on the
    coordinate) warns, naming the coordinates.
    """
    q, s, u, w, chi, tau = parts
    tree = topo.tree
    residual = _loads_at_rest(scene, topo, q, s, u, w, chi, tau, params)
    found = balance_record(scene, topo, residual, buoyancy)
    worst = max(found, key=lambda e: e["share"], default=None)
    balancing = [p for p in scene.ptos if p.preload == "balance"]
    # a dry body that falls (no buoyancy along the coordinate, no preload) is a pendulum, not an error
    if worst is not None and worst["share"] > defaults.get("plant.imbalance_tol") and (balancing or worst["buoyancy_scale"] > 0):
        raise SceneError(
            f"{scene.path}: weight and buoyancy do not balance at rest: {_describe(scene, worst)}; more than "
            f"{defaults.get('plant.imbalance_tol'):.0%}, which no preload may hide. Fix the [[body]] mass, or the draft / "
            f"geometry (the hydro data's displaced volume), or the mapping of the BEM file's bodies "
            f"([hydro] source_bodies)")
    extra = ca.SX.zeros(tree.n_s)
    record = {"imbalance": found, "tolerance": defaults.get("plant.imbalance_tol"), "preloads": {}}
    if balancing:
        d_fun = ca.Function("d", [q], [ca.horzcat(*[pto_signals[p.name][3] for p in balancing])])
        D = np.asarray(d_fun(np.zeros(tree.n_q)))
        f0, *_ = np.linalg.lstsq(D, -residual, rcond=None)
        for pto, value in zip(balancing, f0):
            sym = params.add(f"{pto.name}__preload", float(value))
            extra += pto_signals[pto.name][3] * sym
            record["preloads"][pto.name] = float(value)
        if found:
            say_once(f"{scene.name}: preload = \"balance\" holds rest: "
                      + ", ".join(f"{n} {v:.6g}" for n, v in record["preloads"].items())
                      + f" (N or N m) against {_describe(scene, worst)}")
        residual = residual + D @ f0
    _warn_left(scene, tree, residual)
    return extra, record


_SAID: set[str] = set()     # said-once messages of this process (messages, never results)


def say_once(message: str) -> None:
    """A status line once per process: a plant is assembled twice when its radiation fit is
    judged by the device's response (the device is the plant without radiation states)."""
    if message not in _SAID:
        _SAID.add(message)
        status(message, __name__)


def _buoyancy_source(scene) -> str:
    if scene.hydro.hydrostatics != "linear":
        return "the immersed volume of each body's geometry"
    return "the hydro data's displaced volume"


def _warn_left(scene, tree, residual):
    weight = sum(b.mass for b in scene.bodies) * scene.water.g
    floor = defaults.get("plant.equilibrium_warn") * max(1.0, max(b.mass for b in scene.bodies) * scene.water.g)
    if np.max(np.abs(residual), initial=0.0) <= floor:
        return
    worst = np.argsort(-np.abs(residual))[:3]
    listing = ", ".join(f"{tree.coordinate_names[i]}: {residual[i]:.4g}" for i in worst)
    warnings.warn(f"{scene.path}: rest is not an equilibrium; static generalised loads "
                  f"{listing} (N or N m; the largest is {abs(residual[worst[0]]) / weight:.2%} "
                  f"of the bodies' weight, {weight:.4g} N). Buoyancy ({_buoyancy_source(scene)}) "
                  f"and weight, or their centres, do not balance: a mesh "
                  f"that lost volume, a mass or CoG that is not the floating one. Correct "
                  f"them, or give the PTO preload = \"balance\" (a constant PTO force that "
                  f"holds rest)", RuntimeWarning, stacklevel=4)
