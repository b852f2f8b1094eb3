"""Simulation of a process plant: open and closed loop, by named integration methods.

`simulate(plant, wave, controller=None, ...)` returns an xarray.Dataset over time (the bare
integrator: `mbcontrol.simulate` wraps it, checks the run and returns a `mbcontrol.Result`).
Modules: `run` (simulate: the runner), `record` (the Dataset a run is recorded in), `audit`
(the energy audit), `methods` (tableaux and the method registry), `integrators` (compiled
stepping), `compiled` (the compiled-code cache), `batch` (many cases through one compiled
function), `reference` (direct-convolution reference), `stability` (largest stable steps),
`initial` (initial states of free decays).

`__all__` is the documented public part. The face also serves the later stages of the flow
(studies, export, controllers), which may enter this package only here (tests/test_layout.py):
those names (stepping, compiled code, held-loop maps) are the package's own business and may
change without notice.
"""
from ..lazy import face

# name -> (submodule, its name there): loaded on first use, so that `from ..sim import METHODS`
# (the command line's choices) does not import the simulator, CasADi's compiled code and xarray
_WHERE = {
    # public (__all__)
    "simulate": ("run", "simulate"), "simulate_batch": ("batch", "simulate_batch"),
    "simulate_convolution": ("reference", "simulate_convolution"),
    "run_dataset": ("record", "run_dataset"), "METHODS": ("methods", "METHODS"),
    "method": ("methods", "method"), "Controller": ("protocol", "Controller"),
    "initial_state": ("initial", "initial_state"),
    "describe_initial": ("initial", "describe_initial"),
    "stability_limit": ("stability", "stability_limit"),
    "linear_stability_limit": ("stability", "linear_stability_limit"),
    "stability_table": ("stability", "stability_table"),
    # for the later stages only (studies' sweeps and identification, export, controllers)
    "batch_states": ("batch", "batch_states"), "compiler": ("compiled", "compiler"),
    "plant_outputs": ("integrators", "outputs"), "prepare": ("integrators", "prepare"),
    "rk4_step": ("integrators", "rk4_step"), "wave_terms": ("integrators", "wave_terms"),
    "can_run_light": ("light", "can_run"), "simulate_arrays": ("light", "simulate_arrays"),
    "CONTROLLER_OPTIONAL": ("protocol", "OPTIONAL"), "period_of": ("protocol", "period_of"),
    "law_kind": ("protocol", "law_kind"), "exportable": ("protocol", "exportable"),
    "export_refusal": ("protocol", "export_refusal"), "name_of": ("protocol", "name_of"),
    "closed_loop_map": ("sampled", "closed_loop_map"), "sampled_verdict": ("sampled", "verdict"),
    "sensitivity_name": ("sensitivity", "sensitivity_name"),
    "sensitivity_plant": ("sensitivity", "sensitivity_plant"),
}

__all__ = ["simulate", "simulate_batch", "simulate_convolution", "run_dataset", "METHODS",
           "method", "Controller", "initial_state", "describe_initial", "stability_limit",
           "linear_stability_limit", "stability_table"]


__getattr__, __dir__ = face(__name__, globals(), _WHERE)
