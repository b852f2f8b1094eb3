"""The controllers' common helpers. The Controller protocol they implement, with the optional
members the simulator and the exporters may use, is declared where the simulator lives
(`mbcontrol.sim.protocol`) and re-exported here. What a registered controller class states
about itself beyond it (its kind, tuned settings, tune(), ...) is the law protocol of
`controllers.law`.
"""
from __future__ import annotations

import numpy as np
from mbcontrol.errors import UnknownName
from mbcontrol.sim import Controller  # noqa: F401   (the protocol, re-exported)


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
