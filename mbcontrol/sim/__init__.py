"""Simulation of a process plant: open and closed loop, by named integration methods.

`simulate(plant, wave, controller=None, ...)` returns an xarray.Dataset over time. Modules:
`run` (simulate: the runner, energy audit, mooring report), `methods` (tableaux and the method
registry), `integrators` (compiled stepping), `compiled` (the compiled-code cache), `batch`
(many cases through one compiled function), `reference` (direct-convolution reference),
`stability` (largest stable steps), `initial` (initial states of free decays).
"""
from ..lazy import face

# name -> (submodule, its name there): loaded on first use, so that `from ..sim import METHODS`
# (the command line's choices) does not import the simulator, CasADi's compiled code and xarray
_WHERE = {
    "batch_states": ("batch", "batch_states"), "simulate_batch": ("batch", "simulate_batch"),
    "compiler": ("compiled", "compiler"), "describe_initial": ("initial", "describe_initial"),
    "initial_state": ("initial", "initial_state"), "plant_outputs": ("integrators", "outputs"),
    "prepare": ("integrators", "prepare"), "rk4_step": ("integrators", "rk4_step"),
    "wave_terms": ("integrators", "wave_terms"), "can_run_light": ("light", "can_run"),
    "simulate_arrays": ("light", "simulate_arrays"), "METHODS": ("methods", "METHODS"),
    "method": ("methods", "method"), "CONTROLLER_OPTIONAL": ("protocol", "OPTIONAL"),
    "Controller": ("protocol", "Controller"), "estimation_report": ("protocol", "estimation_report"),
    "period_of": ("protocol", "period_of"), "uses_state": ("protocol", "uses_state"),
    "simulate_convolution": ("reference", "simulate_convolution"),
    "closed_loop_map": ("sampled", "closed_loop_map"), "sampled_verdict": ("sampled", "verdict"),
    "sensitivity_name": ("sensitivity", "sensitivity_name"),
    "sensitivity_plant": ("sensitivity", "sensitivity_plant"),
    "energy_audit": ("run", "energy_audit"), "simulate": ("run", "simulate"),
    "linear_stability_limit": ("stability", "linear_stability_limit"),
    "stability_limit": ("stability", "stability_limit"),
    "stability_table": ("stability", "stability_table"),
}

__all__ = ["simulate", "simulate_batch", "simulate_convolution", "energy_audit", "METHODS",
           "method", "stability_limit", "linear_stability_limit", "stability_table",
           "batch_states", "compiler", "plant_outputs", "prepare", "rk4_step", "wave_terms",
           "can_run_light", "simulate_arrays", "closed_loop_map", "sampled_verdict",
           "sensitivity_name", "sensitivity_plant", "Controller", "CONTROLLER_OPTIONAL", "period_of",
           "uses_state", "estimation_report", "initial_state", "describe_initial"]


__getattr__, __dir__ = face(__name__, globals(), _WHERE)
