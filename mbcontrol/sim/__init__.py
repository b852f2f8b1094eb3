"""Simulation of a process plant: open and closed loop, by named integration methods.

`simulate(plant, wave, controller=None, ...)` returns an xarray.Dataset over time. Modules:
`simulate` (the runner, energy audit, mooring report), `methods` (tableaux and the method
registry), `integrators` (compiled stepping), `compiled` (the compiled-code cache), `batch`
(many cases through one compiled function), `reference` (direct-convolution reference),
`stability` (largest stable steps), `initial` (initial states of free decays).
"""
from .batch import batch_states, simulate_batch
from .compiled import compiler
from .initial import describe_initial, initial_state
from .integrators import outputs as plant_outputs
from .integrators import prepare, rk4_step, wave_terms
from .light import can_run as can_run_light
from .light import simulate_arrays
from .methods import METHODS, method
from .protocol import OPTIONAL as CONTROLLER_OPTIONAL
from .protocol import Controller, estimation_report, period_of, uses_state
from .reference import simulate_convolution
from .sampled import closed_loop_map, verdict as sampled_verdict
from .sensitivity import sensitivity_name, sensitivity_plant
from .simulate import energy_audit, simulate
from .stability import linear_stability_limit, stability_limit, stability_table

__all__ = ["simulate", "simulate_batch", "simulate_convolution", "energy_audit", "METHODS",
           "method", "stability_limit", "linear_stability_limit", "stability_table",
           "batch_states", "compiler", "plant_outputs", "prepare", "rk4_step", "wave_terms",
           "can_run_light", "simulate_arrays", "closed_loop_map", "sampled_verdict",
           "sensitivity_name", "sensitivity_plant", "Controller", "CONTROLLER_OPTIONAL", "period_of",
           "uses_state", "estimation_report", "initial_state", "describe_initial"]
