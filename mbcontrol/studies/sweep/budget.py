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
- resource: where the site file has one weight column per year, the spread of the annual
  energy over the years; its mean's uncertainty is std / sqrt(years).
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


def parameters(weights, gradients, covariance, names, source: str) -> dict:
    """Type B through linearised sensitivities: gradients (n_sea, n_par) in W per unit."""
    G = MWH_PER_W * np.nansum(np.asarray(weights, float)[:, None] * np.asarray(gradients), 0)
    u = float(math.sqrt(max(float(G @ np.asarray(covariance) @ G), 0.0)))
    return component("parameters", "B", "linear", u, source=source,
                     sensitivity_MWh_per_unit=dict(zip(names, G.tolist())))


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
    budget = {"components": rows, "combined_std_MWh": u_c,
              "effective_dof": None if math.isinf(dof) else dof, "coverage_factor": k,
              "method": "independent components in quadrature; 95 % interval annual energy "
                        "+- k u_c, k Student's t at the Welch-Satterthwaite degrees of "
                        "freedom (GUM; IEC TS 62600-100 Annex D's statistical/systematic "
                        "split)"}
    return [aep_MWh - k * u_c, aep_MWh + k * u_c], budget


def table(budget: dict) -> str:
    """Plain text: one line per component."""
    lines = [f"{'component':14s} {'type':4s} {'over seas':10s} {'std MWh':>9s} {'share':>6s}"
             "  source"]
    for c in budget["components"]:
        if c["std_MWh"] is None:
            lines.append(f"{c['component']:14s} {c['type']:4s} {c['over_seas']:10s} "
                         f"{'-':>9s} {'-':>6s}  absent: {c['absent']}")
        else:
            lines.append(f"{c['component']:14s} {c['type']:4s} {c['over_seas']:10s} "
                         f"{c['std_MWh']:9.4g} {100 * c['share_of_variance']:5.1f}%  "
                         f"{c['source']}")
    lines.append(f"combined {budget['combined_std_MWh']:.4g} MWh (1 sigma), k = "
                 f"{budget['coverage_factor']:.3g}")
    return "\n".join(lines)
