"""mbcontrol: control design for multibody marine systems (wave-energy converters first).

The flow, one package per stage (imports run one way, left to right):

    scene -> multibody -> hydro -> plant -> sim -> analysis -> controllers -> studies -> cli

The handful of entry points a script needs are importable from here, e.g.
``from mbcontrol import load_scene, build_plant, simulate, linearize, waves``; each is loaded
on first use, so ``import mbcontrol`` stays cheap.
"""
from importlib import import_module

__version__ = "0.1.0"

_ENTRY_POINTS = {
    "load_scene": "mbcontrol.scene", "list_models": "mbcontrol.scene",
    "build_plant": "mbcontrol.plant", "Fidelity": "mbcontrol.plant",
    "simulate": "mbcontrol.analysis", "simulate_batch": "mbcontrol.sim",
    "linearize": "mbcontrol.analysis", "frequency_domain_response": "mbcontrol.analysis",
    "pto_metrics": "mbcontrol.analysis",
    "make_controller": "mbcontrol.controllers",
}
# `mbcontrol.simulate` checks its result (mbcontrol.analysis.validity); the raw integrator is
# mbcontrol.sim.simulate
_ALIASES = {"make_controller": "make", "simulate": "simulate_checked"}

__all__ = ["waves", *_ENTRY_POINTS]


def __getattr__(name):
    if name in _ENTRY_POINTS:
        value = getattr(import_module(_ENTRY_POINTS[name]), _ALIASES.get(name, name))
        globals()[name] = value
        return value
    if name == "waves":
        return import_module("mbcontrol.waves")
    raise AttributeError(f"module 'mbcontrol' has no attribute {name!r}")
