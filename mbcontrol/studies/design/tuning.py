"""Tuning by controller name for `design`: each controller's tuner, the PTO's limits handed to
the tuners that take them, and the parameters that rebuild the controller
(`make(name, **parameters)`). See `studies.design.study` for what the limits mean."""
from __future__ import annotations

import inspect
import math

from ...analysis import ENVELOPE_SHARE
from ...controllers import REGISTRY, OutsideEnvelope, command_limit, make
from ...errors import ControllerError
from ...results import jsonable

# the tuned parameters of each controller (the contract of make(name, **parameters))
CONTRACT = {"passive": ("damping",), "reactive": ("damping", "stiffness"),
            "latching": ("damping", "latch_time"), "declutching": ("damping", "declutch_time"),
            "mpc": ("horizon_s", "dt_s", "force_max", "stroke_max", "rate_max"),
            "nmpc": ("horizon_s", "dt_s", "force_max", "stroke_max", "rate_max")}
# MPC's default force-rate limit (with a force limit): a full reversal, -F_max to +F_max, takes
# a fifth of the wave period at the least; a real drive cannot switch within a few samples
RATE_REVERSALS_PER_PERIOD = 5


def _accepts(func, keyword: str) -> bool:
    try:
        return keyword in inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False


def _limit_kwargs(func, finite: dict, what: str, notes: list) -> dict:
    """The finite limits `func` takes; a note for each one it does not."""
    taken = {k: v for k, v in finite.items() if _accepts(func, k)}
    missing = sorted(set(finite) - set(taken))
    if missing:
        notes.append(f"{what} does not take {', '.join(missing)}: tuned without "
                     f"{'that limit' if len(missing) == 1 else 'those limits'}")
    return taken


def tune(plant, wave, name, pto_obj, limits, model_params, notes, robust: bool = True,
         envelope: bool = True):
    """(parameters, predicted W or None, tuner info, extra controller settings): the one tuner
    `design`, `export` and per-sea design call. robust (the default): a reactive law within the
    robustness floors (controllers.robustness: the defaults design.gain_margin_min and
    design.phase_margin_min_deg; a passive damper on a passive device has an infinite gain
    margin and a phase margin >= 90 deg anyway); False: the unconstrained optimum
    (--aggressive), checked against the floors and flagged by the callers; envelope: with
    limits, a passive or reactive law also within the linear model's envelope
    (analysis.envelope; False: the PTO's limits only, `envelope_gain.lifted_envelope`)."""
    cls = REGISTRY[name]
    pto = pto_obj.name
    scene = {"force_max": float(pto_obj.force_max), "stroke_max": float(pto_obj.stroke_max)}
    finite = {k: v for k, v in scene.items() if limits and math.isfinite(v)}
    # the controller's own limits, explicit (its default, None, would mean the scene's): the
    # scene's with limits, none without, so make(name, **parameters) is the very controller;
    # a limit on the hull is no clip of the command (limits.command_limit): the tuners hold
    # it in prediction, and the MPC, which cannot, is left to refuse it
    command = {**scene, "force_max": command_limit(pto_obj)}
    own = {k: (v if limits else math.inf) for k, v in command.items() if _accepts(cls, k)}
    if name in ("mpc", "nmpc") and pto_obj.limited_force() == "hull":
        own.pop("force_max", None)
    if name == "mpc" and limits:     # no scene limit: the MPC's own default (a soft stroke
        own = {k: v for k, v in own.items() if math.isfinite(v)}   # limit in its linear range)
    # the wave is a setting beyond the parameters: a predictive controller's preview
    extra = {"wave": wave} if _accepts(cls, "wave") else {}
    if name in ("passive", "reactive") and len(plant.scene.ptos) > 1:
        if robust and name == "reactive":
            notes.append("the robustness floors do not constrain several PTOs tuned jointly: "
                         "each PTO's margins are checked against them and reported")
        return _tune_jointly(plant, wave, name, limits, model_params, own, extra)
    if name in ("passive", "reactive"):
        return _tune_linear(plant, wave, name, pto_obj, limits, model_params, notes, robust,
                            finite=finite, own=own, extra=extra, envelope=envelope)
    if name in ("latching", "declutching"):
        return _tune_switching(plant, wave, name, pto_obj.name, model_params, notes,
                               finite=finite, own=own, extra=extra)
    return _untuned(wave, name, model_params, finite=finite, own=own, extra=extra)


def _tune_linear(plant, wave, name, pto_obj, limits, model_params, notes, robust, *, finite,
                 own, extra, envelope: bool = True):
    """A passive or reactive law tuned for one PTO: within its limits, the linear model's
    envelope and its rated power (with limits); flagged, not refused, outside the envelope."""
    from ...controllers import optimal_damping, reactive_tuning
    pto = pto_obj.name
    tuner = optimal_damping if name == "passive" else reactive_tuning
    kw = _limit_kwargs(tuner, finite, tuner.__name__, notes)
    if pto_obj.efficiency != 1 and _accepts(tuner, "efficiency"):
        kw["efficiency"] = float(pto_obj.efficiency)    # tune for electrical power
    info = {"function": tuner.__name__, "settings": dict(kw)}
    if limits and envelope:   # and the linear model's range (analysis.envelope)
        kw["envelope"] = True
        info["envelope"] = {"share": ENVELOPE_SHARE, "inside": True}
    if limits:
        if math.isfinite(pto_obj.rated_power):     # detuned to the PTO's rated power
            kw["rated_power"] = info["settings"]["rated_power"] = pto_obj.rated_power
    if name == "reactive":
        kw["robust"] = info["robust"] = bool(robust)
    try:
        if name == "passive":
            damping, predicted = tuner(plant, wave, pto=pto, params=model_params, **kw)
            stiffness = None
        else:
            damping, stiffness, predicted = tuner(plant, wave, pto, params=model_params, **kw)
    except OutsideEnvelope as exc:     # flagged, with the damper that comes closest
        damping, stiffness, predicted = exc.fallback
        stiffness = None if name == "passive" else stiffness
        info["envelope"].update(inside=False, ratio=exc.ratio, reason=str(exc))
        notes.append(f"OUTSIDE ITS ENVELOPE: {exc}; the damper that comes closest is used")
    if robust and name == "reactive" and predicted:     # what the floors cost, said
        info["margins_cost"] = _margins_cost(plant, wave, pto, model_params, kw, predicted)
    tuned = {"damping": damping}
    if stiffness is not None:
        tuned["stiffness"] = stiffness
    return {**tuned, **own}, predicted, info, extra


def _margins_cost(plant, wave, pto, model_params, kw, predicted) -> dict:
    """{"aggressive_predicted_W", "share"}: linear theory's power of the unconstrained optimum
    (the same limits, no robustness floors) and the share of it the floors give up."""
    from ...controllers import reactive_tuning
    try:
        aggressive = reactive_tuning(plant, wave, pto, params=model_params,
                                     **{**kw, "robust": False})[2]
    except OutsideEnvelope as exc:
        aggressive = exc.fallback[2]
    share = 1 - predicted / aggressive if aggressive and aggressive > 0 else None
    return {"aggressive_predicted_W": float(aggressive), "share": share}


def _tune_switching(plant, wave, name, pto, model_params, notes, *, finite, own, extra):
    """A latching or declutching law, tuned by simulating the plant itself."""
    from ...controllers import optimal_declutch, optimal_latch_time
    if model_params:
        raise ControllerError("model_params: latching and declutching tune by simulating the "
                              "plant itself")
    tuner, key = ((optimal_latch_time, "latch_time") if name == "latching"
                  else (optimal_declutch, "declutch_time"))
    kw = _limit_kwargs(tuner, finite, tuner.__name__, notes)
    hold, damping, simulated = tuner(plant, wave, pto=pto, **kw)
    return ({"damping": damping, key: hold, **own}, None,
            {"function": tuner.__name__, "settings": kw, "simulated_power_W": simulated,
             "dt_s": wave.period / 500}, extra)


def _untuned(wave, name, model_params, *, finite, own, extra):
    """An MPC (or another registered controller): no tuner; its defaults and the PTO's
    limits, with a horizon and a slew limit fitted to the wave."""
    if model_params:
        raise ControllerError("model_params: this controller is not tuned, so there is no model "
                              "to get wrong")
    if name in ("mpc", "nmpc"):
        # one wave period ahead in 40 steps: the horizon that reaches the constrained bound
        # on the sphere (tests/controllers/test_mpc.py) and a QP of real-time size
        own.setdefault("horizon_s", float(wave.period))
        own.setdefault("dt_s", float(wave.period) / 40)
        if "force_max" in finite:      # a drive's slew: a full reversal in a fifth of a period
            own.setdefault("rate_max", RATE_REVERSALS_PER_PERIOD * 2 * finite["force_max"]
                           / float(wave.period))
    controller = make(name, **own, **extra)
    parameters = {}
    for key in CONTRACT.get(name, ()):
        value = own.get(key, getattr(controller, key, None))
        if isinstance(value, (int, float)):
            parameters[key] = float(value)
    return parameters, None, {"function": None, "settings": "defaults"}, extra


def _tune_jointly(plant, wave, name, limits, model_params, own, extra):
    """Every PTO tuned together for their total power (controllers.joint), each with its
    own law and, with limits, its own force and stroke limits."""
    from ...controllers import joint_tuning, linear_range
    ptos = plant.scene.ptos
    kw = {}
    if limits:       # a stroke the scene leaves free: within the linear model's range
        kw = {"force_max": {p.name: p.force_max for p in ptos},
              "stroke_max": {p.name: p.stroke_max if math.isfinite(p.stroke_max)
                             else linear_range(plant, p.name) for p in ptos}}
        own = {k: {p.name: getattr(p, k) for p in ptos} for k in own}    # each PTO's own
    if any(p.efficiency != 1 for p in ptos):
        kw["efficiency"] = {p.name: float(p.efficiency) for p in ptos}
    tuned = joint_tuning(plant, wave, passive=name == "passive", params=model_params, **kw)
    parameters = {"damping": tuned.damping}
    if name == "reactive":
        parameters["stiffness"] = tuned.stiffness
    tuner = {"function": "joint_tuning", "method": tuned.method,
             "objective": "the total mean power of all PTOs, each closed by its own law",
             "settings": jsonable(kw), "predicted_by_pto_W": tuned.predicted_W,
             "predicted_total_W": tuned.total_W}
    return {**parameters, **own}, tuned.predicted_W, tuner, extra
