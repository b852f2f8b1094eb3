"""A scene written z-up (WEC-Sim's and WAMIT's convention), converted to mbcontrol's NED on load.

mbcontrol's n-frame is north-east-down (x forward, y to starboard, z down, origin on the still
water; DESIGN.md, Conventions). A scene that says ``frame = "z-up"`` is written in x forward,
y to port, z up, the same origin: the two differ by a rotation of pi about x, R = diag(1, -1, -1)
(a proper rotation, so both frames stay right-handed). On load, before any field is read:

- points and directions: body ``cog``, geometry ``center``, joint ``point`` and ``axis``, PTO
  ``point`` and ``parent_point``, mooring ``point`` and ``anchor``, obstacle geometry ``center``:
  (x, y, z) -> (x, -y, -z);
- revolution profiles [r, z]: z -> -z (still written from the top to the keel);
- inertia: R I R, so a diagonal inertia stays as written, Ixy and Ixz change sign;
- headings ([hydro] headings, nonlinear_direction; +x towards +y): angle -> -angle.

A joint axis written z-up keeps its meaning: ``axis = [0, 0, 1]`` is positive upwards in either
frame, so a joint coordinate, its stroke and its end stops need no change. Magnitudes (masses,
stiffnesses, drag coefficients per DOF, lengths) are the same in both frames. Mesh files are
not converted: a z-up scene with a mesh geometry is refused. Results, signals and the CLI's
--direction are NED.
"""
from __future__ import annotations

from ..errors import SceneError
from .units import UnitError, to_si

FRAMES = ("ned", "z-up")
_POINTS = {"body": ("cog",), "joint": ("point", "axis"), "pto": ("point", "parent_point"),
           "mooring": ("point", "anchor")}


def _negated(value, dimension: str | None):
    """-value for a number or a quantity string ("0.72 m" -> -0.72); as it is when it is neither
    (the scene's readers then name the field and what they expected)."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        return -value
    try:
        return -to_si(value, dimension) if dimension else value
    except (UnitError, TypeError, ValueError):
        return value


def _mirrored(vector, dimension):
    if not isinstance(vector, list) or len(vector) != 3:
        return vector
    return [vector[0], _negated(vector[1], dimension), _negated(vector[2], dimension)]


def _geometry(geometry: dict, path, owner: str) -> dict:
    if not isinstance(geometry, dict):
        return geometry
    if geometry.get("type") == "mesh":
        raise SceneError(f"{path}: {owner}.geometry: a mesh file with frame = \"z-up\": mesh files "
                         f"are read as they are, in the body's NED axes; expected the scene in NED "
                         f"(remove frame and write y and z negated) or a primitive geometry")
    out = dict(geometry)
    if "center" in out:
        out["center"] = _mirrored(out["center"], "length")
    if isinstance(out.get("profile"), list):
        out["profile"] = [[p[0], _negated(p[1], "length")] if isinstance(p, list) and len(p) == 2
                          else p for p in out["profile"]]
    return out


def _inertia(value):
    """R I R for R = diag(1, -1, -1): the entries (x, y), (x, z) and their mirrors change sign."""
    if isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) and len(r) == 3
                                                         for r in value):
        sign = [[1, -1, -1], [-1, 1, 1], [-1, 1, 1]]
        return [[v if sign[i][j] > 0 else _negated(v, "inertia") for j, v in enumerate(row)]
                for i, row in enumerate(value)]
    return value


def to_ned(data: dict, path) -> dict:
    """The scene dictionary in NED: as it is without ``frame`` or with ``frame = "ned"``;
    converted (module docs) with ``frame = "z-up"``. Any other value is left for the scene
    reader to refuse, naming the field."""
    if data.get("frame") != "z-up":
        return data
    out = dict(data)
    for section, keys in _POINTS.items():
        tables = out.get(section)
        if not isinstance(tables, list):
            continue
        converted = []
        for k, table in enumerate(tables):
            if not isinstance(table, dict):
                converted.append(table)
                continue
            table = dict(table)
            for key in keys:
                if key in table:
                    table[key] = _mirrored(table[key], None if key == "axis" else "length")
            if section == "body":
                if "inertia" in table:
                    table["inertia"] = _inertia(table["inertia"])
                if "geometry" in table:
                    table["geometry"] = _geometry(table["geometry"], path, f"body[{k}]")
            converted.append(table)
        out[section] = converted
    if isinstance(out.get("obstacle"), list):
        out["obstacle"] = [{**o, "geometry": _geometry(o["geometry"], path, f"obstacle[{k}]")}
                           if isinstance(o, dict) and "geometry" in o else o
                           for k, o in enumerate(out["obstacle"])]
    hydro = out.get("hydro")
    if isinstance(hydro, dict):
        hydro = dict(hydro)
        if isinstance(hydro.get("headings"), list):
            hydro["headings"] = [_negated(h, "angle") for h in hydro["headings"]]
        if "nonlinear_direction" in hydro:
            hydro["nonlinear_direction"] = _negated(hydro["nonlinear_direction"], "angle")
        out["hydro"] = hydro
    return out


# the key's line in the scene-key reference (module reference)
MEANING = {("", "frame"): "`\"ned\"` (default: x forward, y starboard, z down) or `\"z-up\"` (y to "
                          "port, z up: WEC-Sim's and WAMIT's); a z-up scene is turned by pi about x "
                          "on load: points and axes (x, y, z) -> (x, -y, -z), headings negated, "
                          "diagonal inertias as written"}
