"""The scene-key reference, generated from the parser itself.

Every scene the catalogue ships, and one small scene that uses the sections the catalogue
does not (end stops, a catenary line, third-party hydro options), is parsed with
`Reader.record` listening: the keys each section allows, which are required, their defaults,
units and choices are what the parser did, not a copy of it. Only the one-line meanings are
written here, and `tests/scene/test_reference.py` fails when a key has none or a meaning names
a key the parser does not take. `mbcontrol keys` prints the Markdown (the README's "Scene
keys" section and the documentation's page are this output; `mbcontrol keys --readme`
rewrites the former).
"""
from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

from ..errors import InputError
from .checks import Reader
from .frames import MEANING as _FRAME
from .uncertainty import REFERENCE as _UNCERTAINTY
from .units import SI_UNIT

# the sections in the order a scene file is usually written, with what each is
SECTIONS = {
    "": "top level",
    "water": "`[water]`: the sea the bodies float in",
    "body": "`[[body]]`: one rigid body each (at least one)",
    "geometry": "`[body.geometry]` and `[obstacle.geometry]`: the hull the BEM meshes "
                "(by `type`: box `size`; cylinder `radius`, `length`, `axis`; sphere `radius`; "
                "revolution `profile`; mesh `file`)",
    "joint": "`[[joint]]`: the tree, rooted at `ground`, one joint per body",
    "pto": "`[[pto]]`: a power take-off on a joint, or between two body points",
    "pto.drivetrain": "`[pto.drivetrain]`: the PTO's gear and electric machine (absent: an "
                      "ideal PTO, `efficiency` applies); the PTO force is the machine's",
    "friction": "`[[friction]]`: joint friction",
    "end_stop": "`[[end_stop]]`: a stiff spring-damper stop on a joint coordinate",
    "mooring": "`[[mooring]]`: `type = \"linear\"` (springs in x, y, z), `\"catenary\"` or "
               "`\"moordyn\"` (a MoorDyn input file's lines)",
    "drag": "`[[drag]]`: viscous damping of a body, per DOF (m, rad; body frame)",
    "drag.coefficients": "`[drag.coefficients]`: quadratic, F = -c v abs(v), per DOF",
    "drag.linear": "`[drag.linear]`: linear, F = -c v, per DOF",
    "obstacle": "`[[obstacle]]`: a structure fixed to ground that only the BEM sees",
    "hydro": "`[hydro]`: where the hydrodynamic data comes from and how it is fitted",
    "hydro.omega": "`[hydro.omega]` (or a list of such tables): a frequency segment",
    "hydro.source_options": "`[hydro.source_options]`: cleaning third-party BEM data",
    "identify": "`[identify]`: the parameters `mbcontrol identify` fits by default",
    **_UNCERTAINTY["sections"]}

MEANING = {
    ("", "name"): "the model's name (default: the file's name)",
    ("", "description"): "one line shown by `mbcontrol models`",
    ("", "water"): "the `[water]` table",
    ("", "body"): "the `[[body]]` tables",
    ("", "joint"): "the `[[joint]]` tables",
    ("", "pto"): "the `[[pto]]` tables",
    ("", "friction"): "the `[[friction]]` tables",
    ("", "mooring"): "the `[[mooring]]` tables",
    ("", "drag"): "the `[[drag]]` tables",
    ("", "end_stop"): "the `[[end_stop]]` tables",
    ("", "hydro"): "the `[hydro]` table",
    ("", "identify"): "the `[identify]` table",
    ("", "obstacle"): "the `[[obstacle]]` tables",
    ("water", "rho"): "water density",
    ("water", "g"): "gravity",
    ("water", "depth"): "water depth (`inf`: deep water)",
    ("body", "name"): "the body's name (signals are `<name>__Heave` ...)",
    ("body", "mass"): "mass; `\"displaced\"` (alias `\"equilibrium\"`): rho x the immersed volume of the body's geometry at rest (box or revolution), or without one, of its BEM body in `[hydro]` source or file",
    ("body", "inertia"): "inertia about the CoG, in the body frame",
    ("body", "cog"): "centre of gravity at rest, n-frame (z down)",
    ("body", "geometry"): "the hull for the BEM (`[body.geometry]`)",
    ("body", "hydro"): "false: no hydrodynamic forces on this body",
    ("geometry", "type"): "the primitive, or a mesh file",
    ("geometry", "center"): "the primitive's centre (or the mesh's origin; a revolution's "
                            "axis point that its profile's z counts from), n-frame",
    ("geometry", "size"): "box edge lengths",
    ("geometry", "radius"): "cylinder or sphere radius",
    ("geometry", "length"): "cylinder length",
    ("geometry", "axis"): "cylinder axis",
    ("geometry", "file"): "mesh file (STL or any meshio format), beside the scene",
    ("geometry", "profile"): "revolution: [[r, z], ...] from the top to the keel (z down, "
                             "non-decreasing; r >= 0), revolved about the vertical axis; open "
                             "ends are closed by flat discs",
    ("joint", "name"): "the joint's name (its coordinate's signal name)",
    ("joint", "type"): "revolute, prismatic, fixed or free",
    ("joint", "parent"): "parent body, or `ground`",
    ("joint", "child"): "the body this joint carries",
    ("joint", "point"): "where the joint sits, n-frame (required but for a free joint: "
                        "then the child's CoG)",
    ("joint", "axis"): "hinge or slider direction (revolute, prismatic)",
    ("joint", "dofs"): "the DOFs a free joint leaves free",
    ("pto", "name"): "the PTO's name (signals `<name>__power` ...)",
    ("pto", "joint"): "the joint it acts on (or give body, point, parent_point)",
    ("pto", "body"): "PTO between points: the follower body",
    ("pto", "point"): "PTO between points: the point on `body`, n-frame at rest",
    ("pto", "parent"): "PTO between points: the other body",
    ("pto", "parent_point"): "PTO between points: the point on `parent`",
    ("pto", "damping"): "linear damping of the scene's own law (N s/m or N m s/rad)",
    ("pto", "stiffness"): "spring of the scene's own law (N/m or N m/rad)",
    ("pto", "force_max"): "force limit: a force on a prismatic joint or between points, a "
                          "moment on a revolute one",
    ("pto", "force_max_on"): "what `force_max` limits with a drivetrain: `machine` (the "
                             "machine's force, the command; the default) or `hull` (the force "
                             "the drivetrain puts on the hull, the machine's less its "
                             "reflected inertia, friction and stiffness, gear^2 (J a + b v + "
                             "K x): WecOptTool's PTO force); bounds, tuners, design and the MPC "
                             "hold it",
    ("pto", "stroke_max"): "stroke limit: a length (prismatic, between points) or an angle (revolute)",
    ("pto", "efficiency"): "drivetrain efficiency in (0, 1] (electrical power)",
    ("pto", "rated_power"): "rated power: the most mean power the PTO delivers in a sea "
                            "(mechanical; electrical with a drivetrain or an efficiency): the "
                            "tuners detune to it and a sweep's power matrix is capped at it "
                            "(the drivetrain's `power_max` is its peak rating)",
    ("pto", "preload"): "`balance`: the constant force that makes rest an equilibrium",
    ("pto", "drivetrain"): "gear and generator (`[pto.drivetrain]`): current, voltage, losses "
                           "and electrical power as signals",
    ("pto.drivetrain", "gear_ratio"): "generator rad/s per m/s (or rad/s) of the PTO",
    ("pto.drivetrain", "torque_constant"): "N m/A (N/A for a linear machine with gear 1)",
    ("pto.drivetrain", "winding_resistance"): "per phase (dq)",
    ("pto.drivetrain", "winding_inductance"): "per phase; in the voltage's phasor, not in "
                                              "the time-domain power (mean zero)",
    ("pto.drivetrain", "inertia"): "rotor and gear inertia at the generator, kg m^2 (acts as "
                                   "gear^2 x on the joint; joint PTOs only)",
    ("pto.drivetrain", "friction"): "at the generator, N m s/rad (gear^2 x on the joint)",
    ("pto.drivetrain", "stiffness"): "a spring on the generator shaft, N m/rad at the "
                                     "generator (N/m for a linear machine with gear 1; may be "
                                     "negative): gear^2 x on the joint, gear^2 K x (WecOptTool's "
                                     "drivetrain stiffness)",
    ("pto.drivetrain", "phases"): "3: a three-phase machine, kt x sqrt(3/2) in dq; 1: none",
    ("pto.drivetrain", "current_max"): "current limit (reported against; not yet imposed)",
    ("pto.drivetrain", "voltage_max"): "voltage limit (reported against; not yet imposed)",
    ("pto.drivetrain", "power_max"): "electrical power rating (reported against; not yet "
                                     "imposed)",
    ("friction", "name"): "its name (default `<joint>_friction`)",
    ("friction", "joint"): "the joint it acts on",
    ("friction", "viscous"): "viscous coefficient (N s/m or N m s/rad)",
    ("friction", "coulomb"): "Coulomb force or moment (N or N m)",
    ("friction", "velocity_scale"): "velocity over which the Coulomb term is smoothed (m/s or "
                                    "rad/s)",
    ("end_stop", "name"): "its name (default `<joint>_stop`)",
    ("end_stop", "joint"): "the joint it limits",
    ("end_stop", "lower"): "lower stop, in the joint's units (m or rad); rest must lie inside",
    ("end_stop", "upper"): "upper stop",
    ("end_stop", "stiffness"): "contact stiffness (N/m or N m/rad)",
    ("end_stop", "damping"): "contact damping (N s/m or N m s/rad)",
    ("mooring", "name"): "its name",
    ("mooring", "type"): "linear, catenary, or moordyn (MoorDyn's lines, stepped beside the plant)",
    ("mooring", "file"): "moordyn: the MoorDyn input file (v2, or v1 as WEC-Sim's), from the scene",
    ("mooring", "coupled"): "moordyn: Coupled points in the body's frame (z up, about its CoG at "
                            "rest: `body`) or in MoorDyn's frame at rest (`global`)",
    ("mooring", "environment"): "moordyn: water density and depth of the file or of [water] (`scene`)",
    ("mooring", "settle"): "moordyn: bring the lines to rest at the initial pose before t = 0",
    ("mooring", "breaking_load"): "moordyn: each line's breaking load (N): reaching it is reported",
    ("mooring", "body"): "the moored body",
    ("mooring", "point"): "fairlead, n-frame at rest",
    ("mooring", "stiffness"): "linear: spring per n-frame axis (N/m)",
    ("mooring", "damping"): "linear: damper per n-frame axis (N s/m)",
    ("mooring", "anchor"): "catenary: anchor on the sea bed, n-frame",
    ("mooring", "length"): "catenary: unstretched line length",
    ("mooring", "EA"): "catenary: axial stiffness (N)",
    ("mooring", "weight"): "catenary: submerged weight per metre (N/m)",
    ("mooring", "excursion"): "catenary: largest fairlead excursion the line table covers",
    ("drag", "name"): "its name (default `<body>_drag`)",
    ("drag", "body"): "the body it acts on",
    ("drag", "coefficients"): "quadratic coefficients per DOF (`[drag.coefficients]`)",
    ("drag", "linear"): "linear coefficients per DOF (`[drag.linear]`)",
    **{(f"drag.{kind}", dof): f"{'quadratic' if kind == 'coefficients' else 'linear'} "
                              f"coefficient in {dof} ({unit})"
       for kind, units in (("coefficients", ("N s^2/m^2", "N m s^2/rad^2")),
                           ("linear", ("N s/m", "N m s/rad")))
       for dof, unit in zip(("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"),
                            [units[0]] * 3 + [units[1]] * 3)},
    ("obstacle", "name"): "its name (unique among bodies and obstacles)",
    ("obstacle", "geometry"): "its hull (`[obstacle.geometry]`)",
    ("hydro", "file"): "BEM data (netCDF), relative to the scene; when it is absent and "
                       "`omega` is given, Capytaine computes the data (cached)",
    ("hydro", "source"): "third-party BEM output (WAMIT .out, BEMIO .h5, Capytaine .nc)",
    ("hydro", "source_bodies"): "which bodies of `source`, in order",
    ("hydro", "source_options"): "cleaning options for `source` (`[hydro.source_options]`)",
    ("hydro", "omega"): "BEM frequencies: a list, or segments {min, max, n, spacing, endpoint}",
    ("hydro", "headings"): "wave headings solved",
    ("hydro", "panel_size"): "mesh panel size for primitives",
    ("hydro", "lid"): "a lid on each waterplane against irregular frequencies",
    ("hydro", "interaction"): "false: each body solved alone (no coupling)",
    ("hydro", "interaction_radius"): ("m: bodies couple only within it, each solved among its "
                                      "neighbours (mbcontrol.hydro.bem.neighbours); inf: all coupled"),
    ("hydro", "dofs"): "the DOFs solved per body",
    ("hydro", "radiation_tol"): "radiation fit error tolerance (default: the 'hydro.radiation_tol' "
                                "of `mbcontrol defaults`)",
    ("hydro", "radiation_fit"): "`coupled` (one pole set per coupled group), `columns` (per "
                                "column, symmetric columns shared: arrays and farms) or `auto` "
                                "(columns from 9 bodies that radiation couples)",
    ("hydro", "fit_omega_max"): "highest frequency the radiation fit sees",
    ("hydro", "fit_judged_by"): "\"response\": the radiation fit's order is set by the error it causes in "
                                "the device's response; \"kernel\": by K(jω)'s own error",
    ("hydro", "response_band"): "[low, high]: limits where the fit's response error is judged",
    ("hydro", "hydrostatics"): "`nonlinear`: the hydrostatic pressure over the instantaneous wetted "
                               "surface (with `froude_krylov = \"nonlinear\"`: under the incident "
                               "wave); `large_angle`: calm-water primitives only (older scenes)",
    ("hydro", "froude_krylov"): "`nonlinear`: the incident-wave pressure (Wheeler-stretched) over the "
                                "instantaneous wetted surface; needs hydrostatics = \"nonlinear\"",
    ("hydro", "nonlinear_path"): "`analytic` (bodies of revolution, vertical axis), `panels` (any "
                                 "closed surface) or `auto`",
    ("hydro", "nonlinear_panel_size"): "panel size of the surface the nonlinear forces integrate over",
    ("hydro", "nonlinear_reach"): "horizontal excursion from rest the incident field is expanded over",
    ("hydro", "nonlinear_direction"): "the sea's direction the nonlinear field is built for",
    ("hydro", "nonlinear_omega_max"): "wave components above it keep linear Froude-Krylov forces "
                                      "(default: response_band's top, else 4 rad/s)",
    ("hydro", "nonlinear_update"): "`stage`: the nonlinear pressure integral at every Runge-Kutta "
                                   "stage; `step`: once per step, moved to the other stages by its "
                                   "rest increments (about 3x faster on meshes; error charted)",
    ("hydro", "axisymmetric"): "true: bodies of revolution on the z axis in heave; the data's "
                               "one heading serves every wave direction",
    ("hydro.omega", "min"): "first frequency",
    ("hydro.omega", "max"): "last frequency",
    ("hydro.omega", "n"): "number of frequencies",
    ("hydro.omega", "spacing"): "linear or log",
    ("hydro.omega", "endpoint"): "whether `max` is included",
    ("hydro.source_options", "force_symmetric"): "symmetrise A and B",
    ("hydro.source_options", "negative_damping"): "repair, project or error",
    ("hydro.source_options", "omega_range"): "[low, high] kept, rad/s",
    ("hydro.source_options", "asym_tol"): "asymmetry tolerated before warning",
    **_UNCERTAINTY["meaning"], **_FRAME}

# read only when given (the parser checks `key in table` first), though required in form
OPTIONAL = {("drag.coefficients", None), ("drag.linear", None), ("hydro.source_options", None),
            ("mooring", "excursion")}
# units that follow the joint (recorded here on a prismatic one)
UNITS = {("body", "mass"): "number, kg or a unit string, or `\"displaced\"`",
         ("pto", "force_max"): "number, N (prismatic, between points) or N m (revolute), or a "
                               "unit string",
         ("pto", "stroke_max"): "number, m or rad by joint, or a unit string",
         ("end_stop", "lower"): "number, m or rad by joint, or a unit string",
         ("end_stop", "upper"): "number, m or rad by joint, or a unit string"}

# sections the catalogue does not use, so the recorder hears them here
_EXTRA = """
name = "reference"
[water]
depth = 20
[[body]]
name = "float"
mass = "displaced"
inertia = [1, 1, 1]
cog = [0, 0, 0]
hydro = false
[body.geometry]
type = "revolution"
profile = [[0.5, -0.1], [0.5, 0.3], [0, 0.5]]
[[joint]]
name = "heave"
type = "prismatic"
parent = "ground"
child = "float"
axis = [0, 0, 1]
point = [0, 0, 0]
[[pto]]
name = "generator"
joint = "heave"
rated_power = "500 W"
force_max_on = "hull"
[pto.drivetrain]
torque_constant = 1.0
winding_inductance = "1 mH"
current_max = "10 A"
voltage_max = "400 V"
power_max = "1 kW"
[[end_stop]]
joint = "heave"
lower = -1
upper = 1
stiffness = 1e6
[[mooring]]
type = "catenary"
name = "line"
body = "float"
point = [0, 0, 0]
anchor = [50, 0, 20]
length = 60
EA = 1e8
weight = 100
excursion = 5
[[drag]]
body = "float"
[drag.coefficients]
Surge = 1
Sway = 1
Heave = 1
Roll = 1
Pitch = 1
Yaw = 1
[drag.linear]
Surge = 1
Sway = 1
Heave = 1
Roll = 1
Pitch = 1
Yaw = 1
[hydro]
source = "none.out"
[hydro.source_options]
force_symmetric = true
negative_damping = "repair"
omega_range = [0.1, 5]
asym_tol = 0.1
"""


def _section(where: str) -> str:
    section = re.sub(r"\[\d+\]", "", where)
    return "geometry" if section.endswith(".geometry") else section


def schema() -> dict:
    """section -> key -> what the parser did with it (allowed, required, default,
    dimension, shape, options), from every catalogue scene and the extra one above."""
    from .load import list_models, load_scene
    from .parse import parse_scene
    seen: dict = {}

    def record(where, key, what):
        section = _section(where)
        if section != "identify":
            entry = seen.setdefault(section, {}).setdefault(key, {})
            for k, v in what.items():
                if k == "default" and section in ("", "drag", "friction", "end_stop") \
                        and key == "name":
                    continue                   # a default made from the scene, not a constant
                entry.setdefault(k, v)

    Reader.record = record
    try:
        for model in list_models():
            load_scene(model)
        parse_scene(tomllib.loads(_EXTRA + _UNCERTAINTY["example"]), Path("reference.toml"))
    finally:
        Reader.record = None
    return seen


def _kind(what: dict) -> str:
    if "options" in what:
        return " or ".join(f"`{o}`" for o in what["options"])
    shape = what.get("shape", "")
    dimension = what.get("dimension")
    if dimension in SI_UNIT:
        return f"{shape}, {SI_UNIT[dimension]} or a unit string"
    return shape


def _default(section: str, key: str, what: dict) -> str:
    if (section, None) in OPTIONAL or (section, key) in OPTIONAL:
        return "optional"
    if what.get("required"):
        return "required"
    if "default" not in what:
        return ""
    value = what["default"]
    if value is None or value == () or value == [] or value == "":
        return "none"
    if isinstance(value, float) and math.isinf(value):
        return "inf (none)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return f"`{value}`" if isinstance(value, str) else f"{value:g}"


def markdown() -> str:
    """The reference as Markdown: one table per section, keys in the parser's order."""
    found = schema()
    lines = []
    for section, title in SECTIONS.items():
        lines += [f"**{title}**", ""]
        if section == "identify":
            lines += ["Any plant parameter name (`mbcontrol models NAME` lists them) = "
                      "`[low, high]`, its bounds.", ""]
            continue
        lines += ["| key | value | default | meaning |", "|---|---|---|---|"]
        for key, what in found.get(section, {}).items():
            if not what.get("allowed"):
                continue
            kind = UNITS.get((section, key)) or _kind(what)
            lines.append(f"| `{key}` | {kind} | {_default(section, key, what)} | "
                         f"{MEANING.get((section, key), '')} |")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


BEGIN, END = "<!-- scene-keys:begin -->\n", "<!-- scene-keys:end -->"


def in_readme(readme: str) -> str:
    """README text with the reference between its scene-keys markers replaced by markdown()."""
    head, found, rest = readme.partition(BEGIN)
    if not found or END not in rest:
        raise InputError(f"README: expected the markers {BEGIN.strip()} and {END}")
    return head + BEGIN + markdown() + END + rest.partition(END)[2]
