"""Checks of a freshly assembled plant at rest: what the scene forgot, and what will be stiff.

- A free body DOF with no restoring at all (no hydrostatics, mooring, PTO spring or end stop)
  drifts under any mean load and makes the linear model singular: warn, naming body and DOF.
- An end stop of stiffness k on a coordinate of inverse inertia (M⁻¹)_jj rings at
  ω = sqrt(k (M⁻¹)_jj) while engaged; explicit RK4 is stable only for ω dt < 2.785, so the
  plant records the largest stable step (simulate warns when dt exceeds it).
"""
from __future__ import annotations

import warnings

import casadi as ca
import numpy as np

RK4_STABILITY = 2.785  # RK4's stability interval on the imaginary axis, |ω dt| <= 2.785
NO_RESTORING = 1e-9    # relative to the largest stiffness entry


def rest_checks(scene, topo, q, s, u, w, chi, tau, M, params) -> dict:
    """Findings at rest (q = s = u = w = chi = 0, nominal parameters), returned as plant notes."""
    tree = topo.tree
    args = [np.zeros(tree.n_q), np.zeros(tree.n_s), np.zeros(u.shape[0]), np.zeros(w.shape[0]),
            np.zeros(chi.shape[0]), np.array(params.values) if params.names else np.zeros(0)]
    at_rest = ca.Function("at_rest", [q, s, u, w, chi, params.vector],
                          [-ca.jacobian(tau, q), M])
    stiffness, mass = (np.array(x) for x in at_rest(*args))
    notes = {"free_dofs_without_restoring": _unrestored(scene, tree, stiffness)}
    m_inv = np.linalg.inv(mass)
    stops = {}
    for stop in scene.end_stops:
        j = topo.coordinate_of_joint[stop.joint]
        omega = float(np.sqrt(stop.stiffness * m_inv[j, j]))
        stops[stop.name] = {"omega_rad_s": omega, "rk4_max_dt_s": RK4_STABILITY / omega}
    notes["end_stops"] = stops
    return notes


def _unrestored(scene, tree, stiffness) -> list[str]:
    scale = float(np.max(np.abs(stiffness), initial=0.0))
    found = []
    names = list(tree.coordinate_names)
    for joint in scene.joints:
        if joint.type != "free":
            continue
        for dof in joint.dofs:
            j = names.index(f"{joint.name}__{dof}")
            if np.max(np.abs(stiffness[:, j])) <= NO_RESTORING * scale:
                found.append(f"{joint.child}__{dof}")
                warnings.warn(
                    f"{scene.path}: body '{joint.child}' has no restoring in {dof} (free joint "
                    f"'{joint.name}'): no hydrostatics, mooring, PTO spring or end stop resists "
                    f"it, so it drifts under any mean load and its linear model is singular; "
                    f"add a mooring, or leave {dof} out of the joint's dofs",
                    RuntimeWarning, stacklevel=4)
    return found
