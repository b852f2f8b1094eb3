"""The process plant: a scene's nonlinear equations of motion as CasADi Functions.

`build_plant(scene)` assembles x' = f(x, u, w; p), y = h(x, u, w; p) with named signals and
symbolic parameters. Modules: `process` (ProcessPlant and its assembly), `loads` (PTO,
friction, moorings, drag, end stops, gravity, hydrostatics), `catenary` and `catenary_line`
(quasi-static mooring lines), `checks` (rest checks), `fidelity` (simplified models),
`freeze` (DOFs removed: blocked by a rig, or not excited by the waves), `jacobians` (exact
Jacobians, shared downstream), `workspace` (what is derived from a plant, kept with it and
freed with it), `mechanical` (the linear mechanics at rest), `ownership` (which PTO
parameters a controller owns: one rule for every stage), `provenance` (content hashes of
what made a plant), `build` (the entry point).
"""
from .build import build_plant
from .catenary import CatenarySolution, solve_catenary
from .catenary_line import CatenaryLine, catenary_line
from .fidelity import Fidelity, FidelityError, has_couplings, plant_for
from .freeze import as_wave_list
from .held_pressure import stage_load
from .jacobians import jacobians
from .moordyn_loads import kinematics_function as moordyn_kinematics
from .moordyn_statics import recording_served_statics, shipped_statics
from .moordyn_system import MoorDynSystem
from .mechanical import MechanicalMatrices, dof_selector, mechanical_matrices
from .nonlinear import with_nonlinear_pressure
from .ownership import controlled_params, linear_params
from .pieces import f_by_parts
from .process import ProcessPlant, active_hydro_dofs, device_around, response_error_of
from .provenance import provenance
from .workspace import derived

__all__ = ["build_plant", "ProcessPlant", "active_hydro_dofs", "dof_selector", "jacobians",
           "Fidelity", "FidelityError", "plant_for", "CatenaryLine", "CatenarySolution",
           "catenary_line", "solve_catenary", "provenance", "MechanicalMatrices", "mechanical_matrices",
           "device_around", "linear_params", "controlled_params", "response_error_of",
           "derived", "has_couplings", "as_wave_list", "f_by_parts", "with_nonlinear_pressure",
           "stage_load", "moordyn_kinematics", "MoorDynSystem", "recording_served_statics",
           "shipped_statics"]
