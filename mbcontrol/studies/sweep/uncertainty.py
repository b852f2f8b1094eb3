"""How sure a sweep's numbers are: per sea the spectral scatter of a linear law's power, and for
a weighted list the annual energy's 95 % interval with its budget (`budget`).

Inputs beyond the sweep itself: an identification's summary (`mbcontrol identify --json` or
its summary.json: the fitted parameters, their covariance and the model's relative amplitude
error) and a site file's per-year weights (`waves.read_year_weights`).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ...errors import InputError
from . import budget as bud
from .scene_parameters import efficiency_gradients, relative_gradients
from .spectral import radiation_fit_effect, parameter_gradient, sea_components, sea_gains, \
    spectral_row
from .terms import electrical_power, nonlinear_component, nonlinear_difference, pto_means, \
    scene_component


def read_identified(path, model: str, plant_parameters) -> dict:
    """{"values": name -> value, "names", "covariance", "model_error", "model_error_source",
    "source"} from an identification summary; errors name the file and the field."""
    path = Path(path)
    try:
        summary = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: cannot read an identification summary ({exc})") from None
    for field in ("model", "parameters", "correlation", "fit"):
        if field not in summary:
            raise InputError(f"{path}: field {field!r} missing (expected the JSON of "
                             f"`mbcontrol identify --json` or its summary.json)")
    if summary["model"] != model:
        raise InputError(f"{path}: field 'model' is {summary['model']!r}; this sweep runs "
                         f"{model!r} (an identification applies to the model it fitted)")
    names_all = list(summary["parameters"])
    unknown = [n for n in names_all if n not in plant_parameters]
    if unknown:
        raise InputError(f"{path}: field 'parameters' names {unknown[0]!r}, not a parameter "
                         f"of {model} ({', '.join(plant_parameters)})")
    values = {n: float(summary["parameters"][n]["value"]) for n in names_all}
    keep = [i for i, n in enumerate(names_all) if summary["parameters"][n].get("std")]
    names = [names_all[i] for i in keep]
    std = np.array([summary["parameters"][n]["std"] for n in names], float)
    corr = np.asarray(summary["correlation"], float)
    if corr.shape != (len(names_all), len(names_all)):
        raise InputError(f"{path}: field 'correlation' is {corr.shape}; expected "
                         f"{len(names_all)} x {len(names_all)} (one row per parameter)")
    cov = corr[np.ix_(keep, keep)] * np.outer(std, std)
    return {"values": values, "names": names, "covariance": cov, **_model_error(summary),
            "source": str(path)}


def _model_error(summary: dict) -> dict:
    """The identified model's relative amplitude error (1 sigma) and where it comes from: the
    calibrated one (the CV+ quantile of held-out relative errors at 95 %, / 1.96), else the
    validation runs' RMS relative error, else the fitted runs' (in sample: optimistic)."""
    calibration = summary.get("calibration") or {}
    if calibration.get("quantile") is not None and calibration.get("alpha"):
        from scipy.stats import norm
        z = float(norm.ppf(1 - calibration["alpha"] / 2))
        return {"model_error": float(calibration["quantile"]) / z,
                "model_error_source": f"calibrated held-out errors ({calibration['method']}, "
                                      f"quantile {calibration['quantile']:.3g} / {z:.3g})"}
    block, where = (summary.get("validation"), "validation runs (out of sample)")
    if not block or block.get("rms_error") is None:
        block, where = summary["fit"], "fitted runs (in sample: optimistic)"
    return {"model_error": float(block["rms_error"]), "model_error_source": where}


def add_uncertainty(summary: dict, ds, seas, plant, *, controller, settings, params,
                    duration: float, amplitudes: str, identified: dict | None = None,
                    years=None) -> None:
    """Adds to `summary` (in place): per sea the spectral entries of a linear law, and for a
    weighted list "annual_energy_ci95_MWh" and "annual_energy_budget" (with an
    identification also per sea "model_std_W" and "parameter_std_W", W); where the scene
    converts (a drivetrain, an efficiency below 1) "annual_electrical_energy_MWh" with its
    own "annual_electrical_energy_ci95_MWh" and "annual_electrical_energy_budget". years:
    label -> per-year weights (`waves.read_year_weights`) or a buoy record's blocks
    (`resource.ndbc_resource`)."""
    rows = summary["seas"]
    if ds["mean_power_W"].ndim != 2:           # other quantities varied: no single law per sea
        return
    laws, why_not, waves = [], None, []
    for k, sea in enumerate(seas):
        gains, why = sea_gains(ds, k, plant, controller, settings, params)
        laws.append(gains)
        why_not = why_not or why
        if gains is None:
            waves.append(None)
            continue
        wave, rms = sea_components(plant, sea, duration)
        waves.append(wave)
        n_valid = rows[k].get("valid_seeds", int(ds["valid"].isel(sea=k).sum()))
        rows[k].update(spectral_row(plant, wave, rms, gains, duration, amplitudes, n_valid,
                                    rows[k]["mean_power_W"]))
    if summary.get("annual_energy_MWh") is None:
        return
    weights = np.array([s.weight for s in seas])
    power = np.array([np.nan if r["mean_power_W"] is None else r["mean_power_W"]
                      for r in rows], float)
    rated = summary.get("rated_power_W") or ds.attrs.get("rated_power_W")
    capped = power >= rated if rated else np.zeros(power.size, bool)
    held = np.where(np.isfinite(power), power, 0.0)
    if rated:
        held = np.minimum(held, rated)
    inputs = _inputs(ds, plant, rows, waves, laws, weights, power, capped, identified=identified,
                     params=params, controller=controller, why_not=why_not)
    ones = np.ones(power.size)
    ci, table = bud.combine(summary["annual_energy_MWh"],
                            _components(inputs, ones, held, years, summary["annual_energy_MWh"],
                                        electrical=False))
    summary["annual_energy_ci95_MWh"], summary["annual_energy_budget"] = ci, \
        _noted(table, capped, summary)
    electric = electrical_power(ds, plant.scene, held)
    if electric is not None:
        aep_e = float(bud.MWH_PER_W * np.sum(weights * electric))
        scale = np.where(held > 0, electric / np.where(held > 0, held, 1.0), 1.0)
        ci, table = bud.combine(aep_e, _components(inputs, scale, electric, years, aep_e,
                                                   electrical=True))
        table["energy"] = ("electrical: the PTOs' mean electrical power (the drivetrain's "
                           "winding loss, else the efficiency both ways) of the causal law "
                           "simulated; each absorbed-power term scaled per sea by its "
                           "electrical-to-absorbed ratio")
        summary["annual_electrical_energy_MWh"] = aep_e
        summary["annual_electrical_energy_ci95_MWh"] = ci
        summary["annual_electrical_energy_budget"] = _noted(table, capped, summary)
    summary["annual_energy_budget"]["energy"] = "absorbed (mechanical)"


def _inputs(ds, plant, rows, waves, laws, weights, power, capped, *, identified, params,
            controller, why_not) -> dict:
    """Per-sea quantities (W, absorbed) every budget is made from."""
    out = {"weights": weights, "power": power, "why_not": why_not,
           "statistical": _statistical(rows, capped, power), "identified": identified}
    linear = all(g is not None for g in laws)
    if identified is not None:           # each sea's own share of the model's error
        for k, row in enumerate(rows):
            row["model_std_W"] = None if capped[k] or not np.isfinite(power[k]) else \
                2 * identified["model_error"] * power[k]
        out["model_W"] = np.where(capped, 0.0, 2 * identified["model_error"]
                                  * np.nan_to_num(power))
    out["radiation_W"] = np.array([0.0 if capped[k] else radiation_fit_effect(
        plant, waves[k], laws[k], params) for k in range(len(waves))]) * np.nan_to_num(power) \
        if linear else None
    out["parameters"] = _parameters(identified, plant, waves, laws, params=params,
                                    controller=controller, capped=capped, power=power,
                                    rows=rows, weights=weights, why_not=why_not)
    out["nonlinear"] = nonlinear_difference(ds, capped)
    from ...scene import scene_uncertainty
    items = scene_uncertainty(plant.scene)
    out["items"] = items
    skip = capped | ~(np.nan_to_num(power) > 0)
    out["scene_rel"] = relative_gradients(plant, waves, laws, items, params=params, skip=skip) \
        if items and linear else None
    eta = {p.name: p.efficiency for p in plant.scene.ptos}
    out["scene_eff"] = efficiency_gradients(items, *pto_means(ds, plant.scene), eta) \
        if items else None
    if out["scene_eff"] is not None:
        out["scene_eff"][skip] = 0.0
    return out


def _components(inputs: dict, scale, power_W, years, aep: float, *, electrical: bool) -> list:
    """The budget's rows for one energy (absorbed: scale 1; electrical: per sea P_e / P)."""
    w, why_not = inputs["weights"], inputs["why_not"]
    stderr, dof = inputs["statistical"]
    out = [bud.statistical(w, stderr * scale, dof)]
    out.append(_model(inputs["identified"], w, inputs.get("model_W"), scale))
    out.append(bud.linear_over_seas(
        "radiation_fit", w, inputs["radiation_W"] * scale,
        "linear theory's power with the state-space radiation fit over that with the BEM "
        "data, per sea, times the simulated power") if inputs["radiation_W"] is not None
        else bud.absent("radiation_fit", "B", "linear", f"needs a linear law ({why_not})"))
    out.append(nonlinear_component(w, *inputs["nonlinear"], scale))
    out.append(inputs["parameters"](scale) if callable(inputs["parameters"])
               else inputs["parameters"])
    out.append(scene_component(inputs["items"], inputs["scene_rel"], inputs["scene_eff"], w,
                               inputs["power"], scale, electrical=electrical, why_not=why_not))
    if years is None or (isinstance(years, dict) and not years):
        out.append(bud.absent("resource", "A", "one term", (
            "no year-to-year record: give the site file weights_<year> columns, or "
            "--resource with NDBC spectral files (one per year, or one year: monthly blocks)")))
    elif isinstance(years, dict):
        out.append(bud.resource(years, power_W))
    else:
        out.append(bud.resource_blocks(years, power_W, aep))
    return out


def _noted(table: dict, capped, summary) -> dict:
    notes = []
    if capped.any():
        notes.append(f"{int(capped.sum())} seas at the rated power carry no uncertainty (the "
                     f"cap holds their power)")
    if summary.get("annual_energy_coverage", 1.0) < 1.0:
        notes.append("seas with no valid case count as producing nothing: the interval is on "
                     "a lower bound of the annual energy (annual_energy_coverage)")
    if notes:
        table["notes"] = notes
    return table


def _statistical(rows, capped, power) -> tuple[np.ndarray, np.ndarray]:
    """Each sea's standard error (W) and its degrees of freedom: from its seeds, else
    spectral; 0 where its power is held (capped at the rated power) or counted as nothing (no
    valid case); NaN where there is no estimate."""
    stderr, dof = [], []
    for r, p, held in zip(rows, power, capped):
        if held or not np.isfinite(p):
            stderr.append(0.0)
            dof.append(math.inf)
        elif r.get("mean_power_stderr_W") is not None:
            stderr.append(r["mean_power_stderr_W"])
            dof.append(r["valid_seeds"] - 1)
        elif r.get("spectral_stderr_W") is not None:
            stderr.append(r["spectral_stderr_W"])
            dof.append(math.inf)
        else:
            stderr.append(math.nan)
            dof.append(math.inf)
    return np.array(stderr, float), np.array(dof, float)


def _model(identified, weights, model_W, scale) -> dict:
    if identified is None:
        return bud.absent("model", "B", "linear", "no identification given (--identified): "
                          "the model's error against measurements is not known here")
    r = identified["model_error"]
    return bud.linear_over_seas(
        "model", weights, model_W * scale,
        f"identification's relative amplitude error {100 * r:.3g} % (1 sigma) from its "
        f"{identified['model_error_source']}, x2 for power ({identified['source']})")


def _parameters(identified, plant, waves, laws, *, params, controller, capped, power, rows,
                weights, why_not):
    """The identified parameters' term as a function of the per-sea scale (or an absent
    row): gradients computed once."""
    if identified is None or not identified["names"]:
        return bud.absent("parameters", "B", "linear",
                          "no identified parameters with standard errors (--identified)")
    if any(g is None for g in laws):
        return bud.absent("parameters", "B", "linear", f"needs a linear law ({why_not})")
    values = {**identified["values"], **dict(params or {})}
    grads = np.array([np.zeros(len(identified["names"])) if capped[k] or not power[k] > 0
                      else power[k] * parameter_gradient(plant, waves[k], laws[k],
                                                         identified["names"], values,
                                                         scene_law=controller is None)
                      for k in range(len(waves))])
    for k, row in enumerate(rows):        # each sea's spread from the parameters alone
        row["parameter_std_W"] = float(np.sqrt(max(grads[k] @ identified["covariance"]
                                                   @ grads[k], 0.0)))
    return lambda scale: bud.parameters(
        weights, grads * scale[:, None],
        identified["covariance"], identified["names"],
        f"{len(identified['names'])} identified parameters' covariance through linear "
        f"theory's relative sensitivities (central differences) times the simulated power")
