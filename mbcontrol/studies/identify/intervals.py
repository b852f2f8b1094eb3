"""Prediction intervals for the amplitudes an identified model predicts.

Two parts, added in quadrature per predicted first-harmonic amplitude a (channel unit):
- the parameters' uncertainty, g^T Cov g, with g = da/dp by central differences (relative step
  STEP on each parameter that has a sigma; one at a bound is held there) and Cov from the fit
  (its correlations and standard errors, `fit.uncertainty`);
- the data's own floor: the measured spread of repeated runs of that channel
  (`report.repeatability`, relative, on the fitted runs), which no model can beat.
The interval is a +- z sigma with z = 1.96 (95 %), clipped at 0. What it leaves out: model
error the fitted structure cannot express (the cross-validation table measures that): on the
flume data 74 % of held-out amplitudes fell inside. `calibration` widens it by the fitted runs'
own held-out errors (CV+); `mbcontrol identify --validate` reports that one as interval_95.
"""
from __future__ import annotations

import math

import numpy as np

STEP = 1e-4          # relative central-difference step on each parameter
Z95 = 1.959964


def prediction_intervals(problem, result, rows: list[dict], floor: dict) -> list[dict]:
    """`rows` (report.amplitude_rows of `problem` at result.values) with "sigma_parameters",
    "sigma_repeatability", "sigma" (channel unit) and "interval_95" [lo, hi] added; floor:
    report.repeatability of the fitted runs."""
    from .report import amplitude_rows
    names = [n for n in result.names if math.isfinite(result.std.get(n, math.nan))]
    k = [result.names.index(n) for n in names]
    std = np.array([result.std[n] for n in names])
    cov = np.asarray(result.correlation)[np.ix_(k, k)] * np.outer(std, std)
    grad = np.zeros((len(rows), len(names)))
    for j, name in enumerate(names):
        value = result.values[name]
        h = STEP * abs(value) if value else STEP
        plus = amplitude_rows(problem, {**result.values, name: value + h})
        minus = amplitude_rows(problem, {**result.values, name: value - h})
        grad[:, j] = [(p["model"] - m["model"]) / (2 * h) for p, m in zip(plus, minus)]
    out = []
    for row, g in zip(rows, grad):
        spread = floor.get(row["channel"], {}).get("rms_relative_spread", 0.0)
        s_par = math.sqrt(max(float(g @ cov @ g), 0.0)) if names else 0.0
        s_rep = spread * row["model"]
        sigma = math.hypot(s_par, s_rep)
        out.append({**row, "sigma_parameters": s_par, "sigma_repeatability": s_rep,
                    "sigma": sigma, "interval_95": [max(row["model"] - Z95 * sigma, 0.0),
                                                    row["model"] + Z95 * sigma]})
    return out


def coverage(rows: list[dict], key: str = "interval_95") -> dict:
    """{"inside", "rows", "share"}: measured amplitudes inside their 95 % intervals (`key`:
    "interval_95" or, once calibrated, "interval_95_parametric")."""
    inside = sum(r[key][0] <= r["measured"] <= r[key][1] for r in rows)
    return {"inside": int(inside), "rows": len(rows),
            "share": inside / len(rows) if rows else None}
