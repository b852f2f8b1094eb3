"""mbcontrol: control design for multibody marine systems (wave-energy converters first).

The flow, one package per stage (imports run one way, left to right):

    scene -> multibody -> hydro -> plant -> sim -> analysis -> controllers -> studies -> cli

The handful of entry points a script needs are importable from here, e.g.
``from mbcontrol import load_scene, build_plant, simulate, linearize, waves``; each is loaded
on first use, so ``import mbcontrol`` stays cheap.
"""
from .lazy import face

__version__ = "0.1.0"

# name -> (module of the package, its name there); `mbcontrol.simulate` checks its result
# (mbcontrol.analysis.validity), the raw integrator is mbcontrol.sim.simulate
_WHERE = {
    "load_scene": ("scene", "load_scene"), "list_models": ("scene", "list_models"),
    "build_plant": ("plant", "build_plant"), "Fidelity": ("plant", "Fidelity"),
    "simulate": ("analysis", "simulate_checked"), "simulate_batch": ("sim", "simulate_batch"),
    "linearize": ("analysis", "linearize"),
    "frequency_domain_response": ("analysis", "frequency_domain_response"),
    "pto_metrics": ("analysis", "pto_metrics"), "make_controller": ("controllers", "make"),
    "waves": ("waves", None),
}

__all__ = list(_WHERE)

__getattr__, __dir__ = face(__name__, globals(), _WHERE)
