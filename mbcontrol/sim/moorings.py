"""What a run did to its catenary mooring lines: tension range, the line's state at its most
and least stretched, and warnings where it went slack, taut or left its force table."""
from __future__ import annotations

import warnings

import numpy as np


def mooring_report(plant, ds) -> dict:
    """Per catenary line: tension range, the line's state at its most and least stretched
    (exact solve), and warnings when it went slack or taut-out or its fairlead left the force
    table's envelope (where the compiled force is extrapolated)."""
    from ..plant import catenary_line

    report = {}
    for m in (m for m in plant.scene.moorings if m.kind == "catenary"):
        line = catenary_line(m)
        span, height = ds[f"{m.name}__span"].values, ds[f"{m.name}__height"].values
        rest_span, rest_height, _ = line.offsets(line.fairlead)
        t = ds["time"].values
        entry = {"tension_min_N": float(ds[f"{m.name}__tension"].min()),
                 "tension_max_N": float(ds[f"{m.name}__tension"].max())}
        for key, i in (("most_stretched", int(np.argmax(np.hypot(span, height)))),
                       ("least_stretched", int(np.argmin(np.hypot(span, height))))):
            state = _solve_at(line, span[i], height[i])
            entry[key] = {"time_s": float(t[i]), "status": state.status}
            if state.status in ("slack", "taut-out"):
                warnings.warn(f"{plant.name}: mooring '{m.name}' was {state.status} at t = {t[i]:.4g} s "
                              f"(fairlead {span[i]:.4g} m across, {height[i]:.4g} m above the anchor)",
                              RuntimeWarning, stacklevel=3)
        outside = (np.abs(span - rest_span) > line.excursion) | (np.abs(height - rest_height) > line.excursion)
        entry["left_envelope"] = bool(outside.any())
        if outside.any():
            i = int(np.argmax(outside))
            warnings.warn(f"{plant.name}: mooring '{m.name}': the fairlead left the force table's envelope "
                          f"(±{line.excursion:.4g} m about rest) at t = {t[i]:.4g} s, where the line force is "
                          f"extrapolated; give the mooring a larger 'excursion'", RuntimeWarning, stacklevel=3)
        report[m.name] = entry
    return report


def _solve_at(line, span: float, height: float):
    from ..plant import solve_catenary
    return solve_catenary(float(span), float(height), line.length, line.EA, line.weight,
                          friction=line.friction, strain_limit=line.strain_limit, name=line.name)
