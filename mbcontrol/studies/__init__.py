"""Studies: what runs many simulations to answer one question.

Modules: `workprecision` (accuracy against cost of every method and radiation order),
`bench_report` (the `mbcontrol bench` command's study), `fidelity_auto` (the cheapest model
within a tolerance in the user's waves), `parametric` (Mathieu stability maps over period x
height).
"""
from .bench_report import bench as run_bench
from .farm import farm_sweep
from .fidelity_auto import FidelityReport
from .fidelity_auto import auto as auto_fidelity
from .parametric import natural_period, plot_stability_maps, stability_map
from .workprecision import work_precision

__all__ = ["FidelityReport", "work_precision", "run_bench", "farm_sweep", "auto_fidelity",
           "stability_map", "plot_stability_maps", "natural_period"]
