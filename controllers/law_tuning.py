"""How the built-in laws tune for a wave (their `tune` classmethods, controllers.law): the PTO's
limits passed to the tuners that take them, and the settings that rebuild the controller
(make(name, **settings)). `studies.design` calls these through the registry; what the limits
mean is described in `studies.design.study`."""
from __future__ import annotations

import inspect
import math
from typing import Any, NamedTuple

from mbcontrol import defaults
from mbcontrol.errors import ControllerError
from mbcontrol.results import jsonable

from .limits import command_limit
from .tuning import OutsideEnvelope


class Tuning(NamedTuple):
    """What a law's tune() returns. It unpacks as the tuple that `studies.design.tune` has
    always returned.

    settings: the tuned settings, so that make(name, **settings, **extra) is the tuned
    controller (gains in N s/m and N/m, times in s, limits in N and m; a dict by PTO name
    where several PTOs are tuned jointly). predicted_W: the linear-theory mean power, W
    (several PTOs: a dict by PTO name; None where there is no such theory). tuner: what
    tuned it and what it reported (JSON-ready). extra: the settings beyond the tuned ones
    (wave=... for a law that takes a preview).
    """
    settings: dict
    predicted_W: Any
    tuner: dict
    extra: dict


# RATE_REVERSALS_PER_PERIOD, the default "design.rate_reversals_per_period" (5): a predictive
# law's default limit on the force rate (when it has a force limit): a full reversal, -F_max
# to +F_max, takes at least a fifth of the wave period. A real drive cannot switch within a
# few samples.


def accepts(func, keyword: str) -> bool:
    """Does `func` (a function or a class) take `keyword`?"""
    try:
        return keyword in inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False


def _limit_kwargs(func, finite: dict, what: str, notes: list) -> dict:
    """The finite limits `func` takes; a note for each one it does not."""
    taken = {k: v for k, v in finite.items() if accepts(func, k)}
    missing = sorted(set(finite) - set(taken))
    if missing:
        notes.append(f"{what} does not take {', '.join(missing)}: tuned without "
                     f"{'that limit' if len(missing) == 1 else 'those limits'}")
    return taken


def scene_limits(cls, wave, pto_obj, limits: bool):
    """(finite, own, extra). finite: the PTO's finite force and stroke limits (N, m) when
    `limits` is on. own: the limits the law gets explicitly (its default, None, would mean the
    scene's): the scene's with limits, inf without, so that make(name, **settings) is the very
    controller. A limit on the hull does not clip the command (limits.command_limit): the
    tuners hold it in prediction, and a predictive law, which cannot, is left to refuse it.
    extra: the preview of a law that takes one."""
    scene = {"force_max": float(pto_obj.force_max), "stroke_max": float(pto_obj.stroke_max)}
    finite = {k: v for k, v in scene.items() if limits and math.isfinite(v)}
    command = {**scene, "force_max": command_limit(pto_obj)}
    own = {k: (v if limits else math.inf) for k, v in command.items() if accepts(cls, k)}
    if cls.kind == "predictive" and pto_obj.limited_force() == "hull":
        own.pop("force_max", None)
    if cls.own_free_limits and limits:     # a free limit: the law's own default
        own = {k: v for k, v in own.items() if math.isfinite(v)}
    extra = {"wave": wave} if cls.preview else {}
    return finite, own, extra


def tune_linear(cls, tuner, plant, wave, pto_obj, *, limits=True, params=None, notes=None,
                robust=True, envelope=True) -> Tuning:
    """A linear law tuned by `tuner` (passive.optimal_damping, reactive.reactive_tuning: the
    damping, with a spring the stiffness, then the power W), or jointly with the other PTOs
    when the scene has several."""
    notes = [] if notes is None else notes
    finite, own, extra = scene_limits(cls, wave, pto_obj, limits)
    if len(plant.scene.ptos) > 1:
        if robust and cls.floors:
            notes.append("the robustness floors do not constrain several PTOs tuned jointly: "
                         "each PTO's margins are checked against them and reported")
        return _tune_jointly(cls, plant, wave, limits, params, own, extra)
    pto = pto_obj.name
    spring = "stiffness" in cls.tuned
    kw = _limit_kwargs(tuner, finite, tuner.__name__, notes)
    if pto_obj.efficiency != 1 and accepts(tuner, "efficiency"):
        kw["efficiency"] = float(pto_obj.efficiency)    # tune for electrical power
    info = {"function": tuner.__name__, "settings": dict(kw)}
    if limits and envelope:   # and the linear model's range (analysis.envelope)
        kw["envelope"] = True
        info["envelope"] = {"share": defaults.get("envelope.share"), "inside": True}
    if limits:
        if math.isfinite(pto_obj.rated_power):     # detuned to the PTO's rated power
            kw["rated_power"] = info["settings"]["rated_power"] = pto_obj.rated_power
    if cls.floors:
        kw["robust"] = info["robust"] = bool(robust)
    try:
        found = tuner(plant, wave, pto=pto, params=params, **kw)
        damping, predicted = found[0], found[-1]
        stiffness = found[1] if spring else None
    except OutsideEnvelope as exc:     # flagged, with the damper that comes closest
        damping, stiffness, predicted = exc.fallback
        stiffness = stiffness if spring else None
        info["envelope"].update(inside=False, ratio=exc.ratio, reason=str(exc))
        notes.append(f"OUTSIDE ITS ENVELOPE: {exc}; the damper that comes closest is used")
    if robust and cls.floors and predicted:     # what the floors cost, said
        info["margins_cost"] = _margins_cost(tuner, plant, wave, pto, params, kw, predicted)
    tuned = {"damping": damping}
    if stiffness is not None:
        tuned["stiffness"] = stiffness
    return Tuning({**tuned, **own}, predicted, info, extra)


def _margins_cost(tuner, plant, wave, pto, params, kw, predicted) -> dict:
    """{"aggressive_predicted_W", "share"}: linear theory's power of the unconstrained optimum
    (the same limits, no robustness floors) and the share of it the floors give up."""
    try:
        aggressive = tuner(plant, wave, pto=pto, params=params, **{**kw, "robust": False})[-1]
    except OutsideEnvelope as exc:
        aggressive = exc.fallback[2]
    share = 1 - predicted / aggressive if aggressive and aggressive > 0 else None
    return {"aggressive_predicted_W": float(aggressive), "share": share}


def _tune_jointly(cls, plant, wave, limits, params, own, extra) -> Tuning:
    """Every PTO tuned together for their total power (controllers.joint), each with its
    own law and, with limits, its own force and stroke limits."""
    from .joint import joint_tuning
    from .limits import linear_range
    ptos = plant.scene.ptos
    kw = {}
    if limits:       # a stroke the scene leaves free: within the linear model's range
        kw = {"force_max": {p.name: p.force_max for p in ptos},
              "stroke_max": {p.name: p.stroke_max if math.isfinite(p.stroke_max)
                             else linear_range(plant, p.name) for p in ptos}}
        own = {k: {p.name: getattr(p, k) for p in ptos} for k in own}    # each PTO's own
    if any(p.efficiency != 1 for p in ptos):
        kw["efficiency"] = {p.name: float(p.efficiency) for p in ptos}
    spring = "stiffness" in cls.tuned
    tuned = joint_tuning(plant, wave, passive=not spring, params=params, **kw)
    settings = {"damping": tuned.damping}
    if spring:
        settings["stiffness"] = tuned.stiffness
    tuner = {"function": "joint_tuning", "method": tuned.method,
             "objective": "the total mean power of all PTOs, each closed by its own law",
             "settings": jsonable(kw), "predicted_by_pto_W": tuned.predicted_W,
             "predicted_total_W": tuned.total_W}
    return Tuning({**settings, **own}, tuned.predicted_W, tuner, extra)


def tune_switching(cls, tuner, plant, wave, pto_obj, *, limits=True, params=None,
                   notes=None, **_) -> Tuning:
    """A switching law tuned by simulating the plant itself: `tuner` (latching's
    optimal_latch_time, optimal_declutch) returns (hold time s, damping N s/m, simulated W);
    the hold time is the law's last tuned setting."""
    if params:
        raise ControllerError("model_params: latching and declutching tune by simulating the "
                              "plant itself")
    finite, own, extra = scene_limits(cls, wave, pto_obj, limits)
    kw = _limit_kwargs(tuner, finite, tuner.__name__, [] if notes is None else notes)
    hold, damping, simulated = tuner(plant, wave, pto=pto_obj.name, **kw)
    return Tuning({"damping": damping, cls.tuned[-1]: hold, **own}, None,
                  {"function": tuner.__name__, "settings": kw, "simulated_power_W": simulated,
                   "dt_s": wave.period / 500}, extra)


def untuned(cls, plant, wave, pto_obj, *, limits=True, params=None, notes=None) -> Tuning:
    """No tuner: the law's defaults and the PTO's limits; a predictive law also gets a horizon
    and a slew limit fitted to the wave."""
    if params:
        raise ControllerError("model_params: this controller is not tuned, so there is no model "
                              "to get wrong")
    finite, own, extra = scene_limits(cls, wave, pto_obj, limits)
    if cls.kind == "predictive":
        # one wave period ahead in 40 steps: the horizon that reaches the constrained bound
        # on the sphere (tests/controllers/test_mpc.py) and a QP of real-time size
        own.setdefault("horizon_s", float(wave.period))
        own.setdefault("dt_s", float(wave.period) / 40)
        if "force_max" in finite:      # a drive's slew: a full reversal in a fifth of a period
            own.setdefault("rate_max", defaults.get("design.rate_reversals_per_period") * 2
                           * finite["force_max"] / float(wave.period))
    controller = cls(**own, **extra)
    settings = {}
    for key in cls.tuned:
        value = own.get(key, getattr(controller, key, None))
        if isinstance(value, (int, float)):
            settings[key] = float(value)
    return Tuning(settings, None, {"function": None, "settings": "defaults"}, extra)
