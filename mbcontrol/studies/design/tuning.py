"""Tuning by controller name for `design`: the registered law's own tune() (controllers.law),
which hands the PTO's limits to the tuners that take them and returns the settings that
rebuild the controller (`make(name, **parameters)`). See `studies.design.study` for what the
limits mean."""
from __future__ import annotations

from collections.abc import Mapping

from ...controllers import REGISTRY


class _Contract(Mapping):
    """Law name -> the settings its tune() sets (its class's `tuned`), read from the registry
    (the contract of make(name, **parameters))."""

    def __getitem__(self, name):
        return tuple(REGISTRY[name].tuned)

    def __iter__(self):
        return iter(REGISTRY)

    def __len__(self):
        return len(REGISTRY)


CONTRACT = _Contract()


def tune(plant, wave, name, pto_obj, limits, model_params, notes, robust: bool = True,
         envelope: bool = True):
    """(parameters, predicted W or None, tuner info, extra controller settings): the one tuner
    `design`, `export` and per-sea design call, the registered law's tune() (a
    controllers.Tuning, which unpacks as this tuple). robust (the default): a law with floors
    (reactive) within the robustness floors (controllers.robustness: the defaults
    design.gain_margin_min and design.phase_margin_min_deg; a passive damper on a passive
    device has an infinite gain margin and a phase margin >= 90 deg anyway); False: the
    unconstrained optimum (--aggressive), checked against the floors and flagged by the
    callers; envelope: with limits, a linear law also within the linear model's envelope
    (analysis.envelope; False: the PTO's limits only, `envelope_gain.lifted_envelope`)."""
    return REGISTRY[name].tune(plant, wave, pto_obj, limits=limits, params=model_params,
                               notes=notes, robust=robust, envelope=envelope)
