"""Who owns a PTO's force: the one rule every stage applies when a controller commands a
PTO (simulate, the control plant, the linear views and bounds, the tuners, the export).

A scene's PTO law (`<pto>__damping`, `<pto>__stiffness`) is the PTO's passive default. A
controller that commands the PTO replaces it, so the law is zero, unless the caller's
`params` sets it: then it is a physical damper or spring in parallel with the controller,
and every stage keeps it (the tuners tune the controller's force on top of it). Two views
override `params` whatever it says:

- `whole`: PTOs whose whole force is the decision variable (the power bounds, the optimal
  impedance): their law is zero, because such a bound is over the PTO's total force, law
  included;
- `linear=True`: Coulomb friction is zero (its smoothed slope at rest is not linear
  physics).
"""
from __future__ import annotations

import numpy as np


def controlled_params(plant, params=None, *, ptos=None, whole=(), linear: bool = False) -> dict:
    """Parameter overrides for `plant` with a controller commanding `ptos` (names; default
    every PTO). params: the caller's overrides (a dict, or a full parameter vector), which win
    except as `whole` and `linear` say (module docstring). Returns a dict for
    `plant.params(**...)`."""
    if params is not None and not isinstance(params, dict):
        params = dict(zip(plant.parameters, np.asarray(params, float)))
    out = dict(params or {})
    names = [pto.name for pto in plant.scene.ptos] if ptos is None else list(ptos)
    for name in names:
        out.setdefault(f"{name}__damping", 0.0)
        out.setdefault(f"{name}__stiffness", 0.0)
    for name in whole:
        out[f"{name}__damping"] = 0.0
        out[f"{name}__stiffness"] = 0.0
    if linear:
        for friction in plant.scene.frictions:
            out[f"{friction.name}__coulomb"] = 0.0
    return out


def linear_params(plant, ptos, params=None) -> dict:
    """Linear theory seen from `ptos`, whose whole forces are the decision variables: their
    own damping and stiffness zero, Coulomb friction removed, `params` (dict or full vector)
    kept for everything else (the other PTOs keep their scene law unless params sets it)."""
    return controlled_params(plant, params, ptos=ptos, whole=ptos, linear=True)
