"""Field-level reading and whole-scene checks for scene files.

`Reader` wraps one TOML table and knows where it sits ("joint[2].axis" in "file.toml"), so
every SceneError names the file, the field and what was expected. Every name obeys
`textsafe.NAME_RULE` (`Reader.name`, `names.check_names`); messages show names by `shown`.
"""
from __future__ import annotations

import difflib
import math
import numbers
from dataclasses import replace

import numpy as np

from ..errors import SceneError
from ..textsafe import shown
from .names import check_names, name_refusal
from .units import SI_UNIT, UnitError, to_si

_REQUIRED = object()
_DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")


class Reader:
    """Typed access to one table of a scene file, with precise error messages.

    `Reader.record`, when set to a callable, is told of every key a parser allows and reads
    (section, key, what): `scene.reference` builds the scene-key reference from it, so the
    reference lists what the parser really takes."""

    record = None

    def __init__(self, data, file: str, where: str):
        if data is not None and not isinstance(data, dict):
            raise SceneError(f"{file}: {where or 'top level'}: expected a table, "
                             f"got {type(data).__name__}")
        self.data = data or {}
        self.file = file
        self.where = where

    @property
    def empty(self) -> bool:
        return not self.data

    def field(self, key: str) -> str:
        return f"{self.where}.{key}" if self.where else key

    def fail(self, key: str, expected: str):
        raise SceneError(f"{self.file}: {self.field(key)}: {expected}")

    def _note(self, key: str, **what) -> None:
        if Reader.record is not None:
            Reader.record(self.where, key, what)

    def allow(self, *keys: str) -> None:
        for key in keys:
            self._note(key, allowed=True)
        for key in self.data:
            if key not in keys:
                hint = difflib.get_close_matches(key, keys, n=1)
                also = f" (did you mean '{hint[0]}'?)" if hint else ""
                self.fail(key, f"unknown key{also}; expected one of {', '.join(keys)}")

    def _get(self, key: str, default, **what):
        self._note(key, required=default is _REQUIRED, **what,
                   **({} if default is _REQUIRED else {"default": default}))
        if key in self.data:
            return self.data[key]
        if default is _REQUIRED:
            self.fail(key, "missing required field")
        return default

    # -- nested tables
    def table(self, key: str, required: bool = True) -> "Reader":
        value = self._get(key, _REQUIRED if required else None, shape="table")
        if value is not None and not isinstance(value, dict):
            self.fail(key, f"expected a table, got {type(value).__name__}")
        return Reader(value, self.file, self.field(key))

    def tables(self, key: str, required: bool = False) -> list["Reader"]:
        value = self._get(key, _REQUIRED if required else [], shape="[[tables]]")
        if not isinstance(value, list) or (required and not value):
            self.fail(key, f"expected one or more [[{key}]] tables")
        readers = []
        for i, item in enumerate(value):
            if not isinstance(item, dict):
                self.fail(f"{key}[{i}]", f"expected a table, got {type(item).__name__}")
            readers.append(Reader(item, self.file, f"{key}[{i}]"))
        return readers

    # -- scalars
    def string(self, key: str, default=_REQUIRED):
        value = self._get(key, default, shape="string")
        if value is not None and not isinstance(value, str):
            self.fail(key, f"expected a string, got {value!r}")
        return value

    def name(self) -> str:
        """The table's `name`, checked against NAME_RULE; 'ground' (the world) is reserved."""
        value = self.string("name")
        if refusal := name_refusal(value, reserved=("ground",)):
            self.fail("name", refusal)
        return value

    def boolean(self, key: str, default=_REQUIRED) -> bool:
        value = self._get(key, default, shape="true or false")
        if not isinstance(value, bool):
            self.fail(key, f"expected true or false, got {value!r}")
        return value

    def choice(self, key: str, options, default=_REQUIRED) -> str:
        value = self._get(key, default, options=tuple(options))
        if value not in options:
            self.fail(key, f"expected one of {', '.join(options)}, got {value!r}")
        return value

    def number(self, key: str, dimension: str | None, default=_REQUIRED) -> float:
        value = self._get(key, default, dimension=dimension, shape="number")
        if value is default and default is not _REQUIRED:
            return value
        return self._convert(key, value, dimension)

    def _convert(self, key: str, value, dimension):
        try:
            number = to_si(value, dimension)
        except UnitError as exc:
            unit = f" (SI unit {SI_UNIT[dimension]})" if dimension in SI_UNIT else ""
            self.fail(key, f"{exc}{unit}")
        if math.isnan(number):
            self.fail(key, "expected a number, got nan")
        return number

    def positive(self, key: str, dimension: str | None = None, default=_REQUIRED,
                 finite: bool = True) -> float:
        """A number > 0; also finite unless `finite` is False (e.g. depth = inf)."""
        value = self.number(key, dimension, default)
        if not value > 0 or (finite and math.isinf(value)):
            self.fail(key, f"expected a {'finite ' if finite else ''}positive number, "
                           f"got {value}")
        return value

    def finite(self, key: str, dimension: str | None = None, default=_REQUIRED) -> float:
        value = self.number(key, dimension, default)
        if not math.isfinite(value):
            self.fail(key, f"expected a finite number, got {value}")
        return value

    def finite_list(self, key: str, dimension: str | None, default=_REQUIRED) -> list[float]:
        values = self.number_list(key, dimension, default)
        if not all(math.isfinite(v) for v in values):
            self.fail(key, f"expected finite numbers, got {values}")
        return values

    def nonnegative(self, key: str, default=_REQUIRED, dimension: str | None = None) -> float:
        value = self.number(key, dimension, default)
        if not value >= 0 or math.isinf(value):
            self.fail(key, f"expected a finite non-negative number, got {value}")
        return value

    # -- arrays
    def number_list(self, key: str, dimension: str | None, default=_REQUIRED) -> list[float]:
        value = self._get(key, default, dimension=dimension, shape="list of numbers")
        if value is default and default is not _REQUIRED:
            return list(value)
        if not isinstance(value, list):
            self.fail(key, f"expected a list of numbers, got {value!r}")
        return [self._convert(key, v, dimension) for v in value]

    def vector(self, key: str, dimension: str | None, default=_REQUIRED):
        value = self._get(key, default, dimension=dimension, shape="[x, y, z]")
        if value is default and default is not _REQUIRED:
            return value
        numbers = self.number_list(key, dimension)
        if len(numbers) != 3 or not all(math.isfinite(v) for v in numbers):
            self.fail(key, f"expected three finite numbers [x, y, z], got {value!r}")
        return tuple(numbers)

    def inertia(self, key: str):
        """[Ixx, Iyy, Izz] or a 3x3 matrix about the CoG; must be symmetric positive definite."""
        value = self._get(key, _REQUIRED, dimension="inertia", shape="[Ixx, Iyy, Izz] or 3x3")
        rows = value if isinstance(value, list) else None
        if rows and all(isinstance(r, list) for r in rows):
            matrix = (np.array([[self._convert(key, v, "inertia") for v in r] for r in rows])
                      if all(len(r) == 3 for r in rows) else np.zeros((0, 0)))  # ragged rows
        else:
            diagonal = self.number_list(key, "inertia")
            matrix = np.diag(diagonal) if len(diagonal) == 3 else np.zeros((0, 0))
        if matrix.shape != (3, 3):
            self.fail(key, f"expected [Ixx, Iyy, Izz] or a 3x3 matrix (kg m^2), got {value!r}")
        if not np.all(np.isfinite(matrix)):
            self.fail(key, f"expected finite numbers (kg m^2), got {value!r}")
        if not np.allclose(matrix, matrix.T, rtol=1e-9, atol=1e-12):
            self.fail(key, "expected a symmetric inertia matrix")
        if np.linalg.eigvalsh(matrix).min() <= 0:
            self.fail(key, "expected a positive definite inertia matrix (all principal "
                           f"moments > 0), got eigenvalues {np.linalg.eigvalsh(matrix)}")
        return tuple(tuple(float(v) for v in row) for row in matrix)

    def string_list(self, key: str, default=_REQUIRED) -> list[str]:
        value = self._get(key, default, shape="list of strings")
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            self.fail(key, f"expected a list of strings, got {value!r}")
        return list(value)

    def dof_list(self, key: str, default=_REQUIRED) -> tuple[str, ...]:
        value = self._get(key, default, shape="list of DOF names")
        if (not isinstance(value, (list, tuple)) or not value
                or any(v not in _DOFS for v in value) or len(set(value)) != len(value)):
            self.fail(key, f"expected distinct DOF names from {', '.join(_DOFS)}, got {value!r}")
        return tuple(d for d in _DOFS if d in value)   # canonical order

    def frequency_grid(self, key: str) -> tuple[float, ...]:
        """Frequencies (rad/s): a list of numbers, a segment {min, max, n, spacing, endpoint}
        or a list of segments (joined, duplicates removed). spacing is "linear" (default) or
        "log"; endpoint (default true) says whether max belongs to the segment."""
        value = self._get(key, (), dimension="frequency", shape="frequencies or segments")
        if isinstance(value, dict) or (isinstance(value, list) and value
                                       and all(isinstance(v, dict) for v in value)):
            segments = [value] if isinstance(value, dict) else value
            parts = [self._segment(key if len(segments) == 1 else f"{key}[{i}]", seg)
                     for i, seg in enumerate(segments)]
            return tuple(np.unique(np.concatenate(parts)))
        values = self.number_list(key, "frequency", default=())
        if any(v <= 0 for v in values) or list(values) != sorted(set(values)):
            self.fail(key, "expected positive, strictly increasing frequencies (rad/s)")
        return tuple(values)

    def _segment(self, where: str, value: dict) -> np.ndarray:
        grid = Reader(value, self.file, self.field(where))
        grid.allow("min", "max", "n", "spacing", "endpoint")
        lo = grid.positive("min", "frequency")
        hi = grid.positive("max", "frequency")
        n = grid.number("n", None)
        if not (n >= 2 and float(n).is_integer()):
            grid.fail("n", f"expected an integer number of frequencies >= 2, got {n}")
        n = int(n)
        if n > 100_000:
            grid.fail("n", f"expected at most 100000 frequencies, got {n}")
        if hi <= lo:
            self.fail(where, f"expected min < max, got {value}")
        spacing = grid.choice("spacing", ("linear", "log"), default="linear")
        endpoint = grid.boolean("endpoint", default=True)
        make = np.geomspace if spacing == "log" else np.linspace
        return make(lo, hi, n, endpoint=endpoint)


def check_topology(scene, top: Reader):
    """Whole-scene checks: unique names, references, one joint per body, no loops.

    Returns the scene with defaults that need other tables filled in (free-joint points).
    """
    where = top.file
    check_names(scene, top)
    bodies = {b.name: b for b in scene.bodies}
    for kind, items in (("body", scene.bodies), ("joint", scene.joints), ("pto", scene.ptos),
                        ("friction", scene.frictions), ("mooring", scene.moorings),
                        ("drag", scene.drags), ("end_stop", scene.end_stops)):
        _unique(where, kind, [x.name for x in items])

    parent_of: dict[str, str] = {}
    joints = []
    for i, joint in enumerate(scene.joints):
        field = f"joint[{i}]"
        if joint.parent != "ground" and joint.parent not in bodies:
            raise SceneError(f"{where}: {field}.parent: unknown body {shown(joint.parent)}; expected "
                             f"'ground' or one of {', '.join(bodies)}")
        if joint.child not in bodies:
            raise SceneError(f"{where}: {field}.child: unknown body {shown(joint.child)}; expected "
                             f"one of {', '.join(bodies)}")
        if joint.child == joint.parent:
            raise SceneError(f"{where}: {field}: a body cannot be jointed to itself")
        if joint.child in parent_of:
            raise SceneError(f"{where}: {field}.child: body {shown(joint.child)} already has a "
                             f"parent joint; joints must form a tree (or forest)")
        if joint.type == "free" and joint.parent != "ground":
            raise SceneError(f"{where}: {field}.parent: a free joint must connect to 'ground'")
        if joint.point is None:
            if joint.type != "free":
                raise SceneError(f"{where}: {field}.point: missing required field")
            joint = replace(joint, point=bodies[joint.child].cog)
        parent_of[joint.child] = joint.parent
        joints.append(joint)

    for i, name in enumerate(bodies):
        if name not in parent_of:
            raise SceneError(f"{where}: body[{i}]: no joint has body '{name}' as child; give "
                             f"it a 'free' or 'fixed' joint to ground")
        chain, node = [name], parent_of[name]
        while node != "ground":
            if node in chain:
                loop = " -> ".join(chain[chain.index(node):] + [node])
                raise SceneError(f"{where}: joints form a loop: {loop}; expected a tree")
            chain.append(node)
            node = parent_of[node]

    one_dof = {j.name: j for j in joints if j.n_coordinates == 1}
    for i, pto in enumerate(scene.ptos):
        if pto.between_points:
            if pto.body not in bodies:
                raise SceneError(f"{where}: pto[{i}].body: unknown body {shown(pto.body)}")
            if pto.parent != "ground" and pto.parent not in bodies:
                raise SceneError(f"{where}: pto[{i}].parent: unknown body {shown(pto.parent)}; "
                                 f"expected 'ground' or a body")
            if np.linalg.norm(np.subtract(pto.point, pto.parent_point)) < 1e-9:
                raise SceneError(f"{where}: pto[{i}].point: expected a point apart from "
                                 f"parent_point (the line of action needs a direction)")
    for kind, items in (("pto", scene.ptos), ("friction", scene.frictions),
                        ("end_stop", scene.end_stops)):
        for i, item in enumerate(items):
            if getattr(item, "between_points", False):
                continue
            if item.joint not in one_dof:
                known = ", ".join(one_dof) or "none"
                raise SceneError(f"{where}: {kind}[{i}].joint: expected a joint with one "
                                 f"coordinate (revolute, prismatic, or free with one dof); "
                                 f"got {shown(item.joint)}; candidates: {known}")
    for kind, items in (("mooring", scene.moorings), ("drag", scene.drags)):
        for i, item in enumerate(items):
            if item.body not in bodies:
                raise SceneError(f"{where}: {kind}[{i}].body: unknown body {shown(item.body)}")
    given = scene.hydro.file is not None or scene.hydro.source is not None
    if not given or scene.hydro.hydrostatics != "linear":
        for i, body in enumerate(scene.bodies):
            if body.hydro and body.geometry is None:
                raise SceneError(f"{where}: body[{i}].geometry: body '{body.name}' takes "
                                 f"hydrodynamic loads but has no geometry, and the scene gives "
                                 f"no hydrodynamic data ([hydro] file, or source: your WAMIT "
                                 f".out, BEMIO .h5 or Capytaine .nc) or asks for nonlinear "
                                 f"(or large-angle) hydrostatics, which integrate over it; give "
                                 f"a geometry, or data, or set hydro = false")
    return replace(scene, joints=tuple(joints))


def _unique(where: str, kind: str, names: list[str]) -> None:
    seen = set()
    for i, name in enumerate(names):
        if name in seen:
            raise SceneError(f"{where}: {kind}[{i}].name: duplicate name {shown(name)}")
        seen.add(name)


# ----------------------------------------------------------------------------- catenary lines

def catenary_geometry(where: str, *, anchor, fairlead, length, EA, weight, excursion=None,
                      friction=0.0, strain_limit=0.1, n_grid=21, newton_steps=3):
    """(anchor, fairlead, excursion) of a catenary line, checked: points as float tuples (m,
    n-frame, z down), the anchor below the fairlead and within the line's reach, excursion
    (m) between 0 and the fairlead's height above the anchor (None: 20 % of it). length (m),
    EA (N), weight (N/m), strain_limit (-) positive; friction (-) >= 0. SceneError names
    `where` and the field otherwise."""
    anchor, fairlead = (_point(value, where, key) for key, value in
                        (("anchor", anchor), ("fairlead", fairlead)))
    values = {"length": length, "EA": EA, "weight": weight, "strain_limit": strain_limit,
              "friction": friction}
    units = {"length": " m", "EA": " N", "weight": " N/m", "strain_limit": "", "friction": ""}
    for key, value in values.items():
        if not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise SceneError(f"{where}: {key} is {value!r}; expected a finite number")
        if value <= 0.0 and key != "friction" or value < 0.0:
            raise SceneError(f"{where}: {key} is {value:g}{units[key]}; expected a positive "
                             f"number" + (" or 0" if key == "friction" else ""))
    height = anchor[2] - fairlead[2]
    if height <= 0.0:
        raise SceneError(f"{where}: anchor {_fmt(anchor)} is not below the fairlead "
                         f"{_fmt(fairlead)}; expected the anchor's z (down) to be greater")
    distance = math.dist(anchor, fairlead)
    if distance > length * (1.0 + strain_limit):
        raise SceneError(f"{where}: anchor {_fmt(anchor)} is {distance:.0f} m from the "
                         f"fairlead, beyond the line's reach {length:g} m x "
                         f"(1 + {strain_limit:g} strain limit)")
    if excursion is None:
        excursion = 0.2 * height
    if not (isinstance(excursion, numbers.Real) and 0.0 < excursion < height):
        raise SceneError(f"{where}: excursion is {excursion!r} m; expected a number "
                         f"between 0 and the fairlead height above the anchor {height:g} m")
    for key, value, low in (("n_grid", n_grid, 6), ("newton_steps", newton_steps, 0)):
        if not (isinstance(value, numbers.Integral) and value >= low):
            raise SceneError(f"{where}: {key} is {value!r}; expected an integer >= {low}")
    return anchor, fairlead, excursion


def _point(value, where, key):
    """A 3-vector of finite floats (m, n-frame), or a SceneError naming the field."""
    try:
        arr = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise SceneError(f"{where}: {key} is {value!r}; expected 3 finite numbers "
                         f"(x, y, z in m, n-frame, z down)")
    return tuple(float(v) for v in arr)


def _fmt(p) -> str:
    return "(" + ", ".join(f"{v:g}" for v in p) + ")"
