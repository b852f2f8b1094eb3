"""The Controller protocol: what `simulate` needs from a PTO controller.

A controller is bound to a plant by `reset(plant)` (it looks up the signals it measures by
name), then called as `controller(t, y) -> u` every `period` seconds with the plant's output
vector y; u (one force or torque per PTO, N or N m) is held until the next call (zero-order
hold). In closed loop u is the PTO's whole force: the scene's PTO law is set aside. A controller whose law is a static CasADi expression of y may also return it from
`casadi_law(plant)`; with period equal to the simulation step it then runs inside compiled code.
A controller with the attribute `uses_state = True` is called as `controller(t, y, x)` with the
plant's whole state x as well: full-state feedback, an oracle for studies (no real device
measures radiation states), which its describe() must say.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from mbcontrol.errors import UnknownName


@runtime_checkable
class Controller(Protocol):
    name: str
    period: float | None   # s, zero-order-hold period; None: every simulation step

    def reset(self, plant) -> None: ...

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray: ...

    def casadi_law(self, plant): ...

    def describe(self) -> dict: ...


def signal_indices(plant, names: list[str]) -> list[int]:
    """Indices of named outputs, with an error that lists what the plant offers."""
    missing = [n for n in names if n not in plant.outputs]
    if missing:
        raise UnknownName(f"{plant.name}: no output(s) {missing}; outputs are "
                          f"{', '.join(plant.outputs)}")
    return [plant.outputs.index(n) for n in names]


def per_pto(plant, value, what: str) -> np.ndarray:
    """One gain per PTO (scene order) from a number for all or a dict by PTO name."""
    names = [p.name for p in plant.scene.ptos]
    gains = value if isinstance(value, dict) else {n: value for n in names}
    unknown = set(gains) - set(names)
    if unknown:
        raise UnknownName(f"{plant.name}: {what} for unknown PTO(s) {sorted(unknown)}")
    return np.array([float(gains.get(n, 0.0)) for n in names])
