"""Parsing of scene files into the dataclasses of :mod:`mbcontrol.scene`, one section each."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from .. import defaults
from ..errors import SceneError
from .checks import Reader, catenary_geometry, check_topology
from .frames import FRAMES, to_ned
from .model import (DISPLACED_PENDING, DOF_NAMES, JOINT_TYPES, Body, Drag, Drivetrain, EndStop,
                    Friction, Geometry, HydroSettings, Joint, Mooring, Obstacle, Pto, Scene, Water)
from .moordyn_file import read_moordyn
from .names import name_from_stem
from .shapes import displaced_mass, read_profile
from .template import expand
from .uncertainty import check_uncertainty
from .units import JOINT_DIMENSIONS


def parse_scene(data: dict, path: Path, parameters: dict | None = None) -> Scene:
    """Build a Scene from the TOML dictionary; every problem raises SceneError.

    [parameters] and `repeat` entries are expanded first (:mod:`mbcontrol.scene.template`).
    """
    if not isinstance(data, dict):
        raise SceneError(f"{path}: top level: expected a table of scene keys, got "
                         f"{type(data).__name__}")
    data, used = expand(data, str(path), parameters)
    data = to_ned(data, path)        # frame = "z-up": converted before any field is read
    top = Reader(data, str(path), "")
    top.allow("name", "description", "water", "body", "joint", "pto", "friction", "mooring",
              "drag", "end_stop", "hydro", "identify", "obstacle", "uncertainty", "frame")
    top.choice("frame", FRAMES, default="ned")
    water = _water(top.table("water", required=False))
    hydro_data = any(k in (data.get("hydro") or {}) for k in ("source", "file"))  # BEM data given
    bodies = tuple(_body(r, path, water, hydro_data) for r in top.tables("body", required=True))
    joints = tuple(_joint(r) for r in top.tables("joint", required=True))
    kinds = {j.name: j.type for j in joints}
    hydro = _hydro(top.table("hydro", required=False), path)
    obstacles = _obstacles(top, path, bodies, hydro)
    scene = Scene(
        name=_scene_name(top, path),
        path=str(path),
        description=top.string("description", default=""),
        water=water, bodies=bodies, joints=joints,
        ptos=tuple(_pto(r, kinds) for r in top.tables("pto")),
        frictions=tuple(_friction(r) for r in top.tables("friction")),
        moorings=tuple(_mooring(r, path) for r in top.tables("mooring")),
        drags=tuple(_drag(r) for r in top.tables("drag")),
        end_stops=tuple(_end_stop(r, kinds) for r in top.tables("end_stop")),
        hydro=hydro,
        parameters=used,
        identify=_identify(top.table("identify", required=False)),
        obstacles=obstacles,
    )
    return check_uncertainty(top.tables("uncertainty"), check_topology(scene, top))


def _scene_name(top, path: Path) -> str:
    """The scene's `name`, or its file's stem made a name (my-buoy.toml: my_buoy): a file name
    is the user's to choose, a scene name is not (it reaches C and signal names)."""
    name = top.string("name", default=path.stem)
    return name if "name" in top.data else name_from_stem(name)


def _water(r: Reader) -> Water:
    r.allow("rho", "g", "depth")
    return Water(rho=r.positive("rho", "density", default=1025.0),
                 g=r.positive("g", "acceleration", default=9.81),
                 depth=r.positive("depth", "length", default=math.inf, finite=False))


def _body(r: Reader, path: Path, water: Water, hydro_data: bool = False) -> Body:
    r.allow("name", "mass", "inertia", "cog", "geometry", "hydro")
    name = r.name()
    geometry = _geometry(r.table("geometry", required=False), path, f"body '{name}'")
    mass = displaced_mass(r, geometry, water.rho, hydro_data)   # NaN: from the BEM data, later
    return Body(name=name, mass=mass, inertia=r.inertia("inertia"), cog=r.vector("cog", "length"),
                geometry=geometry, hydro=r.boolean("hydro", default=True),
                mass_from=DISPLACED_PENDING if math.isnan(mass) else "")


def _geometry(r: Reader, path: Path, owner: str) -> Geometry | None:
    if r.empty:
        return None
    r.allow("type", "center", "size", "radius", "length", "axis", "file", "profile")
    kind = r.choice("type", ("box", "cylinder", "sphere", "revolution", "mesh"))
    center = r.vector("center", "length", default=(0.0, 0.0, 0.0))
    if kind == "revolution":
        return Geometry(kind, center, profile=read_profile(r, owner))
    if kind == "box":
        size = r.vector("size", "length")
        if min(size) <= 0:
            r.fail("size", f"expected three positive edge lengths (m), got {list(size)}")
        return Geometry(kind, center, size=size)
    if kind == "sphere":
        return Geometry(kind, center, radius=r.positive("radius", "length"))
    if kind == "cylinder":
        return Geometry(kind, center, radius=r.positive("radius", "length"),
                        length=r.positive("length", "length"),
                        axis=r.choice("axis", ("x", "y", "z"), default="z"))
    mesh = path.parent / r.string("file")
    if not mesh.exists():
        r.fail("file", f"expected an existing mesh file, {mesh} does not exist")
    return Geometry(kind, center, file=str(mesh))


def _obstacles(top: Reader, path: Path, bodies, hydro) -> tuple[Obstacle, ...]:
    """[[obstacle]] tables: name and geometry (both required), names unique among bodies too."""
    out, taken = [], {b.name for b in bodies}
    for r in top.tables("obstacle"):
        r.allow("name", "geometry")
        name = r.name()
        if name in taken:
            r.fail("name", f"expected a name no body or other obstacle has, got {name!r}")
        taken.add(name)
        if r.table("geometry", required=False).empty:
            r.fail("geometry", "expected a geometry table (box, cylinder, sphere or mesh): an "
                               "obstacle is a fixed structure only the BEM sees")
        if not hydro.interaction:
            r.fail("name", "expected [hydro] interaction = true: an obstacle acts on the bodies "
                           "through the waves it scatters, which a solve of each body alone leaves out")
        out.append(Obstacle(name=name, geometry=_geometry(r.table("geometry"), path, f"obstacle '{name}'")))
    return tuple(out)


def _joint(r: Reader) -> Joint:
    r.allow("name", "type", "parent", "child", "point", "axis", "dofs")
    kind = r.choice("type", JOINT_TYPES)
    axis, dofs = None, ()
    if kind in ("revolute", "prismatic"):
        axis = r.vector("axis", None)
        norm = float(np.linalg.norm(axis))
        if norm < 1e-9:
            r.fail("axis", f"expected a non-zero direction, got {list(axis)}")
        axis = tuple(float(a) / norm for a in axis)
    if kind == "free":
        dofs = r.dof_list("dofs", default=DOF_NAMES)
    child = r.string("child")
    return Joint(name=r.name(), type=kind, parent=r.string("parent"), child=child,
                 point=r.vector("point", "length", default=None), axis=axis, dofs=dofs)


def _pto(r: Reader, kinds: dict) -> Pto:
    r.allow("name", "joint", "damping", "stiffness", "force_max", "force_max_on", "stroke_max",
            "efficiency", "rated_power", "body", "point", "parent", "parent_point", "preload",
            "drivetrain")
    joint = r.string("joint", default=None)
    # limits in units of the joint's coordinate: "4 m" / "2 MN" (prismatic or between points),
    # "30 deg" / "5 MN m" (revolute); an unknown joint is named by the scene checks later
    stroke_dim, force_dim = JOINT_DIMENSIONS.get(kinds.get(joint, "prismatic"), (None, None))
    points = {k: k in r.data for k in ("body", "point", "parent_point")}
    if joint is not None and any(points.values()):
        r.fail("joint", "expected either a joint or body/point/parent_point, not both")
    if joint is None and not all(points.values()):
        missing = [k for k, given in points.items() if not given]
        r.fail(missing[0] if any(points.values()) else "joint",
               "expected a joint, or body, point and parent_point for a PTO between points")
    efficiency = r.positive("efficiency", None, default=1.0)
    if efficiency > 1:
        r.fail("efficiency", f"expected a number in (0, 1], got {efficiency}")
    force_max_on = r.choice("force_max_on", ("machine", "hull"), default="machine")
    drivetrain = _drivetrain(r.table("drivetrain", required=False), joint is None)
    if force_max_on == "hull" and drivetrain is None:
        r.fail("force_max_on", "'hull' limits the force the drivetrain puts on the hull (the "
                               "machine's less its reflected inertia, friction and stiffness): "
                               "it needs a [pto.drivetrain]; without one the two are the same "
                               "force")
    return Pto(name=r.name(), joint=joint,
               damping=r.nonnegative("damping", default=0.0),
               stiffness=r.finite("stiffness", default=0.0),
               force_max=r.positive("force_max", force_dim, default=math.inf, finite=False),
               stroke_max=r.positive("stroke_max", stroke_dim, default=math.inf, finite=False),
               efficiency=efficiency,
               rated_power=r.positive("rated_power", "power", default=math.inf, finite=False),
               body=r.string("body", default=None),
               point=r.vector("point", "length", default=None),
               parent=r.string("parent", default="ground"),
               parent_point=r.vector("parent_point", "length", default=None),
               preload=r.choice("preload", ("none", "balance"), default="none"),
               drivetrain=drivetrain, force_max_on=force_max_on)


def _drivetrain(r: Reader, between_points: bool) -> Drivetrain | None:
    """[pto.drivetrain]: gear and electric machine (absent: an ideal PTO)."""
    if r.empty:
        return None
    r.allow("gear_ratio", "torque_constant", "winding_resistance", "winding_inductance",
            "inertia", "friction", "stiffness", "phases", "current_max", "voltage_max",
            "power_max")
    phases = r._get("phases", 3, shape="1 or 3")
    if phases not in (1, 3) or isinstance(phases, bool):
        r.fail("phases", f"expected 1 or 3 (3: a three-phase machine in dq), got {phases!r}")
    inertia = r.nonnegative("inertia", default=0.0)
    if inertia > 0 and between_points:
        r.fail("inertia", "a drivetrain inertia needs a PTO on a joint (between points the "
                          "reflected inertia would depend on the pose); give 0 or use a joint")
    limit = (lambda key, dim: r.positive(key, dim, default=math.inf, finite=False))
    return Drivetrain(gear_ratio=r.positive("gear_ratio", None, default=1.0),
                      torque_constant=r.positive("torque_constant", None),
                      winding_resistance=r.nonnegative("winding_resistance", 0.0, "resistance"),
                      winding_inductance=r.nonnegative("winding_inductance", 0.0, "inductance"),
                      inertia=inertia, friction=r.nonnegative("friction", default=0.0),
                      stiffness=r.finite("stiffness", default=0.0),
                      phases=int(phases), current_max=limit("current_max", "current"),
                      voltage_max=limit("voltage_max", "voltage"),
                      power_max=limit("power_max", "power"))


def _friction(r: Reader) -> Friction:
    r.allow("name", "joint", "viscous", "coulomb", "velocity_scale")
    joint = r.string("joint")
    return Friction(name=r.string("name", default=f"{joint}_friction"), joint=joint,
                    viscous=r.nonnegative("viscous", default=0.0),
                    coulomb=r.nonnegative("coulomb", default=0.0),
                    velocity_scale=r.positive("velocity_scale", None, default=1e-2))


def _mooring(r: Reader, path: Path) -> Mooring:
    kind = r.choice("type", ("linear", "catenary", "moordyn"), default="linear")
    if kind == "catenary":
        return _catenary(r)
    if kind == "moordyn":
        return _moordyn(r, path)
    r.allow("name", "type", "body", "point", "stiffness", "damping")
    stiffness = r.vector("stiffness", None)
    damping = r.vector("damping", None, default=(0.0, 0.0, 0.0))
    for key, values in (("stiffness", stiffness), ("damping", damping)):
        if min(values) < 0:
            r.fail(key, f"expected three non-negative numbers, got {list(values)}")
    return Mooring(name=r.name(), body=r.string("body"), point=r.vector("point", "length"),
                   stiffness=stiffness, damping=damping)


def _catenary(r: Reader) -> Mooring:
    r.allow("name", "type", "body", "point", "anchor", "length", "EA", "weight", "excursion")
    m = Mooring(name=r.name(), body=r.string("body"), point=r.vector("point", "length"),
                kind="catenary", anchor=r.vector("anchor", "length"),
                length=r.positive("length", "length"), EA=r.positive("EA"),
                weight=r.positive("weight"),
                excursion=r.positive("excursion", "length") if "excursion" in r.data else None)
    try:    # geometry checks (anchor below the fairlead, within the line's reach)
        catenary_geometry(f"mooring '{m.name}'", anchor=m.anchor, fairlead=m.point,
                          length=m.length, EA=m.EA, weight=m.weight, excursion=m.excursion)
    except ValueError as exc:
        r.fail("anchor", str(exc))
    return m


def _moordyn(r: Reader, path: Path) -> Mooring:
    """A MoorDyn input file whose Coupled points follow `body` (scene.moordyn_file)."""
    r.allow("name", "type", "body", "file", "coupled", "environment", "settle", "breaking_load")
    file = str((path.parent / r.string("file")).resolve())
    read_moordyn(file, f"{r.file}: {r.field('file')}")    # checked now: fails at load
    return Mooring(name=r.name(), body=r.string("body"), point=(0.0, 0.0, 0.0), kind="moordyn",
                   file=file, coupled=r.choice("coupled", ("body", "global"), default="body"),
                   environment=r.choice("environment", ("file", "scene"), default="file"),
                   settle=r.boolean("settle", default=True),
                   breaking_load=_breaking_load(r))


def _breaking_load(r: Reader) -> float | None:
    value = r.number("breaking_load", "force", default=None)
    if value is not None and not (value > 0 and math.isfinite(value)):
        r.fail("breaking_load", f"expected a finite positive force (N), got {value}")
    return value


def _end_stop(r: Reader, kinds: dict) -> EndStop:
    r.allow("name", "joint", "lower", "upper", "stiffness", "damping")
    joint = r.string("joint")
    coordinate = JOINT_DIMENSIONS.get(kinds.get(joint), ("coordinate",))[0]
    lower = r.number("lower", coordinate, default=-math.inf)
    upper = r.number("upper", coordinate, default=math.inf)
    if not lower < upper:
        r.fail("upper", f"expected upper > lower, got lower = {lower}, upper = {upper}")
    if not lower < 0 < upper:
        r.fail("lower" if lower >= 0 else "upper",
               f"the rest position (joint coordinate 0) must lie strictly between the stops, "
               f"got [{lower}, {upper}]: a stop engaged at rest moves the equilibrium")
    if math.isinf(lower) and math.isinf(upper):
        r.fail("lower", "expected at least one of lower, upper")
    return EndStop(name=r.string("name", default=f"{joint}_stop"), joint=joint, lower=lower,
                   upper=upper, stiffness=r.positive("stiffness", None),
                   damping=r.nonnegative("damping", default=0.0))


def _drag(r: Reader) -> Drag:
    r.allow("name", "body", "coefficients", "linear")
    body = r.string("body")
    tables = {}
    for key in ("coefficients", "linear"):
        table = r.table(key, required=False)
        table.allow(*DOF_NAMES)
        tables[key] = {dof: table.nonnegative(dof) for dof in DOF_NAMES if dof in table.data}
    if not tables["coefficients"] and not tables["linear"]:
        r.fail("coefficients", "expected quadratic 'coefficients' or 'linear' damping per DOF")
    return Drag(name=r.string("name", default=f"{body}_drag"), body=body,
                coefficients=tables["coefficients"], linear=tables["linear"])


def _hydro(r: Reader, path: Path) -> HydroSettings:
    if r.empty:
        return HydroSettings()
    r.allow("file", "panel_size", "omega", "headings", "lid", "radiation_tol", "dofs",
            "source", "source_bodies", "source_options", "fit_omega_max", "response_band", "interaction",
            "interaction_radius", "hydrostatics", "radiation_fit", "fit_judged_by", "axisymmetric",
            "froude_krylov", "nonlinear_path", "nonlinear_panel_size", "nonlinear_reach",
            "nonlinear_direction", "nonlinear_omega_max", "nonlinear_update")
    band = r.finite_list("response_band", "frequency", default=()) or None
    if band is not None and not (len(band) == 2 and 0 <= band[0] < band[1]):
        r.fail("response_band", f"expected [low, high] in rad/s with 0 <= low < high, got {band}")
    source = r.string("source", default=None)
    file = r.string("file", default=None)
    omega = r.frequency_grid("omega")
    interaction = r.boolean("interaction", default=True)
    radius = r.positive("interaction_radius", "length", default=math.inf, finite=False)
    if not interaction and radius < math.inf:
        r.fail("interaction_radius", "expected either interaction = false (no coupling) or an "
               "interaction_radius (coupling within it), not both")
    return HydroSettings(
        file=str(path.parent / file) if file else None,
        panel_size=r.positive("panel_size", "length", default=0.1),
        omega=omega,
        headings=tuple(r.finite_list("headings", "angle", default=(0.0,))),
        lid=r.boolean("lid", default=True),
        radiation_tol=r.positive("radiation_tol", None,
                                 default=defaults.get("hydro.radiation_tol")),
        radiation_fit=r.choice("radiation_fit", ("auto", "coupled", "columns"), default="auto"),
        fit_judged_by=r.choice("fit_judged_by", ("response", "kernel"), default="response"),
        dofs=r.dof_list("dofs", default=DOF_NAMES),
        fit_omega_max=r.positive("fit_omega_max", "frequency", default=math.inf, finite=False),
        response_band=tuple(band) if band is not None else None,
        source=str((path.parent / source).resolve()) if source else None,
        source_bodies=tuple(r.string_list("source_bodies", default=())),
        source_options=_source_options(r.table("source_options", required=False)),
        interaction=interaction, interaction_radius=radius,
        axisymmetric=r.boolean("axisymmetric", default=False), **_nonlinear(r))


def _nonlinear(r: Reader) -> dict:
    """[hydro] settings of the nonlinear hydrostatics and Froude-Krylov forces."""
    out = {"hydrostatics": r.choice("hydrostatics", ("linear", "nonlinear", "large_angle"),
                                    default="linear"),
           "froude_krylov": r.choice("froude_krylov", ("linear", "nonlinear"), default="linear"),
           "nonlinear_path": r.choice("nonlinear_path", ("auto", "analytic", "panels"),
                                      default="auto"),
           "nonlinear_panel_size": (r.positive("nonlinear_panel_size", "length")
                                    if "nonlinear_panel_size" in r.data else None),
           "nonlinear_reach": (r.positive("nonlinear_reach", "length")
                               if "nonlinear_reach" in r.data else None),
           "nonlinear_direction": r.finite("nonlinear_direction", "angle", default=0.0),
           "nonlinear_omega_max": (r.positive("nonlinear_omega_max", "frequency")
                                   if "nonlinear_omega_max" in r.data else None),
           "nonlinear_update": r.choice("nonlinear_update", ("stage", "step"), default="stage")}
    if out["nonlinear_update"] != "stage" and out["hydrostatics"] != "nonlinear":
        r.fail("nonlinear_update", "expected hydrostatics = \"nonlinear\" with it: it sets how "
               "often the nonlinear pressure is integrated, and this scene has none")
    if out["froude_krylov"] == "nonlinear" and out["hydrostatics"] != "nonlinear":
        r.fail("froude_krylov", "expected hydrostatics = \"nonlinear\" with it: the incident "
               "pressure and the buoyancy are one pressure over one wetted surface, and either "
               "alone is inconsistent in waves (set both to \"nonlinear\")")
    return out


def _source_options(r: Reader) -> dict:
    """Options for reading and cleaning third-party hydro data (mbcontrol.hydro.readers)."""
    r.allow("force_symmetric", "negative_damping", "omega_range", "asym_tol")
    out = {}
    if "force_symmetric" in r.data:
        out["force_symmetric"] = r.boolean("force_symmetric")
    if "negative_damping" in r.data:
        out["negative_damping"] = r.choice("negative_damping", ("repair", "project", "error"))
    if "omega_range" in r.data:
        lo, hi = r.number_list("omega_range", "frequency")
        out["omega_range"] = (lo, hi)
    if "asym_tol" in r.data:
        out["asym_tol"] = r.positive("asym_tol")
    return out


def _identify(r: Reader) -> dict:
    """[identify]: plant parameter name -> [lo, hi], the default set `mbcontrol identify`
    fits (names are checked against the plant when it is built)."""
    out = {}
    for key, value in r.data.items():
        expected = "expected [lo, hi] with lo < hi (the fitted parameter's bounds)"
        if not isinstance(value, list) or len(value) != 2:
            r.fail(key, f"{expected}, got {value!r}")
        lo, hi = r.number_list(key, None)
        if not lo < hi:
            r.fail(key, f"{expected}, got {value!r}")
        out[key] = (float(lo), float(hi))
    return out
