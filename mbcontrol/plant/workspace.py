"""A plant's workspace (Pinocchio's Data, Drake's Context cache): what later stages derive
from a plant, its Jacobians, compiled steps and chunks, excitation coefficients and port
responses, hangs off the plant itself. It lives exactly as long as the plant: `del plant`
frees it, compiled code included, and a plant copied with `dataclasses.replace` starts
with an empty one (its equations may differ)."""
from __future__ import annotations

from typing import Any, Callable


def derived(plant, key: tuple, build: Callable[[], Any]):
    """The plant's value for `key`, made by `build()` on first use and kept with the plant.

    key: a hashable tuple whose first item names the deriving module (e.g. ("sim.batch",
    method, length)), so that two modules' keys never meet."""
    space = plant.workspace
    if key not in space:
        space[key] = build()
    return space[key]

