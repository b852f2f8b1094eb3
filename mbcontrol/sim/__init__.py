"""Simulation of a process plant: open and closed loop, by named integration methods.

`simulate(plant, wave, controller=None, ...)` returns an xarray.Dataset over time. Modules:
`simulate` (the runner, energy audit, mooring report), `methods` (tableaux and the method
registry), `integrators` (compiled stepping), `compiled` (the compiled-code cache), `batch`
(many cases through one compiled function), `reference` (direct-convolution reference),
`stability` (largest stable steps).
"""
from .batch import simulate_batch
from .methods import METHODS, method
from .reference import simulate_convolution
from .simulate import energy_audit, simulate
from .stability import linear_stability_limit, stability_limit, stability_table

__all__ = ["simulate", "simulate_batch", "simulate_convolution", "energy_audit", "METHODS",
           "method", "stability_limit", "linear_stability_limit", "stability_table"]
