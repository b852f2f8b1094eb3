"""Scene files: what a device is made of, read from TOML and validated once.

A scene names its water, rigid bodies (mass, inertia about the CoG, CoG, BEM geometry), the
joints of a tree (or forest) rooted at "ground", PTOs on joints, extra loads (hinge friction,
linear moorings, quadratic drag) and obstacles (fixed structures only the BEM sees). Every
later stage trusts a loaded `Scene`.

Coordinates are in the n-frame (north-east-down: x forward, y starboard, z down, origin on the
undisturbed free surface) at the reference configuration q = 0, where every body frame is
aligned with the n-frame. Numbers are SI; strings such as "60 mm" or "5 deg" are converted.
See models/hinged_barge.toml for an annotated example.
"""
from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from .. import defaults
from ..errors import InputError

DOF_NAMES = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
JOINT_TYPES = ("revolute", "prismatic", "fixed", "free")
# Body.mass_from of a mass = "displaced" body without geometry until its BEM data are read
DISPLACED_PENDING = "displaced: rho x the displaced volume of its BEM body, when the data are read"


@dataclass(frozen=True)
class Water:
    rho: float = 1025.0            # kg/m^3
    g: float = 9.81                # m/s^2
    depth: float = math.inf        # m; inf for deep water


@dataclass(frozen=True)
class Geometry:
    """BEM geometry of a body in the n-frame at rest: a primitive or a mesh file."""
    kind: str                              # "box" | "cylinder" | "sphere" | "revolution" | "mesh"
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)   # m, geometric centre (primitives;
                                           # revolution: the axis point profile z counts from)
    size: tuple[float, float, float] | None = None         # m, box edge lengths (x, y, z)
    radius: float | None = None                            # m, cylinder and sphere
    length: float | None = None                            # m, cylinder
    axis: str = "z"                                        # cylinder axis
    file: str | None = None                                # mesh file, absolute path
    profile: tuple[tuple[float, float], ...] | None = None  # m, revolution: (r, z down), top to keel


@dataclass(frozen=True)
class Body:
    name: str
    mass: float                                            # kg
    inertia: tuple[tuple[float, ...], ...]                 # kg m^2, 3x3 about the CoG, n axes
    cog: tuple[float, float, float]                        # m, n-frame at rest
    geometry: Geometry | None = None
    hydro: bool = True                                     # False: no hydrodynamic loads
    mass_from: str = ""    # "": given; DISPLACED_PENDING: rho x the BEM file's displaced volume,
                           # set when the data are read (mbcontrol.hydro.with_displaced_masses),
                           # which says here how (volume, rho, file, BEM body)


@dataclass(frozen=True)
class Obstacle:
    """A structure fixed to ground (a flap's base, a wall): in the BEM as a scatterer without
    DOFs of its own, never in the multibody plant (no mass, no states)."""
    name: str
    geometry: Geometry                                     # required: what the waves meet


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
    rated_power: float = math.inf  # W: the most mean power it delivers in a sea (tuners
                                   # detune to it, a sweep's power matrix is capped at it)
    body: str | None = None
    point: tuple[float, float, float] | None = None        # m, n-frame at rest
    parent: str = "ground"
    parent_point: tuple[float, float, float] | None = None  # m, n-frame at rest
    preload: str = "none"          # "none" | "balance"
    drivetrain: "Drivetrain | None" = None   # None: an ideal PTO (efficiency applies)
    force_max_on: str = "machine"  # "machine": force_max limits the machine's force (the
                                   # command); "hull": the force the drivetrain puts on the
                                   # hull, the machine's less gear^2 (J a + b v + K x)

    @property
    def between_points(self) -> bool:
        return self.joint is None

    def limited_force(self, force_on: str | None = None) -> str:
        """Which force force_max limits: "machine" or "hull" (`force_on`, or None for
        force_max_on; "wec", WecOptTool's word, is "hull"). "hull" needs a drivetrain:
        without one the two are the same force, and "machine" is returned."""
        on = self.force_max_on if force_on is None else {"wec": "hull"}.get(force_on, force_on)
        if on not in ("machine", "hull"):
            raise InputError(f"PTO {self.name!r}: force_on {force_on!r}: expected 'machine' "
                             f"or 'hull'")
        return "hull" if on == "hull" and self.drivetrain is not None else "machine"


@dataclass(frozen=True)
class Drivetrain:
    """A PTO's gear and electric machine (`[pto.drivetrain]`), as WecOptTool's two-port.

    The generator turns at gear_ratio x the PTO velocity (rad/s per m/s, or per rad/s). The
    PTO force F (the controller's command, its limits) is the machine's: current
    I = F / (gear_ratio kt'), kt' = torque_constant x sqrt(3/2) for a three-phase machine in dq
    (phases = 3), torque_constant for phases = 1; voltage V = R I + L dI/dt + kt' gear_ratio v;
    electrical power delivered -F v - R I^2. The machine's inertia J, friction b and shaft
    stiffness K act on the joint as gear_ratio^2 J, gear_ratio^2 b and gear_ratio^2 K
    (WecOptTool's drivetrain impedance, `reflected_impedance`).
    """
    gear_ratio: float = 1.0          # rad/s of the generator per m/s (or rad/s) of the PTO
    torque_constant: float = 1.0     # N m/A (N/A for a linear machine with gear_ratio 1)
    winding_resistance: float = 0.0  # ohm
    winding_inductance: float = 0.0  # H
    inertia: float = 0.0             # kg m^2 at the generator
    friction: float = 0.0            # N m s/rad at the generator
    stiffness: float = 0.0           # N m/rad at the generator (may be < 0)
    phases: int = 3                  # 3: the sqrt(3/2) dq factor; 1: none
    current_max: float = math.inf    # A
    voltage_max: float = math.inf    # V
    power_max: float = math.inf      # W

    @property
    def kt(self) -> float:
        """The effective torque constant kt' (N m/A), dq factor included."""
        return self.torque_constant * (math.sqrt(1.5) if self.phases == 3 else 1.0)

    @property
    def force_per_current(self) -> float:
        """PTO force per ampere, gear_ratio x kt' (N/A, or N m/A for a rotary PTO)."""
        return self.gear_ratio * self.kt

    def reflected_impedance(self, s):
        """gear_ratio^2 (J s + b + K / s): the drivetrain's inertia, friction and stiffness
        seen at the joint (N s/m or N m s/rad) at the Laplace variable s; the force they take
        from the joint is this times the PTO velocity. s = 1j omega for phasors of
        exp(+i omega t) (WecOptTool's Z_d), -1j omega for exp(-i omega t)."""
        s = np.asarray(s, complex)
        return self.gear_ratio ** 2 * (self.inertia * s + self.friction + self.stiffness / s)


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
    """A mooring at a body point (the fairlead).

    kind "linear": a spring-damper from the fairlead's rest position, per n-frame axis.
    kind "catenary": a quasi-static elastic catenary line to a seabed anchor
    (mbcontrol.plant.catenary): its tension at the fairlead, from the line's length, axial stiffness
    EA and submerged weight per metre, with seabed contact.
    kind "moordyn": the lines of a MoorDyn input file (mbcontrol.scene.moordyn_file), stepped by
    MoorDyn beside the plant (mbcontrol.sim.moordyn); its Coupled points follow `body`.
    """
    name: str
    body: str
    point: tuple[float, float, float]          # m, fairlead on the body, n-frame at rest
    stiffness: tuple[float, float, float] = (0.0, 0.0, 0.0)  # N/m along n-frame x, y, z
    damping: tuple[float, float, float] = (0.0, 0.0, 0.0)  # N s/m
    kind: str = "linear"                       # "linear" | "catenary"
    anchor: tuple[float, float, float] | None = None   # m, n-frame (catenary)
    length: float = 0.0                        # m, unstretched (catenary)
    EA: float = 0.0                            # N, axial stiffness (catenary)
    weight: float = 0.0                        # N/m, submerged weight (catenary)
    excursion: float | None = None             # m, fairlead motion the force table covers
    file: str | None = None                    # MoorDyn input file (moordyn), absolute
    coupled: str = "body"                      # moordyn: Coupled points in the body's frame
                                               # (about its CoG at rest) or "global"
    environment: str = "file"                  # moordyn: water density and depth from the
                                               # MoorDyn file, or "scene" ([water])
    settle: bool = True                        # moordyn: lines brought to rest at the
                                               # initial pose before t = 0
    breaking_load: float | None = None         # moordyn: N, every line's; reaching it is
                                               # reported (None: not checked)


@dataclass(frozen=True)
class EndStop:
    """Joint travel limits as a stiff, one-sided spring-damper (a contact penalty).

    Beyond `upper` by d > 0 the joint feels -max(stiffness*d + damping*v, 0) (and symmetrically
    below `lower`): it pushes back while engaged and never pulls, so a stop releases cleanly.
    A stiff stop raises the highest natural frequency to about sqrt(stiffness / M_jj): an
    explicit integrator needs steps below ~2.8 / that frequency (the plant reports it).
    """
    name: str
    joint: str
    lower: float = -math.inf       # m or rad, joint coordinate at the stop (rest is 0)
    upper: float = math.inf        # m or rad
    stiffness: float = 0.0         # N/m or N m/rad
    damping: float = 0.0           # N s/m or N m s/rad, while engaged


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
    radiation_tol: float = field(              # radiation fit error (hydro.fit.radiation, "Error")
        default_factory=lambda: defaults.get("hydro.radiation_tol"))
    radiation_fit: str = "auto"                # "coupled" | "columns" (hydro.fit.array_fit) | "auto"
    fit_judged_by: str = "response"            # "response": the device's (hydro.fit.response_error);
                                               # "kernel": K(jω)'s own error (hydro.fit.fit_error)
    fit_omega_max: float = math.inf            # rad/s: fit the radiation model below this
    response_band: tuple[float, float] | None = None  # rad/s: where the device moves (its seas
                                               # and modes); radiation fit judged per ω there
    dofs: tuple[str, ...] = DOF_NAMES          # rigid DOFs the BEM solves for, per body
    source: str | None = None                  # third-party data (WAMIT .out, BEMIO .h5,
                                               # Capytaine .nc) that `file` is converted from
    source_bodies: tuple[str, ...] = ()        # scene body per body of the source, in order
    source_options: dict = field(default_factory=dict)   # reader/cleaning options, see below
    interaction: bool = True                   # False: each body solved alone (hydro.bem.isolated)
    interaction_radius: float = math.inf       # m: couple bodies only within it (hydro.bem.neighbours)
    hydrostatics: str = "linear"               # "linear" | "nonlinear" (pressure over the
                                               # instantaneous wetted surface) | "large_angle"
                                               # (calm-water primitives, kept for old scenes)
    froude_krylov: str = "linear"              # "linear" | "nonlinear" (incident pressure over
                                               # the instantaneous wetted surface)
    nonlinear_path: str = "auto"               # "auto" | "analytic" (bodies of revolution) |
                                               # "panels" (any closed surface)
    nonlinear_panel_size: float | None = None  # m: panel size of the nonlinear surface
                                               # (None: the body's size / 12)
    nonlinear_reach: float | None = None       # m: horizontal excursion the wave field covers
                                               # (None: the body's half-width, at least 5 m)
    nonlinear_direction: float = 0.0           # rad: the sea's direction the field is built for
    nonlinear_omega_max: float | None = None   # rad/s: components above it stay linear (None:
                                               # response_band's top, else 4 rad/s)
    nonlinear_update: str = "stage"            # "stage": the pressure integral at every
                                               # Runge-Kutta stage; "step": once per step
                                               # (mbcontrol.plant.held_pressure)
    axisymmetric: bool = False                 # bodies of revolution on the z axis, in heave:
                                               # one heading's excitation serves every direction


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
    end_stops: tuple[EndStop, ...] = ()
    hydro: HydroSettings = HydroSettings()
    parameters: dict = field(default_factory=dict)  # [parameters] as used (overrides applied)
    identify: dict = field(default_factory=dict)    # [identify]: parameter -> (lo, hi) to fit
    obstacles: tuple[Obstacle, ...] = ()            # [[obstacle]]: fixed structures the BEM sees

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
        for mooring in data["moorings"]:  # other kinds' digests stay as they were
            if mooring["breaking_load"] is None:
                mooring.pop("breaking_load")
            if mooring["kind"] == "moordyn":
                mooring["file"] = _file_digest(mooring["file"])
            else:
                for key in ("file", "coupled", "environment", "settle"):
                    mooring.pop(key)
        if not data["obstacles"]:       # digests of scenes without obstacles stay as they were
            data.pop("obstacles")
        for body in data["bodies"]:       # digests of scenes with given masses stay as they were
            if not body["mass_from"]:
                body.pop("mass_from")
        for body in list(data["bodies"]) + list(data.get("obstacles", ())):
            if body["geometry"] and body["geometry"]["file"]:
                body["geometry"]["file"] = _file_digest(body["geometry"]["file"])
            if body["geometry"] and body["geometry"]["profile"] is None:
                body["geometry"].pop("profile")   # digests of scenes without one stay as they were
        text = json.dumps(data, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()


def _file_digest(path: str | None):
    if path is None:
        return None
    content = Path(path).read_bytes() if Path(path).exists() else b"missing"
    return [Path(path).name, hashlib.sha256(content).hexdigest()]
