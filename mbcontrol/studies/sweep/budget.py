"""The annual energy's uncertainty budget and its 95 % interval (IEC TS 62600-100's split).

Each component is a standard uncertainty of the mean annual energy production (MWh, 1 sigma):
- statistical (Type A): each sea's standard error of its mean power, from its seeds (Student:
  n - 1 degrees of freedom) or, with one seed of a linear law, the spectral estimate
  (`analysis.power_statistics`); independent between seas, so added in quadrature over seas:
  u = H sqrt(sum (w_i u_i)^2), H = 8766 h / 1e6 (MWh per W over a year);
- model (Type B): the identified model's relative amplitude error r (out of sample where the
  identification validated), a relative power error 2 r (P ~ amplitude^2), the same sign in
  every sea, so added linearly: u = H sum w_i 2 r P_i;
- radiation fit (Type B): linear theory's power with the state-space radiation the simulation
  steps minus that with the BEM data, per sea; linear over seas, the sum's size taken as the standard
  uncertainty (the fit's error is known in size, not in what the truth would do);
- parameters (Type B): the identified parameters' covariance C through each sea's power
  sensitivity g_i (linear theory, central differences); the same parameters in every sea, so
  u = sqrt(G^T C G), G = H sum w_i g_i;
- linear_vs_nonlinear (Type B): per sea the linear run's power minus the nonlinear one's where
  a --nonlinear invalid sweep ran both, linear over seas (`terms`);
- scene_parameters (Type B): the scene's [[uncertainty]] tables (masses, drag, efficiency),
  a diagonal covariance through `parameters` (`scene_parameters`), each with its own share;
- resource: where the site file has one weight column per year, the spread of the annual
  energy over the years; its mean's uncertainty is std / sqrt(years); or a buoy record's
  blocks (`resource_blocks`: years, or one year's months by a month-block bootstrap).
Each present row carries share_of_variance = u_i^2 / u_c^2 (they sum to 1).
A component that cannot be evaluated is listed with the reason (absent), never counted as 0
silently. Components are independent: u_c = sqrt(sum u^2); the interval is AEP +- k u_c with
k Student's t(0.975) at the Welch-Satterthwaite degrees of freedom (1.96 when all are Type B).
"""
from __future__ import annotations

import math

import numpy as np

from ...waves import HOURS_PER_YEAR

MWH_PER_W = HOURS_PER_YEAR / 1e6


def component(name: str, kind: str, over_seas: str, std_MWh=None, *, dof=math.inf,
              source: str = "", absent: str | None = None, **extra) -> dict:
    """One row of the budget; std_MWh None with `absent` saying why."""
    return {"component": name, "type": kind, "over_seas": over_seas,
            "std_MWh": None if std_MWh is None else float(std_MWh),
            "dof": None if dof is None or math.isinf(dof) else float(dof),
            "source": source, "absent": absent, **extra}


def statistical(weights, stderr_W, dof) -> dict:
    """Type A over seas in quadrature; stderr_W (W) and dof per sea (NaN stderr: no estimate,
    counted and said; inf dof: a spectral estimate)."""
    w, s, nu = (np.asarray(x, float) for x in (weights, stderr_W, dof))
    known = np.isfinite(s) & (w > 0)
    lacking = int(np.sum(~np.isfinite(s) & (w > 0)))
    if not known.any():
        return component("statistical", "A", "quadrature", absent=(
            "no sea has an estimate of its mean power's scatter: a nonlinear law or plant "
            "with one seed (run --seeds 2 or more)"))
    terms = MWH_PER_W * w[known] * s[known]
    u = float(np.sqrt(np.sum(terms ** 2)))
    finite = np.isfinite(nu[known])
    denominator = np.sum(terms[finite] ** 4 / nu[known][finite])
    dof_total = u ** 4 / denominator if denominator > 0 else math.inf
    kinds = []
    if finite.any():
        kinds.append(f"{int(finite.sum())} seas from their seeds' standard error")
    if (~finite).any():
        kinds.append(f"{int((~finite).sum())} from the spectral estimate (one record of a "
                     f"linear law)")
    note = "; ".join(kinds)
    if lacking:
        note += f"; {lacking} weighted seas without an estimate are left out of it"
    return component("statistical", "A", "quadrature", u, dof=dof_total, source=note,
                     seas_without_estimate=lacking)


def linear_over_seas(name: str, weights, per_sea_W, source: str) -> dict:
    """A systematic component: the same sign in every sea, so summed over seas (the sum's size)."""
    w, d = np.asarray(weights, float), np.asarray(per_sea_W, float)
    signed = float(MWH_PER_W * np.nansum(w * d))
    return component(name, "B", "linear", abs(signed), source=source, signed_MWh=signed)


def parameters(weights, gradients, covariance, names, source: str,
               name: str = "parameters") -> dict:
    """Type B through linearised sensitivities: gradients (n_sea, n_par) in W per unit;
    with each parameter's own share of the variance where the covariance is diagonal."""
    G = MWH_PER_W * np.nansum(np.asarray(weights, float)[:, None] * np.asarray(gradients), 0)
    C = np.asarray(covariance, float)
    u = float(math.sqrt(max(float(G @ C @ G), 0.0)))
    extra = {}
    if np.count_nonzero(C - np.diag(np.diag(C))) == 0:
        extra["std_MWh_by_parameter"] = dict(zip(names, (np.abs(G) * np.sqrt(np.diag(C)))
                                                 .tolist()))
    return component(name, "B", "linear", u, source=source,
                     sensitivity_MWh_per_unit=dict(zip(names, G.tolist())), **extra)


def resource(years: dict, power_W) -> dict:
    """years: label -> weights of each sea in that year; the annual energy per year with the
    same powers, its spread (interannual_std_MWh) and its mean's uncertainty std / sqrt(Y)."""
    p = np.nan_to_num(np.asarray(power_W, float))
    per_year = {y: float(MWH_PER_W * np.sum(np.asarray(w, float) * p)) for y, w in years.items()}
    values = np.array(list(per_year.values()))
    spread = float(np.std(values, ddof=1))
    return component("resource", "A", "one term", spread / math.sqrt(values.size),
                     dof=values.size - 1, source=f"{values.size} years of the site's weights",
                     interannual_std_MWh=spread, annual_energy_by_year_MWh=per_year)


def resource_blocks(resource, power_W, aep_MWh: float) -> dict:
    """A buoy record's blocks (`resource.Resource`): each block's annual energy with the same
    powers; their relative spread (year blocks: ddof 1; month blocks: the month-block
    bootstrap's) applied to the site's annual energy, over sqrt(years) of record."""
    from .resource import block_spread
    p = np.nan_to_num(np.asarray(power_W, float))
    per_block = {b: float(MWH_PER_W * np.sum(np.asarray(w, float) * p))
                 for b, w in resource.weights.items()}
    values = np.array(list(per_block.values()))
    spread, dof = block_spread(values, resource.kind)
    relative = spread / float(np.mean(values)) if np.mean(values) > 0 else 0.0
    n_years = len(values) if resource.kind == "year" else 1
    if resource.kind == "year":
        how = f"{n_years} years of buoy record ({', '.join(resource.files)})"
    else:
        how = (f"ONE year of buoy record ({', '.join(resource.files)}): interannual variability "
               f"ESTIMATED from {len(values)} monthly blocks (bootstrap of months as "
               f"exchangeable blocks, sigma_m / sqrt(12); the seasonal cycle counts as "
               f"variability, so an upper estimate)")
    return component("resource", "A", "one term", relative * aep_MWh / math.sqrt(n_years),
                     dof=dof, source=how + "; its relative spread times the site's annual "
                     "energy; hours to the nearest site sea in (Hm0, Te) over their ranges",
                     interannual_relative_std=relative,
                     interannual_std_MWh=relative * aep_MWh, blocks=resource.kind,
                     annual_energy_by_block_MWh=per_block, notes=list(resource.notes))


def absent(name: str, kind: str, over_seas: str, why: str) -> dict:
    return component(name, kind, over_seas, absent=why)


def combine(aep_MWh: float, components: list[dict]) -> tuple[list[float], dict]:
    """([lo, hi], budget): the 95 % interval on the annual energy and the budget table
    (components with their share of the variance, combined_std_MWh, dof, coverage_factor)."""
    from scipy.stats import t as student
    present = [c for c in components if c["std_MWh"] is not None]
    u_c = math.sqrt(sum(c["std_MWh"] ** 2 for c in present))
    denominator = sum(c["std_MWh"] ** 4 / c["dof"] for c in present
                      if c["dof"] is not None and c["dof"] > 0)
    dof = u_c ** 4 / denominator if denominator > 0 else math.inf
    k = float(student.ppf(0.975, dof)) if math.isfinite(dof) else 1.959964
    rows = [{**c, "share_of_variance": (c["std_MWh"] ** 2 / u_c ** 2 if u_c > 0 else 0.0)
             if c["std_MWh"] is not None else None} for c in components]
    for row in rows:            # a diagonal parameter term: each parameter's own share too
        if u_c > 0 and row.get("std_MWh_by_parameter"):
            row["share_of_variance_by_parameter"] = {
                n: u ** 2 / u_c ** 2 for n, u in row["std_MWh_by_parameter"].items()}
    budget = {"components": rows, "combined_std_MWh": u_c,
              "effective_dof": None if math.isinf(dof) else dof, "coverage_factor": k,
              "method": "independent components in quadrature; 95 % interval annual energy "
                        "+- k u_c, k Student's t at the Welch-Satterthwaite degrees of "
                        "freedom (GUM; IEC TS 62600-100 Annex D's statistical/systematic "
                        "split)"}
    return [aep_MWh - k * u_c, aep_MWh + k * u_c], budget


def table(budget: dict) -> str:
    """Plain text: one line per component."""
    lines = [f"{'component':19s} {'type':4s} {'over seas':10s} {'std MWh':>9s} {'share':>6s}"
             "  source"]
    for c in budget["components"]:
        if c["std_MWh"] is None:
            lines.append(f"{c['component']:19s} {c['type']:4s} {c['over_seas']:10s} "
                         f"{'-':>9s} {'-':>6s}  absent: {c['absent']}")
        else:
            lines.append(f"{c['component']:19s} {c['type']:4s} {c['over_seas']:10s} "
                         f"{c['std_MWh']:9.4g} {100 * c['share_of_variance']:5.1f}%  "
                         f"{c['source']}")
            for n, share in (c.get("share_of_variance_by_parameter") or {}).items():
                lines.append(f"  {n:35s} {c['std_MWh_by_parameter'][n]:9.4g} "
                             f"{100 * share:5.1f}%")
    lines.append(f"combined {budget['combined_std_MWh']:.4g} MWh (1 sigma), k = "
                 f"{budget['coverage_factor']:.3g}; share: u_i^2 / u_c^2")
    return "\n".join(lines)
