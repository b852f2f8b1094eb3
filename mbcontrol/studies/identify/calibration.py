"""Prediction intervals calibrated on the fitted runs' own held-out errors (CV+ over runs).

The parametric interval (`intervals.prediction_intervals`: parameter covariance and
repeatability) leaves out model error, and on the flume data held 46 of 62 held-out amplitudes
(74 %) in leave-one-series-out folds. Here the fitted runs are split into folds; each fold's
runs are predicted by a fit on the others (same structure, method and options), and each of
their amplitudes gives a normalised score

    R = |measured - model| / s,   s = model * sqrt(1 + (KAPPA * S)^2),   S = d ln a / d ln omega

(dimensionless): the relative error, with the scale widened where the predicted amplitude a is
sensitive to frequency, i.e. on the flanks of a resonance, where a small error in a natural
frequency moves the amplitude most (S by central differences, omega -/+ SLOPE_STEP). Relative
scores carry over between wave heights; absolute ones do not. A new amplitude's interval is
CV+ (`conformal.cv_plus_interval`): each fold's model predicts it, widened by every score of
that fold's held-out runs. The interval reported is the hull of it and the parametric one.

Folds: one per series (the runs' `group`) when the fitted runs span two or more, so every score
predicts a configuration its fit never saw (harsher than a new run of a fitted series); within
one series, up to MAX_FOLDS folds of frequencies (repeats of one frequency share a fold; the
frequencies dealt round-robin so each fold spans the band).

Guarantee (Barber et al. 2021): if the new runs are exchangeable with the fitted ones, CV+
covers with probability >= 1 - 2 alpha - min(2 (1 - 1/K) / (n/K + 1), (1 - K/n) / (K + 1))
(n scores, K folds; stated for equal folds) in the worst case, and about 1 - alpha in
practice. Runs of another wave height or frequency are not exchangeable with the fitted ones:
nothing is guaranteed there, the relative score is what makes it carry over. Rows of one run
share a fold and are not independent; scores pool every channel (a channel the fitted runs
lack is calibrated on the others'). With fewer than 1/alpha - 1 scores (19 at 95 %) no finite
quantile exists: from MIN_SCORES on the largest score is used (nominal level n/(n + 1), said in
the block), below it the parametric interval is kept and the block says why. Fold fits use the
main fit's structure and method from the scene's start (one start), less the parameters the
fold's runs cannot see (a DOF blocked in all of them: they keep the scene's values).
"""
from __future__ import annotations

import dataclasses
import time
import warnings

import numpy as np

from ... import defaults
from ...console import progress_bar
from .conformal import cv_plus_guarantee, cv_plus_interval, quantile_index

# ALPHA and KAPPA: the defaults "identify.alpha" (0.05: 95 % intervals) and "identify.kappa"
# (0.3: the frequency slope's weight in the scale; see the README's comparison)
SLOPE_STEP = 0.02     # relative step in omega for d ln a / d ln omega
MAX_FOLDS = 5         # folds of frequencies when the fitted runs are one series
MIN_SCORES = 9        # fewer than 1/ALPHA - 1 (19) scores: the largest, if n/(n+1) >= 90 %


def score_text() -> str:
    """The calibration score as the JSON block states it, with the "identify.kappa" in force."""
    return (f"|measured - model| / (model * sqrt(1 + ({defaults.get('identify.kappa')} * d ln a "
            f"/ d ln omega)^2)), each fold's runs predicted by a fit on the other folds")


def folds(runs) -> tuple[str, list[tuple[str, set]]]:
    """(how, [(fold name, names of its held-out runs)]): one fold per group when there are two
    or more, else up to MAX_FOLDS folds of frequencies (repeats together, dealt in turn)."""
    groups = sorted({r.group for r in runs})
    if len(groups) >= 2:
        return "leave one series out", [(g, {r.name for r in runs if r.group == g})
                                        for g in groups]
    omegas = sorted({round(r.omega, 6) for r in runs})
    k = min(MAX_FOLDS, len(omegas))
    if k < 2:
        return "none", []
    out = [(f"frequencies {', '.join(f'{w:.3g}' for w in omegas[i::k])} rad/s",
            {r.name for r in runs if round(r.omega, 6) in set(omegas[i::k])}) for i in range(k)]
    return f"{k} folds of frequencies within {groups[0]}", out


def frequency_slopes(problem, values: dict) -> dict:
    """{(run, channel): d ln a / d ln omega} of the model's first-harmonic amplitude a at
    `values`, by central differences over the runs driven at omega (1 -/+ SLOPE_STEP)."""
    from .report import amplitude_rows
    from .setup import prediction
    amp = {}
    for sign in (1, -1):
        shifted = [dataclasses.replace(r, omega=r.omega * (1 + sign * SLOPE_STEP))
                   for r in problem.runs]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # the shifted runs' own extrapolation notes
            rows = amplitude_rows(prediction(problem, shifted), values)
        amp[sign] = {(r["run"], r["channel"]): r["model"] for r in rows}
    step = np.log1p(SLOPE_STEP) - np.log1p(-SLOPE_STEP)
    return {key: float(np.log(amp[1][key] / amp[-1][key]) / step) if amp[1][key] > 0
            and amp[-1][key] > 0 else 0.0 for key in amp[1]}


def scale(model: float, slope: float) -> float:
    """The score's scale (channel unit): model * sqrt(1 + (KAPPA slope)^2), KAPPA the default
    "identify.kappa"."""
    return model * float(np.hypot(1.0, defaults.get("identify.kappa") * slope))


def _fold_rows(problem, values, runs) -> dict:
    """{(run, channel): (measured, model, scale)} of `runs` predicted by `problem`'s model."""
    from .report import amplitude_rows
    from .setup import prediction
    target = prediction(problem, runs)
    slopes = frequency_slopes(target, values)
    return {(r["run"], r["channel"]): (r["measured"], r["model"],
                                       scale(r["model"], slopes[(r["run"], r["channel"])]))
            for r in amplitude_rows(target, values)}


def calibrate(model: str, runs, validation, *, fit=(), method=None, progress: bool = False,
              alpha: float | None = None, **options) -> dict:
    """CV+ intervals for the `validation` runs' amplitudes from folds of the fitted `runs`
    (see the module). fit, method, options: as the main fit's (`setup.flume_identification`,
    `fit.fit`). Returns {"calibration": the JSON block (method, folds, score, n_scores,
    quantile_index, guarantee, ...), "intervals": {(run, channel): [lo, hi]} (channel unit;
    empty when not calibrated)}. alpha left out: the default "identify.alpha" (0.05)."""
    from .fit import fit as fit_problem
    alpha = defaults.resolve("identify.alpha", alpha)
    from .setup import flume_identification
    how, parts = folds(runs)
    n = sum(len(r.channels) for r in runs)
    asked = alpha
    if quantile_index(n, alpha) is None and n >= MIN_SCORES:
        alpha = 1 / (n + 1)          # too few for 1 - alpha: the largest score, level n/(n+1)
    k = quantile_index(n, alpha)
    block = {"method": None, "folds": how, "n_scores": n, "alpha": alpha,
             "nominal_coverage": 1 - alpha,
             "channels": sorted({c for r in runs for c in r.channels})}   # where scores come from
    if not parts or k is None:
        block["reason"] = (f"{n} scores from {len(runs)} fitted runs: at least {MIN_SCORES} "
                           f"needed (the largest then covers n/(n + 1) >= 90 %)" if parts
                           else "one frequency only: no folds")
        return {"calibration": block, "intervals": {}}
    started = time.perf_counter()
    bar = progress_bar(total=len(parts), desc="calibration folds", unit="fit",
                       leave=False) if progress else None
    scores, fold_of, centres, scales = [], [], [], []
    for i, (_, held) in enumerate(parts):
        train = [r for r in runs if r.name not in held]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # a fold's own fit notes are not the user's
            # the structure asked for, less what the fold's runs cannot see (a blocked DOF)
            problem = flume_identification(model, None, runs=train, fit=list(fit),
                                           drop_absent=True, **options)
            values = fit_problem(problem, method).values if problem.fit else {}
            for measured, mu, s in _fold_rows(problem, values,
                                              [r for r in runs if r.name in held]).values():
                scores.append(abs(measured - mu) / s if s > 0 else np.inf)
                fold_of.append(i)
            predicted = _fold_rows(problem, values, validation) if validation else {}
        keys = sorted(predicted)
        centres.append([predicted[key][1] for key in keys])
        scales.append([predicted[key][2] for key in keys])
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    intervals = {}
    if validation:
        lo, hi = cv_plus_interval(scores, fold_of, centres, scales, alpha)
        intervals = {key: [max(float(a), 0.0), float(b)] for key, a, b in zip(keys, lo, hi)}
    ordered = np.sort(scores)
    block.update({
        "method": "CV+ (jackknife+ over folds of runs; Barber et al. 2021)",
        "fold_runs": {name: sorted(held) for name, held in parts}, "score": score_text(),
        "kappa": defaults.get("identify.kappa"), "quantile_index": k, "quantile": float(ordered[k - 1]),
        "guarantee": f"if new runs are exchangeable with the fitted ones: coverage >= "
                     f"{cv_plus_guarantee(n, len(parts), alpha):.1%} in the worst case "
                     f"(1 - 2 alpha - O(K/n)), about {1 - alpha:.1%} in practice; none for "
                     f"runs unlike them (other wave heights, frequencies)"
                     + ("" if alpha == asked else f"; {n} scores are too few for "
                        f"{1 - asked:.0%}: the largest is used"),
        "worst_case_coverage": cv_plus_guarantee(n, len(parts), alpha),
        "reported": "interval_95: hull of the CV+ interval and interval_95_parametric",
        "wall_time_s": time.perf_counter() - started})
    return {"calibration": block, "intervals": intervals}


def quantile_index_min(alpha: float) -> int:
    """The fewest scores with a finite conformal quantile at level 1 - alpha (19 at 95 %)."""
    n = 1
    while quantile_index(n, alpha) is None:
        n += 1
    return n


def calibrated_rows(rows: list[dict], intervals: dict) -> list[dict]:
    """`rows` (with the parametric "interval_95") with "interval_95_parametric" kept and
    "interval_95" the hull of it and the CV+ interval (unchanged where not calibrated)."""
    out = []
    for row in rows:
        para = list(row["interval_95"])
        cal = intervals.get((row["run"], row["channel"]))
        both = [min(para[0], cal[0]), max(para[1], cal[1])] if cal else para
        out.append({**row, "interval_95_parametric": para, "interval_95": both})
    return out
