"""Quantities in scene files: plain SI numbers, or strings such as "60 mm" or "5 deg".

A string must carry a unit of the dimension the field expects; "3 kg" where a length is due is
an error, never a silent conversion.
"""
from __future__ import annotations

import math
import re

# dimension -> {unit: factor to SI}
UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "km": 1e3},
    "mass": {"kg": 1.0, "g": 1e-3, "t": 1e3},
    "angle": {"rad": 1.0, "deg": math.pi / 180.0},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "frequency": {"rad/s": 1.0, "Hz": 2 * math.pi},
    "density": {"kg/m^3": 1.0, "kg/m3": 1.0},
    "acceleration": {"m/s^2": 1.0, "m/s2": 1.0},
    "inertia": {"kg*m^2": 1.0, "kg m^2": 1.0, "kg*m2": 1.0},
    "force": {"N": 1.0, "kN": 1e3, "MN": 1e6},
    "moment": {"N m": 1.0, "N*m": 1.0, "Nm": 1.0, "kN m": 1e3, "kN*m": 1e3, "kNm": 1e3,
               "MN m": 1e6, "MN*m": 1e6, "MNm": 1e6},
    "current": {"A": 1.0, "mA": 1e-3, "kA": 1e3},
    "voltage": {"V": 1.0, "mV": 1e-3, "kV": 1e3},
    "resistance": {"ohm": 1.0, "mohm": 1e-3, "kohm": 1e3},
    "inductance": {"H": 1.0, "mH": 1e-3, "uH": 1e-6},
    "power": {"W": 1.0, "kW": 1e3, "MW": 1e6},
}
# a joint coordinate: a length (prismatic) or an angle (revolute), where the joint is not known
UNITS["coordinate"] = {**UNITS["length"], **UNITS["angle"]}
# a joint's generalised coordinate and force, by joint type (PTO limits, end stops)
JOINT_DIMENSIONS = {"prismatic": ("length", "force"), "revolute": ("angle", "moment")}

SI_UNIT = {
    "length": "m", "mass": "kg", "angle": "rad", "time": "s", "frequency": "rad/s",
    "density": "kg/m^3", "acceleration": "m/s^2", "inertia": "kg*m^2", "coordinate": "m or rad",
    "force": "N", "moment": "N m", "current": "A", "voltage": "V", "resistance": "ohm",
    "inductance": "H", "power": "W",
}

# The largest magnitude (SI) a finite value of each dimension may take: far past any device (the
# largest floating structures weigh ~6e8 kg; the deepest sea is 11 km), so only a slip of
# units or orders of magnitude, or a hostile file, is refused, by the field that holds it
# rather than later as a "diverged: try a smaller time step". Infinity stays for the fields
# that mean "none" by it (depth = inf: deep water).
PHYSICAL_MAX = {
    "length": 1e5, "mass": 1e10, "angle": 1e3, "time": 1e7, "frequency": 1e4, "density": 1e5,
    "acceleration": 1e3, "inertia": 1e16, "coordinate": 1e5, "force": 1e11, "moment": 1e13,
    "current": 1e6, "voltage": 1e7, "resistance": 1e9, "inductance": 1e6, "power": 1e10,
}
MAX_QUANTITY_CHARS = 64      # "1.2345e+06 kg*m^2" is 17; a longer string is not a quantity
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)?\s*$")


class UnitError(ValueError):
    """A value is not a number, or its unit is not of the expected dimension."""


def to_si(value, dimension: str | None) -> float:
    """Return `value` in SI units of `dimension`.

    `value` is a number (taken as SI) or a string "<number> <unit>". `dimension` None means a
    dimensionless number or one whose unit the scene format does not name (e.g. N*s/m):
    then only plain numbers are accepted.
    """
    return _in_range(_si(value, dimension), dimension, value)


def _in_range(number: float, dimension: str | None, given) -> float:
    limit = PHYSICAL_MAX.get(dimension or "")
    if limit is not None and math.isfinite(number) and abs(number) > limit:
        raise UnitError(f"{given!r} is beyond the physical range of {_article(dimension)} "
                        f"{dimension} (at most {limit:g} {SI_UNIT[dimension]} in size); check "
                        f"the value and its unit")
    return number


def _article(word: str) -> str:
    return "an" if word[0] in "aeiou" else "a"


def _si(value, dimension: str | None) -> float:
    if isinstance(value, bool):
        raise UnitError(f"expected a number, got the boolean {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        if len(value) > MAX_QUANTITY_CHARS:
            raise UnitError(f"expected a number or '<number> <unit>' of at most "
                            f"{MAX_QUANTITY_CHARS} characters, got {len(value)} characters "
                            f"{value[:40]!r}...")
        match = _QUANTITY.match(value)
        if not match:
            raise UnitError(f"expected a number or '<number> <unit>', got {value!r}")
        number, unit = float(match.group(1)), match.group(2)
        if unit is None:
            return number
        table = UNITS.get(dimension or "", {})
        if unit not in table:
            if dimension is None:
                raise UnitError(f"expected a plain SI number here, got a unit in {value!r}")
            raise UnitError(
                f"expected {_article(dimension)} {dimension} in one of "
                f"{sorted(table)}, got {value!r}")
        return number * table[unit]
    raise UnitError(f"expected a number, got {type(value).__name__} {value!r}")
