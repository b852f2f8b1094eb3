"""A controller designed for one sea of a sweep (`mbcontrol sweep --design`): its settings
tuned as `design` tunes them (studies.design.tuning.tune, the PTO's limits and the linear
model's envelope respected), and the bound the same envelope sets (analysis.envelope)."""
from __future__ import annotations

from mbcontrol.controllers import REGISTRY
from mbcontrol.errors import ControllerError
from mbcontrol.results import jsonable

# what --design tunes: every registered law, each with its tune() (a tuner, or defaults
# fitted to the sea; controllers.register checks that it has one)
DESIGNABLE = REGISTRY


def design_for_sea(plant, wave, name: str, dt: float | None = None,
                   robust: bool = True) -> dict:
    """{"settings": the tuned settings (make(name, **settings, wave=...) runs them; a
    predictive controller's period rounded to whole steps of the simulation's dt, s),
    "predicted_W": linear theory's mean power (None where there is none), "bound_W": the
    most any PTO force absorbs inside the same envelope (analysis.envelope.envelope_bound;
    several PTOs: the multiport complex-conjugate bound, no envelope), "bound": how it was
    made, "envelope": the tuner's verdict (inside, ratio, reason), "robustness": the linear
    laws' margins against controllers.robustness' floors (None for the others), "notes",
    "controller": the law to make (`name`, or controllers.DAMPER where it fell back),
    "fell_back" and "fallback" (None, or {"fell_back", "from", "to", "why"}:
    studies.design.fallback)}. JSON-ready. robust: a reactive law tuned within those floors.
    A sea no law serves raises fallback.NoLawForSea (a ControllerError) with the reason."""
    from ...analysis import envelope_bound

    from .fallback import tune_with_fallback
    if name not in DESIGNABLE:
        raise ControllerError(f"--design: {name!r} has no tuner; expected one of "
                              f"{', '.join(DESIGNABLE)}")
    ptos = plant.scene.ptos
    notes: list[str] = []
    law = tune_with_fallback(plant, wave, name, ptos[0], notes, robust=robust)
    parameters, predicted, tuner = law["parameters"], law["predicted"], law["tuner"]
    name = law["controller"]
    if dt and parameters.get("dt_s"):      # a controller period of whole simulation steps
        parameters["dt_s"] = dt * max(1, round(parameters["dt_s"] / dt))
    if isinstance(predicted, dict):
        predicted = sum(predicted.values())
    if len(ptos) == 1:
        bound = envelope_bound(plant, wave, ptos[0].name)
        bound["kind"] = "complex-conjugate bound within the envelope (analysis.envelope)"
    else:
        from mbcontrol.analysis import multiport_bound
        bound = {"bound_W": multiport_bound(plant, wave).power,
                 "kind": "multiport complex-conjugate bound (no envelope: several PTOs)"}
    envelope = tuner.get("envelope") or {"inside": None,
                                         "reason": f"{name}'s tuner does not take the envelope"}
    robust = None
    if REGISTRY[name].kind == "linear" and len(ptos) == 1:   # the floors of `design`
        from ...controllers import loop_margins, loop_robustness
        gains = {k: parameters[k] for k in ("damping", "stiffness") if k in parameters}
        robust = loop_robustness(loop_margins(plant, gains, pto=ptos[0].name))
    return jsonable({"settings": parameters, "predicted_W": predicted,
                     "bound_W": bound["bound_W"], "bound": bound, "envelope": envelope,
                     "robustness": robust, "notes": notes, "controller": name,
                     "fell_back": law["fallback"] is not None, "fallback": law["fallback"]})
