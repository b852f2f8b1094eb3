"""What the linear model's envelope costs, on a plant that covers large motions.

`design` tunes a passive or reactive law inside the envelope of linear hydrodynamics
(analysis.envelope: significant relative heave within the mean draft, roll and pitch within
30 deg, times "envelope.share"), because beyond it the linear model's numbers are not to be
trusted. A plant with nonlinear hydrostatics and Froude-Krylov forces ([hydro] hydrostatics =
froude_krylov = "nonlinear") covers those motions, so the envelope need not hold the
controller back there. `lifted_envelope` tunes the same law with the envelope lifted (the
PTO's force and stroke limits kept), simulates it on that plant and reports how far into the
former envelope it goes and the power it gains. The controller is still designed on the
linear model and checked on the nonlinear one: the gain is what the nonlinear plant gives,
not what linear theory predicted (both are reported).
"""
from __future__ import annotations

from ... import defaults

GAINS_RTOL = 1e-3      # gains closer than this (relative) are the same law


def excursion_ratios(excursions: dict) -> dict:
    """{"<body> relative heave" | "<body> roll" | "<body> pitch": significant value / the
    validity check's limit} from a verdict's checks["excursions"] (1 is the edge of the
    linear model's range: the draft times "validity.draft_factor", "validity.angle_max")."""
    out = {}
    angle_max = defaults.get("validity.angle_max")
    for body, e in excursions.items():
        limits = {"relative heave": ("relative_heave",
                                     None if e.get("relative_heave_limit_m") is None
                                     else defaults.get("validity.draft_factor")
                                     * e["relative_heave_limit_m"]),
                  "roll": ("roll", angle_max), "pitch": ("pitch", angle_max)}
        for what, (key, limit) in limits.items():
            if limit and f"{key}_significant" in e:
                out[f"{body} {what}"] = float(e[f"{key}_significant"]) / limit
    return out


def lifted_envelope(plant, wave, name: str, pto_obj, design: dict, *, duration: float,
                    dt: float, score_from_s: float | None = None,
                    model_params=None, robust: bool = True) -> dict | None:
    """The law `name` tuned without the envelope, on `plant` (one with nonlinear pressure):
    {"parameters", "predicted_power_W" (linear theory), "mean_power_W" (the nonlinear
    plant's, W), "valid", "invalid_reasons", "envelope_used" (`excursion_ratios`), "binds"
    (whether the envelope changed the law), "gain_W" and "gain_percent"}. design: the
    design inside the envelope, {"parameters", "mean_power_W", "excursions" (its verdict's
    checks)}; where the lifted law is the same, its run is the design's and the gain is 0.
    Scored as the design was: from score_from_s (s; None: after the ramp). None where it does
    not apply: a plant without nonlinear pressure, a law that is not linear (kind),
    several PTOs (tuned jointly, without an envelope already). robust: as the design was
    tuned (within the robustness floors, or the unconstrained optimum)."""
    from mbcontrol.controllers import REGISTRY, make
    if (not plant.pressure or REGISTRY[name].kind != "linear"
            or len(plant.scene.ptos) > 1):
        return None
    from mbcontrol.analysis import pto_metrics, summary
    from mbcontrol.errors import SimulationError
    from mbcontrol.sim import simulate

    from .tuning import tune
    try:
        parameters, predicted, _, extra = tune(plant, wave, name, pto_obj, True, model_params,
                                               [], robust=robust, envelope=False)
    except ValueError as exc:          # the tuner cannot serve this sea without the envelope
        return {"parameters": {}, "predicted_power_W": None, "binds": None,
                "mean_power_W": None, "valid": False,
                "invalid_reasons": [f"not tuned without the envelope: {exc}"],
                "envelope_used": {}, "gain_W": None, "gain_percent": None}
    # the two tuners (with the envelope: a constrained search) land within ~1e-6 of each
    # other when it does not bind (OSWEC, PacWave): only a change past GAINS_RTOL is binding
    binds = any(abs(parameters.get(k, 0.0) - design["parameters"].get(k, 0.0))
                > GAINS_RTOL * max(1.0, abs(design["parameters"].get(k, 0.0)))
                for k in ("damping", "stiffness"))
    out = {"parameters": parameters, "predicted_power_W": predicted, "binds": binds}
    if not binds:                      # the same law: its run is the design's
        return {**out, "mean_power_W": design["mean_power_W"], "valid": design["valid"],
                "invalid_reasons": design["invalid_reasons"],
                "envelope_used": excursion_ratios(design["excursions"]), "gain_W": 0.0,
                "gain_percent": 0.0}
    try:
        ds = simulate(plant, wave, duration=duration, dt=dt,
                      controller=make(name, **parameters, **extra))
    except SimulationError as exc:
        return {**out, "mean_power_W": None, "valid": False,
                "invalid_reasons": [f"the simulation failed: {exc}"], "envelope_used": {},
                "gain_W": None, "gain_percent": None}
    if score_from_s is not None:
        ds.attrs["statistics_from_s"] = score_from_s
    report = summary(ds, plant)
    power = pto_metrics(ds, pto_obj)["mean_power_W"]
    gain = power - design["mean_power_W"]
    return {**out, "mean_power_W": power, "valid": report["valid"],
            "invalid_reasons": report["invalid_reasons"],
            "envelope_used": excursion_ratios(report["validity"].get("excursions", {})),
            "gain_W": gain, "gain_percent": 100 * gain / design["mean_power_W"]
            if design["mean_power_W"] else None}
