"""Model structure chosen by evidence: leave-one-group-out cross-validation of candidates.

A candidate structure is a list of parameters to fit (`--fit` specs, NAME or NAME=LO:HI; an
empty list is the scene's [identify] table). For each candidate and each group of runs (the
flume's series: each blocks a different DOF, so a fold predicts a configuration it never saw),
the parameters are fitted by Gauss-Newton on the other groups and the held-out group is
predicted; the candidate's score is the RMS relative amplitude error over every held-out run
and channel (`report.channel_errors`, pooled). The lowest score wins; fewer parameters break
ties within 1 % of it. What the fits warn about (extrapolation, bounds, correlations) is kept
per fold in the result, not printed.
"""
from __future__ import annotations

import warnings

import numpy as np

from ... import defaults
from ...console import progress_bar
from ...errors import InputError

# TIE, the default "identify.structure_tie": scores within 1 % (relative) of the best: the smaller structure wins


def cross_validate(model: str, runs, candidates: dict, *, progress: bool = False,
                   **options) -> dict:
    """{"groups", "candidates": {name: {"fit", "n_parameters", "folds": {group: {channel:
    rms relative error}}, "channels": {channel: pooled rms}, "score", "warnings"}}, "best"}.
    candidates: name -> list of fit specs; options: the Identification's (dt, settle, ...)."""
    from .fit import fit
    from .report import amplitude_rows, channel_errors
    from .setup import flume_identification, prediction
    groups = sorted({r.group for r in runs})
    if len(groups) < 2:
        raise InputError(f"cross-validation needs runs of at least two groups (series); got "
                         f"{groups}")
    if not candidates:
        raise InputError("cross-validation: no candidate structures given")
    bar = _bar(progress, len(candidates) * len(groups))
    out = {}
    for name, specs in candidates.items():
        held_rows, folds, said, n_parameters = [], {}, [], 0
        for group in groups:
            train = [r for r in runs if r.group != group]
            test = [r for r in runs if r.group == group]
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                problem = flume_identification(model, None, runs=train, fit=list(specs),
                                               **options)
                result = fit(problem, "gauss-newton")
                rows = amplitude_rows(prediction(problem, test), result.values)
            n_parameters = len(problem.fit)
            said += [f"{group} held out: {w.message}" for w in caught]
            folds[group] = {c: e["rms_relative_error"] for c, e in channel_errors(rows).items()}
            held_rows += rows
            if bar is not None:
                bar.update(1)
        rel = np.array([r["relative_error"] for r in held_rows])
        out[name] = {"fit": list(specs), "n_parameters": n_parameters, "folds": folds,
                     "channels": {c: e["rms_relative_error"]
                                  for c, e in channel_errors(held_rows).items()},
                     "score": float(np.sqrt(np.mean(rel ** 2))), "warnings": said}
    if bar is not None:
        bar.close()
    low = min(c["score"] for c in out.values())
    near = [n for n, c in out.items() if c["score"] <= low * (1 + defaults.get("identify.structure_tie"))]
    best = min(near, key=lambda n: (out[n]["n_parameters"], out[n]["score"]))
    return {"groups": groups, "candidates": out, "best": best}


def table(cv: dict) -> str:
    """Plain text: one row per candidate, the held-out RMS relative error per channel and
    the pooled score, the best marked."""
    channels = sorted({c for v in cv["candidates"].values() for c in v["channels"]})
    width = max(len("candidate"), *(len(n) for n in cv["candidates"]))
    head = f"{'candidate':{width}s} {'params':>6s} " + " ".join(f"{c:>8s}" for c in channels)
    lines = [head + f" {'score':>8s}"]
    for name, v in cv["candidates"].items():
        cells = " ".join(f"{100 * v['channels'].get(c, float('nan')):7.1f}%" for c in channels)
        mark = "  <- best" if name == cv["best"] else ""
        lines.append(f"{name:{width}s} {v['n_parameters']:6d} {cells} {100 * v['score']:7.1f}%{mark}")
    lines.append(f"(each of {', '.join(cv['groups'])} predicted by a fit on the others; RMS "
                 f"relative amplitude error over the held-out runs)")
    return "\n".join(lines)


def _bar(progress: bool, total: int):
    if not progress:
        return None
    return progress_bar(total=total, desc="cross-validation", unit="fold", leave=False)
