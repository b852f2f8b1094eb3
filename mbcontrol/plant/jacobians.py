"""Exact Jacobians of a ProcessPlant (CasADi), built once per plant and shared by every user:
linearisation, frequency responses, fidelity checks and stability limits."""
from __future__ import annotations

import casadi as ca

from .workspace import derived


def jacobians(plant) -> ca.Function:
    """(x, u, w, p) -> (A, B_u, B_w, C, D_u, D_w), built once per plant."""
    return derived(plant, ("plant.jacobians",), lambda: _jacobians(plant))


def _jacobians(plant) -> ca.Function:
    x = ca.SX.sym("x", plant.nx)
    u, w = ca.SX.sym("u", len(plant.inputs)), ca.SX.sym("w", len(plant.disturbances))
    p = ca.SX.sym("p", len(plant.p0))
    f, h = plant.f(x, u, w, p), plant.h(x, u, w, p)
    outs = [ca.jacobian(f, x), ca.jacobian(f, u), ca.jacobian(f, w),
            ca.jacobian(h, x), ca.jacobian(h, u), ca.jacobian(h, w)]
    return ca.Function("jacobians", [x, u, w, p], outs)
