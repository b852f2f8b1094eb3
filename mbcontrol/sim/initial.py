"""Initial states for free decays and other runs that do not start at rest.

A joint coordinate is given by its name (`plant.topology.tree.coordinate_names`: a one-
coordinate joint's name, "heave"; a free joint's "<body>__Heave"), along the joint's axis in
the scene's frames (NED: a prismatic joint along +z moves the body down, into the water), as a
number in SI units or a string with its unit ("0.5 m", "10 deg"). Everything else starts at
rest: velocities zero, radiation states zero (the fluid at rest).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..scene import UnitError, to_si

_ANGLES = ("Roll", "Pitch", "Yaw")
_LENGTHS = ("Surge", "Sway", "Heave")


def coordinate_dimension(plant, name: str) -> str:
    """"length" or "angle": the dimension of the joint coordinate `name`."""
    joints = {j.name: j for j in plant.scene.joints}
    if name in joints:
        return "length" if joints[name].type == "prismatic" else "angle"
    return "angle" if name.rsplit("__", 1)[-1] in _ANGLES else "length"


def initial_state(plant, coordinates: dict) -> np.ndarray:
    """The rest state (plant.x0) with the named joint coordinates set (module docs); an
    InputError names an unknown coordinate, a value of the wrong dimension, or one outside
    +-pi rad for an angle (a decay starts within one turn)."""
    names = list(plant.topology.tree.coordinate_names)
    x0 = plant.x0().copy()
    for name, value in coordinates.items():
        if name not in names:
            raise InputError(f"--initial {name}: not a joint coordinate of {plant.name}; its "
                             f"coordinates are {', '.join(names)}")
        dimension = coordinate_dimension(plant, name)
        try:
            number = to_si(value, dimension)
        except UnitError as exc:
            raise InputError(f"--initial {name}: {exc} ({dimension}, SI unit "
                             f"{'m' if dimension == 'length' else 'rad'})") from None
        if not np.isfinite(number) or (dimension == "angle" and abs(number) > np.pi):
            raise InputError(f"--initial {name}: expected a finite {dimension}"
                             + (" within +-pi rad (+-180 deg)" if dimension == "angle" else "")
                             + f", got {value!r}")
        x0[plant.states.index(name)] = number
    return x0


def describe_initial(plant, coordinates: dict) -> dict:
    """{coordinate: {"value", "unit", "direction"}} of a run's initial coordinates, SI, with
    the sign convention of each (what the JSON and the text summary say)."""
    out = {}
    x0 = initial_state(plant, coordinates)
    for name in coordinates:
        dimension = coordinate_dimension(plant, name)
        out[name] = {"value": float(x0[plant.states.index(name)]),
                     "unit": "m" if dimension == "length" else "rad",
                     "direction": _direction(plant, name)}
    return out


def _direction(plant, name: str) -> str:
    joint = next((j for j in plant.scene.joints if j.name == name), None)
    axis = getattr(joint, "axis", None)
    if joint is None or axis is None:
        return ("about the body's own axis (ZYX Euler angle)" if name.endswith(_ANGLES)
                else "along the n-frame axis (NED: x forward, y starboard, z down)")
    a = ", ".join(f"{float(v):.3g}" for v in axis)
    if joint.type == "prismatic":
        down = " (NED: + is down, into the water)" if np.allclose(axis, [0, 0, 1]) else \
            " (NED: + is up, out of the water)" if np.allclose(axis, [0, 0, -1]) else ""
        return f"along the joint axis ({a}){down}"
    return f"about the joint axis ({a}), right-handed"
