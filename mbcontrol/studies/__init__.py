"""Studies: what runs many simulations to answer one question.

Modules: `workprecision` (accuracy against cost of every method and radiation order),
`bench_report` (the `mbcontrol bench` command's study), `fidelity_auto` (the cheapest model
within a tolerance in the user's waves).
"""
from .fidelity_auto import FidelityReport
from .workprecision import work_precision

__all__ = ["FidelityReport", "work_precision"]
