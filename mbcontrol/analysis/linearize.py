"""Exact linearisation of a ProcessPlant into a named python-control StateSpace.

The model is in deviation coordinates about an operating point (x0, u0, w0, p), which must be
an equilibrium: f(x0, u0, w0, p) = 0 to within `tol`, by default EQUILIBRIUM_SHARE of gravity
(m/s^2, rad/s^2: a load left at rest of that share of a body's weight; a BEM file's displaced
volume printed to 7 digits leaves 4e-7). Jacobians are CasADi's exact ones, built
once per plant. Note that a smoothed Coulomb friction linearises to its slope at v = 0,
coulomb / velocity_scale; pass params={"<friction>__coulomb": 0} to leave it out.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .. import defaults
from ..errors import LinearizationError
from ..plant import jacobians

if TYPE_CHECKING:       # python-control costs 2.5 s to import: only where it is used
    import control


# EQUILIBRIUM_SHARE: the default "linearize.equilibrium_share" (mbcontrol.defaults)


def linearize(plant, *, x0=None, u0=None, w0=None, params=None, inputs=None, outputs=None,
              tol: float | None = None) -> control.StateSpace:
    """Linear model about an equilibrium, with the plant's signal names.

    inputs/outputs: names to keep (default: every u and w; every output). params: dict of
    overrides or a full vector. Raises LinearizationError when the point is not an equilibrium
    or a name is unknown.
    """
    import control
    x0 = plant.x0() if x0 is None else np.asarray(x0, float)
    u0 = np.zeros(len(plant.inputs)) if u0 is None else np.asarray(u0, float)
    w0 = np.zeros(len(plant.disturbances)) if w0 is None else np.asarray(w0, float)
    p = plant.params(**params) if isinstance(params, dict) else (
        plant.p0 if params is None else np.asarray(params, float))
    g = plant.scene.water.g
    tol = defaults.get("linearize.equilibrium_share") * g if tol is None else tol
    residual = np.asarray(plant.f(x0, u0, w0, p)).ravel()
    if np.max(np.abs(residual), initial=0.0) > tol:
        worst = np.argsort(-np.abs(residual))[:3]
        listing = ", ".join(f"{plant.states[i]}' = {residual[i]:.3g} ({residual[i] / g:.2g} g)"
                            for i in worst)
        raise LinearizationError(f"{plant.name}: the operating point is not an equilibrium "
                                 f"(largest residuals: {listing}; tolerance {tol:.3g}, "
                                 f"{tol / g:.2g} of gravity): weight and buoyancy, or the "
                                 f"static loads, do not balance there")
    A, Bu, Bw, C, Du, Dw = (np.asarray(M) for M in jacobians(plant)(x0, u0, w0, p))
    all_inputs = list(plant.inputs) + list(plant.disturbances)
    B, D = np.hstack([Bu, Bw]), np.hstack([Du, Dw])
    keep_in = _indices(plant, all_inputs, inputs, "input")
    keep_out = _indices(plant, list(plant.outputs), outputs, "output")
    return control.ss(A, B[:, keep_in], C[keep_out], D[np.ix_(keep_out, keep_in)],
                      states=list(plant.states), inputs=[all_inputs[i] for i in keep_in],
                      outputs=[plant.outputs[i] for i in keep_out], name=plant.name)


def _indices(plant, names, wanted, kind):
    if wanted is None:
        return list(range(len(names)))
    missing = [n for n in wanted if n not in names]
    if missing:
        raise LinearizationError(f"{plant.name}: unknown {kind}(s) {missing}; expected some "
                                 f"of {', '.join(names)}")
    return [names.index(n) for n in wanted]
