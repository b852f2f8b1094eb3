"""What per-sea design does when the tuned law cannot serve a sea: it falls back, and says so.

The chain, tried in order until a law holds the PTO's limits and the linear model's envelope
(analysis.envelope) in linear theory:

1. the law asked for, tuned (studies.design.tuning.tune);
2. detuned: a passive damper within the same limits (a reactive law's spring, a latch or an
   MPC's reactive power all need more force than the damper that absorbs the same sea; the
   damper is the gentlest law that still absorbs);
3. saturated: a passive damper whose command is clipped at the PTO's force_max, as the
   drive clips it (controllers.Passive saturates), chosen on the statistically linearised
   law. A damper meets the force limit and the stroke limit at opposite ends of its range:
   a light one keeps the force small and lets the stroke run, a heavy one holds the stroke
   and needs a large force. In a storm no damping does both (sphere, Hs 6.13 m, Tp 11.86 s:
   the force peak stays below 2 MN only up to the damping at which the stroke peak is still
   past 4 m). The force limit is the drive's rating, which it enforces itself by clipping;
   the stroke limit is the end stop, which only the force can keep the body from: so the
   law that still runs clips the force and spends all of it on holding the stroke. A
   saturated damper F = -sat(c v) in a Gaussian sea acts, in Booton's statistical
   linearisation, as the damper c_eq = c erf(F_max / (sqrt 2 c sigma_v)) (a regular wave:
   the describing function of the saturation); its mean power is c_eq sigma_v^2 and its
   motion that of the damper c_eq. c_eq can reach F_max sqrt(2 / pi) / sigma_v (c -> inf, a
   drive at +-F_max throughout, Coulomb-like): the most any force within F_max resists.

A sea where even that damper leaves the stroke or the envelope past its limit cannot be
served by any of these laws: NoLawForSea, with the numbers (the device's survival mode; a
sweep records the sea with that reason and counts its energy as zero, saying so).
"""
from __future__ import annotations

import math

import numpy as np

from mbcontrol.controllers import DAMPER
from mbcontrol.errors import ControllerError
from ... import defaults

SATURATED = "passive, saturated at force_max"
# the clipped damper is taken at most this close to the Coulomb limit (c -> inf): beyond it
# its damping c grows without bound for a few % more resistance
# COULOMB_SHARE: the default "design.coulomb_share" (mbcontrol.defaults)


class NoLawForSea(ControllerError):
    """No law of the fallback chain holds the PTO's stroke and the linear model's envelope in
    this sea with a force within force_max. attempts: [{"law", "why"}] of each law tried."""

    exit_status = 3     # the CLI's: a sea the device cannot serve is a result, not bad input

    def __init__(self, message: str, attempts: list):
        super().__init__(message)
        self.attempts = attempts


def equivalent_damping(damping, force_max: float, spread, regular: bool = False):
    """The damper c_eq (N s/m) a damper `damping` c clipped at +-force_max (N) acts as on a
    velocity of standard deviation `spread` (m/s; a regular wave: its amplitude): Booton's
    c erf(F_max / (sqrt 2 c sigma)) for a Gaussian velocity, else the describing function
    (2 c / pi)(asin r + r sqrt(1 - r^2)), r = min(1, F_max / (c A)). Broadcasts."""
    from scipy.special import erf
    c = np.asarray(damping, float)
    if not regular:
        return c * erf(force_max / (math.sqrt(2) * c * spread))
    r = np.minimum(1.0, force_max / (c * spread))
    return 2 * c / np.pi * (np.arcsin(r) + r * np.sqrt(1 - r ** 2))


def coulomb_limit(force_max: float, spread, regular: bool = False):
    """The largest c_eq a force within +-force_max gives (c -> inf), N s/m: F_max sqrt(2/pi)
    / sigma_v in a sea, 4 F_max / (pi A) in a regular wave."""
    return force_max * (4 / np.pi if regular else math.sqrt(2 / np.pi)) / np.asarray(spread)


def damping_for(c_eq: float, force_max: float, spread: float, regular: bool = False) -> float:
    """The clipped damper c whose equivalent damping is c_eq (the inverse of
    equivalent_damping, which rises monotonically in c to coulomb_limit)."""
    from scipy.optimize import brentq
    limit = float(coulomb_limit(force_max, spread, regular))
    if not c_eq < limit:
        raise ControllerError(f"equivalent damping {c_eq:.4g} N s/m: a force within "
                              f"{force_max:.4g} N gives at most {limit:.4g}")
    high = c_eq
    while equivalent_damping(high, force_max, spread, regular) < c_eq:
        high *= 2
    return float(brentq(lambda c: equivalent_damping(c, force_max, spread, regular) - c_eq,
                        c_eq, high, xtol=1e-9 * c_eq, rtol=1e-12))


def _statistics(plant, wave, name: str, damping, exceedance: float = 0.01) -> dict:
    """Linear theory of the damper(s) `damping` (N s/m, 1-D) alone on PTO `name`: sigma_v,
    sigma_x (a regular wave: amplitudes), the stroke peak (a sea: Rice's level crossed with
    expected count `exceedance` in the repeat period, as controllers.impedance.fd_statistics),
    power (W) and the envelope ratio (analysis.envelope). exp(-i omega t) as pto_thevenin."""
    from mbcontrol.analysis import envelope_response, pto_thevenin
    from mbcontrol.plant import controlled_params
    base = controlled_params(plant, None, linear=True)
    w, a = np.asarray(wave.omega, float), np.asarray(wave.amplitude, float)
    th = pto_thevenin(plant, w, name, wave.direction, base, check_passive=False)
    c = np.asarray(damping, float)[:, None]
    V = th.excitation * a / (th.impedance + c)        # the PTO force -c V
    X = V / (-1j * w)
    env = envelope_response(plant, wave, name, params=base)
    ratio = env.ratio(-c * V)
    if w.size == 1:
        s_v, s_x = np.abs(V[:, 0]), np.abs(X[:, 0])
        return {"spread_v": s_v, "spread_x": s_x, "stroke_peak": s_x, "force_peak": c[:, 0] * s_v,
                "power_W": 0.5 * c[:, 0] * s_v ** 2, "envelope_ratio": ratio, "regular": True}
    s_v = np.sqrt(0.5 * np.sum(np.abs(V) ** 2, axis=1))
    s_x = np.sqrt(0.5 * np.sum(np.abs(X) ** 2, axis=1))
    s_a = np.sqrt(0.5 * np.sum(np.abs(w * V) ** 2, axis=1))
    record = 2 * np.pi / (wave.d_omega or np.min(np.diff(np.sort(w))))

    def peak(s, s_rate):         # Rice: 2 T / T_z crossings, T_z = 2 pi s / s_rate
        return s * np.sqrt(2 * np.log(np.maximum(record * s_rate / (np.pi * s) / exceedance,
                                                 1.0)))
    return {"spread_v": s_v, "spread_x": s_x, "stroke_peak": peak(s_x, s_v),
            "force_peak": c[:, 0] * peak(s_v, s_a), "power_W": c[:, 0] * s_v ** 2,
            "envelope_ratio": ratio, "regular": False}


def saturated_damper(plant, wave, pto_obj, *, share: float | None = None,
                     exceedance: float = 0.01) -> dict:
    """The clipped damper (see the module doc) with the most mean power whose equivalent
    linear motion keeps the stroke peak within stroke_max (m), every envelope quantity within
    `share` (default "envelope.share") of its limit and the power within the rated
    power. {"damping" c (N s/m, the controller's), "force_max" (N, its clip),
    "equivalent_damping" c_eq, "predicted_W" c_eq sigma_v^2, "stroke_peak_m",
    "envelope_ratio", "inside_envelope", "clipped_share" (the share of the time the force is
    at the clip, erfc(F_max / (sqrt 2 c sigma_v)) in a sea)}. Where no such damper keeps the
    envelope (a sea whose relative motion passes the draft even with the body held: the
    envelope is the linear model's range, not the device's), the one closest to it that
    holds the stroke, inside_envelope false: the run's validity check, or the nonlinear
    plant (sweep --nonlinear invalid), decides. NoLawForSea, with the numbers at the Coulomb
    limit, if no clipped damper holds the stroke."""
    from mbcontrol import defaults
    share = defaults.resolve("envelope.share", share)
    f_max, s_max = float(pto_obj.force_max), float(pto_obj.stroke_max)
    if not math.isfinite(f_max) or pto_obj.limited_force() == "hull":
        raise NoLawForSea(f"PTO {pto_obj.name!r}: no force limit on the machine to saturate at "
                          f"(force_max {f_max:.4g})", [])
    from mbcontrol.analysis import pto_thevenin
    k = int(np.argmax(wave.amplitude))
    scale = float(np.abs(pto_thevenin(plant, wave.omega[k:k + 1], pto_obj.name,
                                      wave.direction, check_passive=False).impedance[0]))
    c_eq = np.geomspace(1e-3 * scale, 1e4 * scale, 600)
    st = _statistics(plant, wave, pto_obj.name, c_eq, exceedance)
    reach = c_eq < defaults.get("design.coulomb_share") * coulomb_limit(f_max, st["spread_v"], st["regular"])
    holds = reach & (st["stroke_peak"] <= s_max)
    if math.isfinite(pto_obj.rated_power):
        holds &= st["power_W"] <= pto_obj.rated_power
    if not holds.any():
        j = int(np.argmin(np.where(reach, st["stroke_peak"], np.inf))) if reach.any() else 0
        raise NoLawForSea(
            f"even the force held at +-{f_max:.4g} N (a clipped damper at "
            f"{100 * defaults.get('design.coulomb_share'):.0f} % of its Coulomb limit, the most any force within "
            f"force_max resists) leaves the predicted stroke peak at "
            f"{st['stroke_peak'][j]:.3g} m, past stroke_max {s_max:.3g} m: no law within the "
            f"PTO's limits serves this sea (survival)", [])
    inside = holds & (st["envelope_ratio"] <= share)
    if inside.any():           # the most power inside the envelope
        j = int(np.argmax(np.where(inside, st["power_W"], -np.inf)))
    else:                      # none inside: the closest, flagged (the run's check decides)
        j = int(np.argmin(np.where(holds, st["envelope_ratio"], np.inf)))
    spread = float(st["spread_v"][j])
    c = damping_for(float(c_eq[j]), f_max, spread, st["regular"])
    from scipy.special import erfc
    clipped = float(erfc(f_max / (math.sqrt(2) * c * spread))) if not st["regular"] else \
        float(2 / np.pi * np.arccos(min(1.0, f_max / (c * spread))))
    return {"damping": c, "force_max": f_max, "equivalent_damping": float(c_eq[j]),
            "inside_envelope": bool(inside.any()),
            "predicted_W": float(st["power_W"][j]), "stroke_peak_m": float(st["stroke_peak"][j]),
            "envelope_ratio": float(st["envelope_ratio"][j]), "clipped_share": clipped}


def tune_with_fallback(plant, wave, name: str, pto_obj, notes: list, *, robust: bool = True,
                       model_params=None, limits: bool = True) -> dict:
    """The law for one sea, through the chain of the module doc: {"controller": the law to
    make (name, or controllers.DAMPER after a fallback), "parameters" (make(controller,
    **parameters, **extra)), "predicted" (W, linear theory; None where there is none),
    "tuner" (its info; a saturated law's numbers under "saturated"), "extra", "fallback":
    None, or {"fell_back": true, "from": name, "to": the law used, "why": the tuned law's
    error}}. The tuned law is used as it is when it holds the limits and the envelope; one
    the tuner could only bring closest to the envelope (envelope inside false) is replaced by
    the saturated damper when that holds it. Several PTOs or no limits: the tuner alone.
    NoLawForSea when nothing holds (its attempts: every law tried and why not); a note says
    each fallback."""
    from ...controllers import LimitsUnreachable

    from .tuning import tune
    single = limits and len(plant.scene.ptos) == 1 and model_params is None
    try:
        parameters, predicted, tuner, extra = tune(plant, wave, name, pto_obj, limits,
                                                   model_params, notes, robust=robust)
    except LimitsUnreachable as exc:     # the sea, not the request: a gentler law may serve
        if not single:
            raise
        return _fall_back(plant, wave, name, pto_obj, notes, str(exc), robust)
    tuned = {"controller": name, "parameters": parameters, "predicted": predicted,
             "tuner": tuner, "extra": extra, "fallback": None}
    envelope = tuner.get("envelope") or {}
    if not single or envelope.get("inside") is not False:
        return tuned
    why = envelope.get("reason", "outside the linear model's envelope")
    saturated_notes: list[str] = []
    try:
        law = _saturated(plant, wave, name, pto_obj, saturated_notes, why)
    except NoLawForSea as exc:
        law, reason = None, str(exc)
    else:
        reason = "it does not keep the envelope either"
    if law is not None and law["tuner"]["envelope"]["inside"]:
        notes += saturated_notes
        return law
    notes.append(f"FELL BACK: {name} -> the damper closest to the envelope (outside it), the "
                 f"tuner's own; the saturated damper is no better: {reason}")
    return {**tuned, "fallback": {"fell_back": True, "from": name,
                                  "to": "passive, the damper closest to the envelope",
                                  "why": why}}


def limits_conflict(plant, wave, pto_obj, exceedance: float = 0.01) -> str | None:
    """Why no unclipped damper meets force_max and stroke_max together in `wave`, in numbers
    (a damper lowers the stroke and raises the force: the two limits bind at opposite ends),
    or None where one does."""
    f_max, s_max = float(pto_obj.force_max), float(pto_obj.stroke_max)
    if not (math.isfinite(f_max) and math.isfinite(s_max)):
        return None
    from mbcontrol.analysis import pto_thevenin
    k = int(np.argmax(wave.amplitude))
    scale = float(np.abs(pto_thevenin(plant, wave.omega[k:k + 1], pto_obj.name,
                                      wave.direction, check_passive=False).impedance[0]))
    c = np.geomspace(1e-3 * scale, 1e4 * scale, 600)
    st = _statistics(plant, wave, pto_obj.name, c, exceedance)
    light, heavy = st["force_peak"] <= f_max, st["stroke_peak"] <= s_max
    if (light & heavy).any() or not light.any() or not heavy.any():
        return None
    i, j = int(np.flatnonzero(light)[-1]), int(np.flatnonzero(heavy)[0])
    return (f"no damper meets both limits in this sea: the heaviest within force_max "
            f"{f_max:.4g} N (damping {c[i]:.4g} N s/m) lets the stroke peak reach "
            f"{st['stroke_peak'][i]:.3g} m, past stroke_max {s_max:.3g} m; holding the stroke "
            f"needs damping >= {c[j]:.4g} N s/m and a force peak of {st['force_peak'][j]:.4g} N")


def _fall_back(plant, wave, name, pto_obj, notes, why: str, robust: bool) -> dict:
    """The detuned damper, else the saturated one, after the tuned law raised `why`."""
    from .tuning import tune
    conflict = limits_conflict(plant, wave, pto_obj)
    if conflict:                       # the numbers that explain it, from the fallback's own check
        why = conflict
    attempts = [{"law": name, "why": why}]
    if name != DAMPER:
        damper_notes: list[str] = []
        try:
            parameters, predicted, tuner, extra = tune(plant, wave, DAMPER, pto_obj, True,
                                                       None, damper_notes, robust=robust)
        except ControllerError as exc:
            attempts.append({"law": DAMPER, "why": str(exc)})
        else:
            if (tuner.get("envelope") or {}).get("inside") is not False:
                notes += damper_notes
                notes.append(f"FELL BACK: {name} -> {DAMPER} (detuned): {why}")
                return {"controller": DAMPER, "parameters": parameters,
                        "predicted": predicted, "tuner": tuner, "extra": extra,
                        "fallback": {"fell_back": True, "from": name, "to": DAMPER,
                                     "why": why}}
            attempts.append({"law": DAMPER, "why": tuner["envelope"].get("reason", "")})
    try:
        return _saturated(plant, wave, name, pto_obj, notes, why)
    except NoLawForSea as exc:
        attempts.append({"law": SATURATED, "why": str(exc)})
        raise NoLawForSea(f"{plant.name}: no law serves this sea: {name}: {why}; {SATURATED}: "
                          f"{exc}", attempts) from None


def _saturated(plant, wave, name, pto_obj, notes, why: str) -> dict:
    law = saturated_damper(plant, wave, pto_obj)
    notes.append(f"FELL BACK: {name} -> {SATURATED} {law['force_max']:.4g} N (damping "
                 f"{law['damping']:.4g} N s/m, acting as {law['equivalent_damping']:.4g}; "
                 f"clipped {100 * law['clipped_share']:.2g} % of the time): {why}")
    envelope = {"inside": law["inside_envelope"], "ratio": law["envelope_ratio"]}
    if not law["inside_envelope"]:
        envelope["reason"] = (f"no clipped damper that holds the stroke keeps the envelope: "
                              f"the closest reaches {law['envelope_ratio']:.2f} of its limit")
        notes.append(f"OUTSIDE ITS ENVELOPE: {envelope['reason']}")
    tuner = {"function": "fallback.saturated_damper", "saturated": law, "envelope": envelope}
    return {"controller": DAMPER,
            "parameters": {"damping": law["damping"], "force_max": law["force_max"]},
            "predicted": law["predicted_W"], "tuner": tuner, "extra": {},
            "fallback": {"fell_back": True, "from": name, "to": SATURATED, "why": why}}


def no_law_design(exc: NoLawForSea, name: str) -> dict:
    """The `design` entry of a sweep record for a sea no law serves (design_for_sea's keys,
    nothing tuned; `name` the law asked for): fell_back true, to None, why: the reason."""
    return {"controller": None, "settings": {}, "predicted_W": None, "bound_W": None,
            "bound": None, "envelope": {"inside": None, "reason": str(exc)},
            "robustness": None, "notes": [str(exc)], "fell_back": True,
            "fallback": {"fell_back": True, "from": name, "to": None, "why": str(exc),
                         "attempts": exc.attempts}}
