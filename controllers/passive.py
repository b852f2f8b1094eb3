"""Passive control: each PTO a linear damper, u = -damping * v (absorbed power c v^2 >= 0)."""
from __future__ import annotations

import casadi as ca
import numpy as np

from .base import per_pto, signal_indices


class Passive:
    """A linear damper on every PTO: u = -damping * v, the PTO's whole force.

    damping: N s/m (or N m s/rad) per PTO, one number for all, or a dict by PTO name. In
    closed loop the controller owns the PTO force (the scene's PTO law is set aside).
    """
    name = "passive"

    def __init__(self, damping=0.0, period: float | None = None):
        self.damping = damping
        self.period = period          # s; None: every simulation step
        self._gains = None
        self._law = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        self._gains = per_pto(plant, self.damping, "passive damping")
        if np.any(self._gains < 0):
            raise ValueError(f"passive damping must be >= 0, got {self._gains}")
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        self._law = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        return -self._gains * np.asarray(y)[self._velocity]

    def casadi_law(self, plant):
        if self._law is None:
            y = ca.SX.sym("y", len(plant.outputs))
            u = -ca.DM(self._gains) * y[self._velocity]
            self._law = ca.Function("passive_law", [y], [u])
        return self._law

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "period_s": self.period}


def optimal_damping(plant, wave, *, pto: str | None = None, params=None,
                    bounds=None) -> tuple[float, float]:
    """PTO damping that maximises the mean absorbed power in `wave`: (damping, power W).

    Evaluated on the frequency-domain solution built straight from the BEM data (linear
    theory: Coulomb friction is left out, as linear theory cannot hold it), with the PTO's
    force -damping * v alone, as in closed loop. For a regular wave or an irregular sea (sum
    over its components). bounds: search interval, N s/m or N m s/rad; default: 1e-3 to 1e3
    times the PTO's intrinsic impedance |Z_i| at the wave's most energetic component (the
    regular-wave optimum is |Z_i| itself), so the search fits a tank model and a 10 m buoy.
    """
    from scipy.optimize import minimize_scalar

    from mbcontrol.analysis import frequency_domain_response
    name = pto or plant.scene.ptos[0].name
    base = dict(params or {})
    for friction in plant.scene.frictions:
        base.setdefault(f"{friction.name}__coulomb", 0.0)
    for other in plant.scene.ptos:
        base.setdefault(f"{other.name}__damping", 0.0)
        base.setdefault(f"{other.name}__stiffness", 0.0)

    def power(damping: float) -> float:
        v = frequency_domain_response(plant, wave.omega, direction=wave.direction,
                                      params={**base, f"{name}__damping": damping},
                                      outputs=[f"{name}__velocity"])[:, 0]
        return float(np.sum(0.5 * damping * np.abs(v * wave.amplitude) ** 2))

    if bounds is None:
        from mbcontrol.bounds import pto_thevenin
        k = int(np.argmax(wave.amplitude))
        scale = float(np.abs(pto_thevenin(plant, wave.omega[k:k + 1], pto=name, direction=wave.direction,
                                          params=base, check_passive=False).impedance[0]))
        bounds = (1e-3 * scale, 1e3 * scale)
    result = minimize_scalar(lambda z: -power(np.exp(z)), method="bounded",
                             bounds=np.log(bounds), options={"xatol": 1e-4})
    return float(np.exp(result.x)), -float(result.fun)
