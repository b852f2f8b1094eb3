"""Scene files -> a validated, frozen `Scene`: the first stage of the flow.

`load_scene(path_or_name)` reads a TOML scene (or a catalogue model by name) and checks every
field once; later stages trust the result. Modules: `model` (the dataclasses), `parse` (one
section each), `checks` (field readers and whole-scene checks), `template` ([parameters] and
repeat), `units` ("60 mm" -> 0.06), `shapes` (revolution profiles, immersed volumes), `frames`
(a scene written z-up turned to NED), `load` (files and the catalogue).
"""
from .load import catalogue_dir, list_models, load_scene, resolve
from .model import (DISPLACED_PENDING, DOF_NAMES, JOINT_TYPES, Body, Drag, Drivetrain, EndStop, Friction, Geometry, HydroSettings,
                    Joint, Mooring, Obstacle, Pto, Scene, Water)
from .checks import catenary_geometry
from .moordyn_file import TO_MOORDYN, MoorDynInput, read_moordyn, run_text
from .parse import parse_scene
from .reference import in_readme as scene_keys_in_readme
from .reference import markdown as scene_keys_markdown
from .shapes import immersed_profile, immersed_volume, profile_problem
from .template import evaluate as evaluate_expression
from .uncertainty import Uncertain, scene_uncertainty
from .units import UnitError, to_si

__all__ = ["load_scene", "list_models", "catalogue_dir", "resolve", "parse_scene",
           "DISPLACED_PENDING", "DOF_NAMES", "JOINT_TYPES", "Scene", "Water", "Geometry", "Body", "Joint", "Pto",
           "Friction", "Mooring", "EndStop", "Drag", "Drivetrain", "HydroSettings", "Obstacle",
           "immersed_profile", "immersed_volume", "profile_problem", "catenary_geometry",
           "evaluate_expression", "scene_keys_markdown", "scene_keys_in_readme", "to_si",
           "UnitError", "TO_MOORDYN", "MoorDynInput", "read_moordyn", "run_text",
           "Uncertain", "scene_uncertainty"]
