"""The frequency-domain sweep's Dataset and summary, in the time-domain sweep's format
(`study._summary`: the `mbcontrol sweep --json` contract), so that whatever reads one reads
the other; and the per-sea comparison of the two (`--domain both`). Powers in W, energy in MWh.
"""
from __future__ import annotations

import math

import numpy as np
import xarray as xr

from ...waves import annual_energy_MWh


def frequency_dataset(plant, seas, result: dict, width: float | None) -> xr.Dataset:
    """The sweep's Dataset as `store.assemble` lays it out (sea x one seed), so that
    `power_matrix` and `plot_sweep` take it: mean_power_W, conjugate_bound_W (W),
    energy_flux_W_per_m, capture_width_m (and capture_width_ratio with a width, m)."""
    power = result["power_W"][:, None]
    failed = ~np.isfinite(power)
    ds = xr.Dataset(
        {"mean_power_W": (("sea", "seed"), power, {"units": "W", "long_name":
                          "linear theory's mean absorbed power (frequency domain)"}),
         "conjugate_bound_W": (("sea", "seed"), result["bound_W"][:, None], {
             "units": "W", "long_name": "multiport complex-conjugate bound (linear theory)"}),
         "valid": (("sea", "seed"), ~failed), "failed": (("sea", "seed"), failed),
         "invalid_reasons": (("sea", "seed"), np.array([[r or ""] for r in result["reasons"]],
                                                       dtype=str)),
         "energy_flux_W_per_m": ("sea", result["energy_flux_W_per_m"])},
        coords={"sea": np.arange(len(seas)), "seed": [0],
                "hs": ("sea", [s.hs for s in seas]), "tp": ("sea", [s.tp for s in seas]),
                "te": ("sea", [s.te for s in seas]), "gamma": ("sea", [s.gamma for s in seas]),
                "weight": ("sea", [s.weight for s in seas])},
        attrs={"model": plant.scene.name, "domain": "frequency"})
    ds["capture_width_m"] = ds["mean_power_W"] / ds["energy_flux_W_per_m"]
    if width:
        ds["capture_width_ratio"] = ds["capture_width_m"] / width
        ds.attrs["characteristic_width_m"] = width
    rated = sum(p.rated_power for p in plant.scene.ptos)
    if plant.scene.ptos and math.isfinite(rated):
        ds.attrs["rated_power_W"] = float(rated)
    return ds


def _number(value):
    """A float for JSON, None where there is none (NaN); inf stays (an unbounded bound)."""
    value = float(value)
    return None if math.isnan(value) else value


def _rows(ds, seas, result: dict) -> list[dict]:
    """Per sea: the time-domain sweep's row keys, and the conjugate bound with its share."""
    rows = []
    cw, flux = ds["capture_width_m"].values[:, 0], ds["energy_flux_W_per_m"].values
    ratio = ds["capture_width_ratio"].values[:, 0] if "capture_width_ratio" in ds else None
    for k, s in enumerate(seas):
        power, bound = _number(result["power_W"][k]), _number(result["bound_W"][k])
        row = {"hs": s.hs, "tp": s.tp, "weight": None if math.isnan(s.weight) else s.weight,
               "mean_power_W": power, "capture_width_m": _number(cw[k]),
               "energy_flux_W_per_m": float(flux[k]),
               "invalid_cases": 0, "failed_cases": int(result["reasons"][k] is not None),
               "conjugate_bound_W": bound,
               "percent_of_conjugate_bound": None if power is None or not bound
               or math.isinf(bound) else 100 * power / bound}
        if not math.isnan(s.te):
            row["te"] = s.te
        if not math.isnan(s.direction):
            row["direction_deg"] = math.degrees(s.direction)
        if ratio is not None:
            row["capture_width_ratio"] = _number(ratio[k])
        rows.append(row)
    return rows


def _annual(ds, seas, result: dict, notes: list) -> dict:
    """The weighted figures as the time-domain sweep makes them: a sea with no power counts
    as nothing (coverage below 1), the power capped at the PTOs' rated power; the conjugate
    bound's annual energy beside them (uncapped)."""
    weights = np.array([s.weight for s in seas], float)
    out = {"weighted_mean_power_W": None, "annual_energy_MWh": None,
           "annual_energy_coverage": None, "annual_energy_unchecked_MWh": None,
           "zero_seas": [], "weighted_conjugate_bound_W": None,
           "annual_energy_conjugate_bound_MWh": None}
    if np.any(np.isnan(weights)):
        return out
    power = result["power_W"]
    missing = np.isnan(power) & (weights > 0)
    held = np.where(np.isnan(power), 0.0, power)
    unchecked = annual_energy_MWh(held, weights)
    rated = ds.attrs.get("rated_power_W")
    if rated is not None and np.any(held > rated):
        notes.append(f"{int(np.sum(held > rated))} seas are capped at the rated power "
                     f"{rated / 1e3:.4g} kW: annual energy "
                     f"{annual_energy_MWh(np.minimum(held, rated), weights):.4g} MWh, "
                     f"{unchecked:.4g} MWh uncapped")
        held = np.minimum(held, rated)
    out.update(weighted_mean_power_W=float(np.sum(weights * held)),
               annual_energy_MWh=annual_energy_MWh(held, weights),
               annual_energy_coverage=float(1.0 - weights[missing].sum()),
               annual_energy_unchecked_MWh=unchecked)
    bound = np.where(np.isnan(result["bound_W"]), 0.0, result["bound_W"])
    if np.all(np.isfinite(bound)):
        out.update(weighted_conjugate_bound_W=float(np.sum(weights * bound)),
                   annual_energy_conjugate_bound_MWh=annual_energy_MWh(bound, weights))
    return out


def frequency_summary(plant, seas, ds, result: dict, *, gains: dict, controller, settings,
                      duration: float) -> dict:
    """The summary of `frequency_domain.frequency_sweep` (the time-domain sweep's keys, with
    "domain", "law" (pto -> damping, stiffness), "frequency_grid" and the bound's figures)."""
    from ...plant import provenance
    from .made_by import sweep_provenance
    notes = [f"frequency domain: linear theory straight from the BEM data, the law F = -(c v + "
             f"k x) ({', '.join(f'{n} c {c:.4g}, k {k:.4g}' for n, (c, k) in gains.items())}) "
             f"with no force or stroke limit, the seas of {duration:g} s records; nothing "
             f"simulated (--domain time or both for the simulation)"]
    failed = [{"hs": s.hs, "tp": s.tp, "seed": 0, "reasons": reason}
              for s, reason in zip(seas, result["reasons"]) if reason is not None]
    if failed:
        notes.append(f"{len(failed)} of {len(seas)} seas have no power (listed with their "
                     f"reason): they count as nothing in the annual figures")
    unbounded = int(np.sum(np.isinf(result["bound_W"])))
    if unbounded:
        notes.append(f"{unbounded} seas excite a PTO where it sees no dissipation: their "
                     f"complex-conjugate bound is unbounded (inf)")
    annual = _annual(ds, seas, result, notes)
    made_by = sweep_provenance({"model": plant.scene.name, **provenance(plant)}, controller,
                               settings, {}, {}, amplitudes="deterministic", nonlinear="scene",
                               identified=None, design=False, robust=False, measured=None)
    summary = {"model": plant.scene.name, "domain": "frequency", "cases": len(seas),
               "computed": len(seas), "reused": 0, "wall_time_s": None,
               "valid_cases": len(seas) - len(failed), "invalid_cases": 0, "invalid": [],
               "failed_cases": len(failed), "failed": failed, "notes": notes,
               "seas": _rows(ds, seas, result), **annual,
               "law": {n: {"damping": float(c), "stiffness": float(k)}
                       for n, (c, k) in gains.items()},
               "frequency_grid": {"groups": result["groups"],
                                  "components": result["components"],
                                  "duration_s": float(duration)},
               "provenance": {**made_by, "domain": "frequency"}}
    if "rated_power_W" in ds.attrs:
        summary["rated_power_W"] = ds.attrs["rated_power_W"]
    return summary


def compare_domains(time_summary: dict, frequency: dict) -> dict:
    """`--domain both`: the time-domain summary with, per sea, "frequency_domain_power_W"
    and "relative_difference" (time / frequency - 1: the simulation against linear theory),
    and "frequency_domain" (the frequency-domain summary's weighted figures and timing)."""
    for row, fd in zip(time_summary["seas"], frequency["seas"]):
        p_td, p_fd = row["mean_power_W"], fd["mean_power_W"]
        row["frequency_domain_power_W"] = p_fd
        row["conjugate_bound_W"] = fd["conjugate_bound_W"]
        row["relative_difference"] = (p_td / p_fd - 1.0 if isinstance(p_td, float)
                                      and math.isfinite(p_td) and p_fd else None)
    time_summary["frequency_domain"] = {key: frequency[key] for key in (
        "weighted_mean_power_W", "annual_energy_MWh", "weighted_conjugate_bound_W",
        "annual_energy_conjugate_bound_MWh", "compute_time_s", "wall_time_s", "law",
        "frequency_grid", "failed_cases")}
    time_summary["domain"] = "both"
    return time_summary
