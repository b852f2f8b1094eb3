"""Scene files: what a device is made of, read from TOML and validated once.

A scene names its water, rigid bodies (mass, inertia about the CoG, CoG, BEM geometry), the
joints of a tree (or forest) rooted at "ground", PTOs on joints and extra loads (hinge friction,
linear moorings, quadratic drag). Every later stage trusts a loaded `Scene`.

Coordinates are in the n-frame (north-east-down: x forward, y starboard, z down, origin on the
undisturbed free surface) at the reference configuration q = 0, where every body frame is
aligned with the n-frame. Numbers are SI; strings such as "60 mm" or "5 deg" are converted.
See models/hinged_barge.toml for an annotated example.
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import asdict, dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np

from .errors import SceneError
from .scene_checks import Reader, check_topology

DOF_NAMES = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
JOINT_TYPES = ("revolute", "prismatic", "fixed", "free")


@dataclass(frozen=True)
class Water:
    rho: float = 1025.0            # kg/m^3
    g: float = 9.81                # m/s^2
    depth: float = math.inf        # m; inf for deep water


@dataclass(frozen=True)
class Geometry:
    """BEM geometry of a body in the n-frame at rest: a primitive or a mesh file."""
    kind: str                              # "box" | "cylinder" | "sphere" | "mesh"
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)   # m, geometric centre (primitives)
    size: tuple[float, float, float] | None = None         # m, box edge lengths (x, y, z)
    radius: float | None = None                            # m, cylinder and sphere
    length: float | None = None                            # m, cylinder
    axis: str = "z"                                        # cylinder axis
    file: str | None = None                                # mesh file, absolute path


@dataclass(frozen=True)
class Body:
    name: str
    mass: float                                            # kg
    inertia: tuple[tuple[float, ...], ...]                 # kg m^2, 3x3 about the CoG, n axes
    cog: tuple[float, float, float]                        # m, n-frame at rest
    geometry: Geometry | None = None
    hydro: bool = True                                     # False: no hydrodynamic loads


@dataclass(frozen=True)
class Joint:
    name: str
    type: str                                              # one of JOINT_TYPES
    parent: str                                            # body name or "ground"
    child: str
    point: tuple[float, float, float]                      # m, joint point, n-frame at rest
    axis: tuple[float, float, float] | None = None         # unit axis (revolute, prismatic)
    dofs: tuple[str, ...] = ()                             # free joints: subset of DOF_NAMES

    @property
    def n_coordinates(self) -> int:
        return {"revolute": 1, "prismatic": 1, "fixed": 0}.get(self.type, len(self.dofs))


@dataclass(frozen=True)
class Pto:
    """A linear PTO: load on its follower = -(damping*v + stiffness*x) + u (+ preload).

    Either on a one-coordinate joint (`joint`; x is the joint coordinate) or between two
    points (`body`/`point` the follower, `parent`/`parent_point` the other end, "ground" or a
    body; x is the change of the distance between them, the force acts along their line).
    preload "balance": a constant force chosen so that rest is an equilibrium (the static
    load the PTO carries, e.g. a float's weight on a motor).
    """
    name: str
    joint: str | None = None
    damping: float = 0.0           # N s/m or N m s/rad
    stiffness: float = 0.0         # N/m or N m/rad
    force_max: float = math.inf    # N or N m; a limit controllers must respect
    stroke_max: float = math.inf   # m or rad; a limit controllers must respect
    efficiency: float = 1.0        # mechanical to electrical conversion, 0..1
    body: str | None = None
    point: tuple[float, float, float] | None = None        # m, n-frame at rest
    parent: str = "ground"
    parent_point: tuple[float, float, float] | None = None  # m, n-frame at rest
    preload: str = "none"          # "none" | "balance"

    @property
    def between_points(self) -> bool:
        return self.joint is None


@dataclass(frozen=True)
class Friction:
    """Joint friction -(viscous*v + coulomb*tanh(v/velocity_scale)); tanh smooths the sign."""
    name: str
    joint: str
    viscous: float = 0.0           # N s/m or N m s/rad
    coulomb: float = 0.0           # N or N m
    velocity_scale: float = 1e-2   # m/s or rad/s


@dataclass(frozen=True)
class Mooring:
    """Linear spring-damper between a body point and an anchor, per n-frame axis."""
    name: str
    body: str
    point: tuple[float, float, float]          # m, fairlead on the body, n-frame at rest
    stiffness: tuple[float, float, float]      # N/m along n-frame x, y, z
    damping: tuple[float, float, float] = (0.0, 0.0, 0.0)  # N s/m


@dataclass(frozen=True)
class Drag:
    """Viscous loads per body DOF on the CoG twist (body axes): -c|v|v - b v."""
    name: str
    body: str
    coefficients: dict[str, float] = field(default_factory=dict)  # quadratic: N s^2/m^2, N m s^2
    linear: dict[str, float] = field(default_factory=dict)        # linear: N s/m, N m s/rad


@dataclass(frozen=True)
class HydroSettings:
    file: str | None = None                    # precomputed body-frame data (.nc), absolute path
    panel_size: float = 0.1                    # m, BEM panel size
    omega: tuple[float, ...] = ()              # rad/s, BEM frequencies
    headings: tuple[float, ...] = (0.0,)       # rad, NED wave directions
    lid: bool = True
    radiation_tol: float = 0.01                # normalised RMS error of the radiation fit
    fit_omega_max: float = math.inf            # rad/s: fit the radiation model below this
    dofs: tuple[str, ...] = DOF_NAMES          # rigid DOFs the BEM solves for, per body
    source: str | None = None                  # third-party data (WAMIT .out, BEMIO .h5,
                                               # Capytaine .nc) that `file` is converted from
    source_bodies: tuple[str, ...] = ()        # scene body per body of the source, in order
    source_options: dict = field(default_factory=dict)   # reader/cleaning options, see below


@dataclass(frozen=True)
class Scene:
    name: str
    path: str
    description: str
    water: Water
    bodies: tuple[Body, ...]
    joints: tuple[Joint, ...]
    ptos: tuple[Pto, ...] = ()
    frictions: tuple[Friction, ...] = ()
    moorings: tuple[Mooring, ...] = ()
    drags: tuple[Drag, ...] = ()
    hydro: HydroSettings = HydroSettings()

    def body(self, name: str) -> Body:
        return next(b for b in self.bodies if b.name == name)

    def joint(self, name: str) -> Joint:
        return next(j for j in self.joints if j.name == name)

    def digest(self) -> str:
        """sha256 of the scene's content (not its path): provenance and cache keys.

        Files the scene refers to (hydro data, meshes) enter by name and content, so a copy of
        a model in another folder has the same digest.
        """
        data = asdict(self)
        data.pop("path")
        data["hydro"]["file"] = _file_digest(self.hydro.file)
        data["hydro"]["source"] = Path(self.hydro.source).name if self.hydro.source else None
        for body in data["bodies"]:
            if body["geometry"] and body["geometry"]["file"]:
                body["geometry"]["file"] = _file_digest(body["geometry"]["file"])
        text = json.dumps(data, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()


def _file_digest(path: str | None):
    if path is None:
        return None
    content = Path(path).read_bytes() if Path(path).exists() else b"missing"
    return [Path(path).name, hashlib.sha256(content).hexdigest()]


# ---------------------------------------------------------------------------------- loading

def catalogue_dir() -> Path:
    return Path(str(resources.files("mbcontrol.models")))


def list_models() -> list[str]:
    """Names of the scene files shipped in the catalogue (models/*.toml)."""
    return sorted(p.stem for p in catalogue_dir().glob("*.toml"))


def resolve(path_or_name: str | Path) -> Path:
    path = Path(path_or_name)
    if path.suffix == ".toml" or path.exists():
        if not path.exists():
            raise SceneError(f"{path}: no such scene file")
        return path
    candidate = catalogue_dir() / f"{path_or_name}.toml"
    if not candidate.exists():
        raise SceneError(f"{path_or_name}: not a file and not a catalogue model; "
                         f"the catalogue has {', '.join(list_models())}")
    return candidate


def load_scene(path_or_name: str | Path) -> Scene:
    """Read and validate a scene file, or a catalogue model by name (see `list_models`)."""
    path = resolve(path_or_name)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: not valid TOML: {exc}") from None
    return parse_scene(data, path)


def parse_scene(data: dict, path: Path) -> Scene:
    """Build a Scene from the TOML dictionary; every problem raises SceneError."""
    top = Reader(data, str(path), "")
    top.allow("name", "description", "water", "body", "joint", "pto", "friction", "mooring",
              "drag", "hydro")
    water = _water(top.table("water", required=False))
    bodies = tuple(_body(r, path) for r in top.tables("body", required=True))
    joints = tuple(_joint(r) for r in top.tables("joint", required=True))
    scene = Scene(
        name=top.string("name", default=path.stem),
        path=str(path),
        description=top.string("description", default=""),
        water=water, bodies=bodies, joints=joints,
        ptos=tuple(_pto(r) for r in top.tables("pto")),
        frictions=tuple(_friction(r) for r in top.tables("friction")),
        moorings=tuple(_mooring(r) for r in top.tables("mooring")),
        drags=tuple(_drag(r) for r in top.tables("drag")),
        hydro=_hydro(top.table("hydro", required=False), path),
    )
    return check_topology(scene, top)


def _water(r: Reader) -> Water:
    r.allow("rho", "g", "depth")
    return Water(rho=r.positive("rho", "density", default=1025.0),
                 g=r.positive("g", "acceleration", default=9.81),
                 depth=r.positive("depth", "length", default=math.inf, finite=False))


def _body(r: Reader, path: Path) -> Body:
    r.allow("name", "mass", "inertia", "cog", "geometry", "hydro")
    return Body(name=r.name(), mass=r.positive("mass", "mass"),
                inertia=r.inertia("inertia"), cog=r.vector("cog", "length"),
                geometry=_geometry(r.table("geometry", required=False), path),
                hydro=r.boolean("hydro", default=True))


def _geometry(r: Reader, path: Path) -> Geometry | None:
    if r.empty:
        return None
    r.allow("type", "center", "size", "radius", "length", "axis", "file")
    kind = r.choice("type", ("box", "cylinder", "sphere", "mesh"))
    center = r.vector("center", "length", default=(0.0, 0.0, 0.0))
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


def _pto(r: Reader) -> Pto:
    r.allow("name", "joint", "damping", "stiffness", "force_max", "stroke_max", "efficiency",
            "body", "point", "parent", "parent_point", "preload")
    joint = r.string("joint", default=None)
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
    return Pto(name=r.name(), joint=joint,
               damping=r.nonnegative("damping", default=0.0),
               stiffness=r.finite("stiffness", default=0.0),
               force_max=r.positive("force_max", None, default=math.inf, finite=False),
               stroke_max=r.positive("stroke_max", None, default=math.inf, finite=False),
               efficiency=efficiency,
               body=r.string("body", default=None),
               point=r.vector("point", "length", default=None),
               parent=r.string("parent", default="ground"),
               parent_point=r.vector("parent_point", "length", default=None),
               preload=r.choice("preload", ("none", "balance"), default="none"))


def _friction(r: Reader) -> Friction:
    r.allow("name", "joint", "viscous", "coulomb", "velocity_scale")
    joint = r.string("joint")
    return Friction(name=r.string("name", default=f"{joint}_friction"), joint=joint,
                    viscous=r.nonnegative("viscous", default=0.0),
                    coulomb=r.nonnegative("coulomb", default=0.0),
                    velocity_scale=r.positive("velocity_scale", None, default=1e-2))


def _mooring(r: Reader) -> Mooring:
    r.allow("name", "body", "point", "stiffness", "damping")
    stiffness = r.vector("stiffness", None)
    damping = r.vector("damping", None, default=(0.0, 0.0, 0.0))
    for key, values in (("stiffness", stiffness), ("damping", damping)):
        if min(values) < 0:
            r.fail(key, f"expected three non-negative numbers, got {list(values)}")
    return Mooring(name=r.name(), body=r.string("body"), point=r.vector("point", "length"),
                   stiffness=stiffness, damping=damping)


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
            "source", "source_bodies", "source_options", "fit_omega_max")
    source = r.string("source", default=None)
    file = r.string("file", default=None)
    omega = r.frequency_grid("omega")
    return HydroSettings(
        file=str(path.parent / file) if file else None,
        panel_size=r.positive("panel_size", "length", default=0.1),
        omega=omega,
        headings=tuple(r.finite_list("headings", "angle", default=(0.0,))),
        lid=r.boolean("lid", default=True),
        radiation_tol=r.positive("radiation_tol", None, default=0.01),
        dofs=r.dof_list("dofs", default=DOF_NAMES),
        fit_omega_max=r.positive("fit_omega_max", "frequency", default=math.inf, finite=False),
        source=str((path.parent / source).resolve()) if source else None,
        source_bodies=tuple(r.string_list("source_bodies", default=())),
        source_options=_source_options(r.table("source_options", required=False)))


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
