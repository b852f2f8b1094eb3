"""The seas a sweep counts as producing nothing, each with why: no law within the PTO's limits
serves it (studies.design.NoLawForSea: the device's survival mode), its cases failed to run,
or they ran and failed their physics checks. The annual energy counts them as zero and says
so (study._summary: "zero_seas" and a note)."""
from __future__ import annotations

import numpy as np

ZERO_KINDS = {"no_law": "with no law within the PTO's limits (survival)",
              "failed": "whose cases failed to run", "invalid": "whose cases failed their "
              "physics checks"}


def zero_seas(ds, seas, missing) -> list[dict]:
    """The weighted seas counted as zero: {"hs", "tp", "weight", "kind" (a ZERO_KINDS key),
    "why": the first case's reason}."""
    out = []
    for k in np.flatnonzero(missing):    # missing: weighted seas without a valid case
        sea = ds.isel(sea=int(k))
        reasons = [str(r) for r in np.ravel(sea["invalid_reasons"].values) if str(r)]
        kind = ("no_law" if "no_law" in ds and bool(sea["no_law"].values.any()) else
                "failed" if "failed" in ds and bool(sea["failed"].values.any()) else "invalid")
        out.append({"hs": seas[k].hs, "tp": seas[k].tp, "weight": seas[k].weight,
                    "kind": kind, "why": reasons[0] if reasons else "no valid case"})
    return out


def zero_kinds(zero: list) -> dict:
    """ZERO_KINDS' phrase -> how many of the zero seas are of that kind."""
    counts = {}
    for z in zero:
        counts[ZERO_KINDS[z["kind"]]] = counts.get(ZERO_KINDS[z["kind"]], 0) + 1
    return counts


def zero_note(zero: list, aep: float, coverage: float, unchecked: float) -> str:
    """The note on the seas counted as zero: how many, their share of the year, of which kind
    (each listed under zero_seas with its reason)."""
    kinds = "; ".join(f"{n} {what}" for what, n in zero_kinds(zero).items())
    return (f"annual energy {aep:.4g} MWh counts {len(zero)} weighted seas "
            f"({100 * (1 - coverage):.3g} % of the year) with no valid case as producing "
            f"nothing, a lower bound: {kinds} (each listed under zero_seas with its reason); "
            f"with the numbers of the cases that ran but failed their checks it would be "
            f"{unchecked:.4g} MWh")


def fell_back_summary(ds, rows: list) -> dict:
    """--design: {"fell_back": [{"hs", "tp", "to"}] of the seas whose law fell back to
    another that ran, "fell_back_seas": how many}; {} without --design."""
    if "fell_back" not in ds:
        return {}
    fell = [{"hs": r["hs"], "tp": r["tp"], "to": r["fallback"]} for r in rows if r["fell_back"]]
    return {"fell_back": fell, "fell_back_seas": len(fell)}
