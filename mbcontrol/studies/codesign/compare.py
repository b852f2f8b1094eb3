"""Does the optimum move? One study's points set beside the same points under another
objective (`codesign --against`): typically the site's annual energy with a causal controller
against the non-causal bound's, the question WecOptTool's bound-based co-design leaves open.

The verdict is read with error bars: the causal objective's best point against its value at
the other objective's optimum, the difference's 95 % half-width taken as sqrt(e1^2 + e2^2).
The two points share seas, seeds and the radiation-fit error's sign, so their errors are
positively correlated and the true half-width of the difference is smaller: "moved" is
conservative, "within the error bars" may hide a real shift.
"""
from __future__ import annotations

import math

TIE = 1e-6      # relative: the other objective as good at my best as at its own (a flat one)


def params_key(params: dict) -> tuple:
    """A point's values as a hashable key (rounded so that a JSON round trip matches)."""
    return tuple(sorted((k, round(float(v), 12)) for k, v in params.items()))


def compare_optima(result: dict, other: dict) -> dict:
    """{"best", "other_best", "at_other_best", "difference", "difference_95", "share_of_other",
    "verdict"}: `result` and `other` from `codesign` on the same points. share_of_other: per
    point, result's objective over other's (the share of the bound a causal law reaches).
    verdict: "same optimum", "moved" (by more than the difference's 95 % half-width), "moved
    within the error bars", or "moved: the other optimum is not valid here" (result's
    objective fails its checks there: at_other_best then carries the reasons)."""
    mine = {params_key(p["params"]): p for p in result["points"]}
    theirs = {params_key(p["params"]): p for p in other["points"]}
    shares = []
    for key, p in mine.items():
        q = theirs.get(key)
        ok = q is not None and p["valid"] and q["valid"] and p["objective"] is not None \
            and q["objective"] not in (None, 0.0)
        shares.append({"params": p["params"],
                       "share": p["objective"] / q["objective"] if ok else None})
    best, other_best = result.get("best"), other.get("best")
    out = {"objective": result["objective_name"], "other_objective": other["objective_name"],
           "best": best, "other_best": other_best, "at_other_best": None, "difference": None,
           "difference_95": None, "share_of_other": shares, "verdict": None}
    if best is None or other_best is None:
        out["verdict"] = "no valid optimum on one side"
        return out
    tie = theirs.get(params_key(best["params"]))        # the other objective at my best
    if tie is not None and tie["valid"] and tie["objective"] is not None and \
            tie["objective"] >= other_best["objective"] - TIE * abs(other_best["objective"]):
        out.update(other_best={k: tie[k] for k in ("params", "objective", "error_95")},
                   difference=0.0, difference_95=0.0, verdict="same optimum")
        out["at_other_best"] = out["best"]
        return out
    at = mine.get(params_key(other_best["params"]))
    if at is None:
        out["verdict"] = f"{other['objective_name']}'s optimum is not a point of this study"
        return out
    if not at["valid"] or at["objective"] is None:
        out["at_other_best"] = {"params": at["params"], "objective": at["objective"],
                                "error_95": at["error_95"], "reasons": at["reasons"]}
        out["verdict"] = "moved: the other optimum is not valid here"
        return out
    out["at_other_best"] = {"params": at["params"], "objective": at["objective"],
                            "error_95": at["error_95"]}
    if params_key(best["params"]) == params_key(other_best["params"]):
        out.update(difference=0.0, difference_95=0.0, verdict="same optimum")
        return out
    diff = best["objective"] - at["objective"]
    half = math.hypot(best["error_95"] or 0.0, at["error_95"] or 0.0)
    out.update(difference=diff, difference_95=half,
               verdict="moved" if diff > half else "moved within the error bars")
    return out


def describe(comparison: dict, unit: str) -> str:
    """A line for the terminal: where each optimum is and what the verdict means."""
    c = comparison
    if c["best"] is None or c["other_best"] is None or c["at_other_best"] is None:
        return f"optimum comparison: {c['verdict']}"

    def at(p):
        return ", ".join(f"{k} {v:.4g}" for k, v in p["params"].items())
    if c["difference"] is None:
        return (f"optimum of {c['objective']}: {at(c['best'])} ({c['best']['objective']:.4g} "
                f"{unit}); of {c['other_objective']}: {at(c['other_best'])}, where "
                f"{c['objective']} is not valid ({'; '.join(c['at_other_best']['reasons'])}): "
                f"{c['verdict']}")
    line = (f"optimum of {c['objective']}: {at(c['best'])} ({c['best']['objective']:.4g} {unit}); "
            f"of {c['other_objective']}: {at(c['other_best'])}, where {c['objective']} is "
            f"{c['at_other_best']['objective']:.4g} {unit}")
    if c["verdict"] == "same optimum":
        return line + ": the same optimum"
    return (line + f": {c['verdict']} (difference {c['difference']:.3g} +- "
            f"{c['difference_95']:.2g} {unit}, 95 %)")
