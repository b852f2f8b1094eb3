"""Passive control: each PTO a linear damper, u = -damping * v (absorbed power c v^2 >= 0)."""
from __future__ import annotations

import casadi as ca
import numpy as np

from .base import signal_indices


class Passive:
    """A damper on every PTO of the plant.

    damping: N s/m (or N m s/rad) per PTO, one number for all, or a dict by PTO name. The
    force is added to the PTO's own scene damping and stiffness.
    """
    name = "passive"

    def __init__(self, damping=0.0, period: float | None = None):
        self.damping = damping
        self.period = period          # s; None: every simulation step
        self._gains = None
        self._law = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        gains = self.damping if isinstance(self.damping, dict) else {n: self.damping
                                                                     for n in names}
        unknown = set(gains) - set(names)
        if unknown:
            raise KeyError(f"{plant.name}: passive damping for unknown PTO(s) {sorted(unknown)}")
        self._gains = np.array([float(gains.get(n, 0.0)) for n in names])
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
