"""`[[uncertainty]]`: how far a scene's author believes its numbers may be off, one table per
number, for the annual energy's budget (`mbcontrol.studies.sweep.uncertainty`).

    [[uncertainty]]
    parameter = "float.mass"        # <body>.mass, <pto>.efficiency,
                                    # <drag>.linear.<Dof> or <drag>.coefficients.<Dof>
    std = "2 %"                     # 1 sigma: "x %" of the scene's value, or a number in SI
    distribution = "normal"         # or "uniform" with half_width instead of std

None of it changes the plant: the tables are checked when the scene is parsed
(`check_uncertainty`, called by `parse_scene`) and read again from the scene file when a
sweep needs them (`scene_uncertainty`), so a scene's digest and caches do not depend on them.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .checks import Reader
from .model import DOF_NAMES
from .template import expand
from .units import UnitError, to_si

DISTRIBUTIONS = ("normal", "uniform")
FORMS = ("`<body>.mass`, `<pto>.efficiency`, `<drag>.linear.<Dof>` or "
         "`<drag>.coefficients.<Dof>`")


@dataclass(frozen=True)
class Uncertain:
    """One uncertain scene number: kind "mass" (kg), "efficiency" (-), "drag_linear"
    (N s/m or N m s/rad) or "drag_quadratic" (N s^2/m^2 or N m s^2/rad^2); owner the body,
    PTO or drag it belongs to, dof the drag's DOF; nominal the scene's value and std its
    standard uncertainty (1 sigma, SI; a uniform half-width w gives w / sqrt(3))."""
    parameter: str
    kind: str
    owner: str
    dof: str | None
    nominal: float
    std: float
    distribution: str


def check_uncertainty(tables: list[Reader], scene):
    """The scene, once its [[uncertainty]] tables parse (SceneError naming the field if not)."""
    parse_uncertainty(tables, scene)
    return scene


def parse_uncertainty(tables: list[Reader], scene) -> tuple[Uncertain, ...]:
    out, seen = [], set()
    for r in tables:
        r.allow("parameter", "std", "half_width", "distribution")
        name = r.string("parameter")
        if name in seen:
            r.fail("parameter", f"{name!r} is given twice; expected one table per number")
        seen.add(name)
        kind, owner, dof, nominal, dimension = _target(r, name, scene)
        distribution = r.choice("distribution", DISTRIBUTIONS, default="normal")
        key = "half_width" if distribution == "uniform" else "std"
        other = "std" if key == "half_width" else "half_width"
        if other in r.data:
            r.fail(other, f"a {distribution} distribution takes {key}, not {other}")
        size = _size(r, key, nominal, dimension)
        std = size / math.sqrt(3.0) if distribution == "uniform" else size
        out.append(Uncertain(name, kind, owner, dof, nominal, std, distribution))
    return tuple(out)


def _target(r: Reader, name: str, scene):
    """(kind, owner, dof, nominal, unit dimension) of a parameter name, or a SceneError."""
    parts = name.split(".")
    bodies = {b.name: b for b in scene.bodies}
    ptos = {p.name: p for p in scene.ptos}
    drags = {d.name: d for d in scene.drags}
    if len(parts) == 2 and parts[1] == "mass" and parts[0] in bodies:
        return "mass", parts[0], None, float(bodies[parts[0]].mass), "mass"
    if len(parts) == 2 and parts[1] == "efficiency" and parts[0] in ptos:
        pto = ptos[parts[0]]
        if pto.drivetrain is not None:
            r.fail("parameter", f"{name!r}: PTO {pto.name!r} has a drivetrain, whose winding "
                                f"loss, not `efficiency`, makes its electrical power")
        return "efficiency", pto.name, None, float(pto.efficiency), None
    if len(parts) == 3 and parts[1] in ("linear", "coefficients") and parts[0] in drags:
        if parts[2] not in DOF_NAMES:
            r.fail("parameter", f"{name!r}: DOF {parts[2]!r}; expected one of "
                                f"{', '.join(DOF_NAMES)}")
        drag = drags[parts[0]]
        table = drag.linear if parts[1] == "linear" else drag.coefficients
        kind = "drag_linear" if parts[1] == "linear" else "drag_quadratic"
        return kind, drag.name, parts[2], float(table.get(parts[2], 0.0)), None
    known = ([f"{b}.mass" for b in bodies] + [f"{p}.efficiency" for p in ptos]
             + [f"{d}.linear.<Dof>" for d in drags] + [f"{d}.coefficients.<Dof>" for d in drags])
    r.fail("parameter", f"{name!r}: expected {FORMS} naming this scene's bodies, PTOs and "
                        f"[[drag]] tables ({', '.join(known)})")


def _size(r: Reader, key: str, nominal: float, dimension) -> float:
    """A positive std or half-width: "x %" of the nominal value, else a number (or a unit
    string for a mass) in SI."""
    value = r._get(key, None, dimension=dimension, shape='number or "x %"')
    if value is None:
        r.fail(key, f"missing required field (1 sigma, a number or \"x %\" of the value)")
    if isinstance(value, str) and value.strip().endswith("%"):
        try:
            share = float(value.strip()[:-1]) / 100.0
        except ValueError:
            r.fail(key, f"expected \"x %\" with a number x, got {value!r}")
        if nominal == 0.0:
            r.fail(key, f"{value!r} of a value of 0: give it in SI instead")
        if math.isnan(nominal):     # a mass = "displaced" the plant resolves from BEM data:
            return share            # checked for its form here, sized on the plant's scene
        size = share * abs(nominal)
    else:
        try:
            size = to_si(value, dimension)
        except UnitError as exc:
            r.fail(key, str(exc))
    if not (math.isfinite(size) and size > 0):
        r.fail(key, f"expected a positive size, got {value!r}")
    return size


def scene_uncertainty(scene) -> tuple[Uncertain, ...]:
    """The scene's [[uncertainty]] tables, read again from its file (() when it has none or
    no file)."""
    path = Path(scene.path)
    if not path.is_file():
        return ()
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    if "uncertainty" not in data:
        return ()
    data, _ = expand(data, str(path), dict(scene.parameters) or None)
    return parse_uncertainty(Reader(data, str(path), "").tables("uncertainty"), scene)


REFERENCE = {
    "sections": {"uncertainty": "`[[uncertainty]]`: one uncertain number each, for the annual "
                                "energy's budget (`sweep`); the plant does not read them"},
    "meaning": {("", "uncertainty"): "the `[[uncertainty]]` tables",
                ("uncertainty", "parameter"): f"which number: {FORMS}",
                ("uncertainty", "std"): "its standard uncertainty (1 sigma): `\"x %\"` of the "
                                        "scene's value, or a number in SI",
                ("uncertainty", "half_width"): "a uniform distribution's half-width (`\"x %\"` "
                                               "or SI); std = half_width / sqrt(3)",
                ("uncertainty", "distribution"): "normal (takes std) or uniform (takes "
                                                 "half_width)"},
    "example": '\n[[uncertainty]]\nparameter = "float.mass"\nstd = "2 %"\n'
               '[[uncertainty]]\nparameter = "float_drag.coefficients.Heave"\n'
               'distribution = "uniform"\nhalf_width = "30 %"\n',
}
