"""The figure of a co-design study: the objective against each varied quantity."""
from __future__ import annotations

import numpy as np


def plot_codesign(result: dict, path=None, unit: str = ""):
    """One panel per varied name: each point's objective against that name's value (valid
    points as dots, with their 95 % error bars where the objective has them; failed or
    invalid ones as red crosses at the panel's foot), the best point ringed and labelled.
    Returns the figure, written to `path` when given."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    points = result["points"]
    names = list(points[0]["params"]) if points else []
    n = max(len(names), 1)
    fig, axes = plt.subplots(1, n, figsize=(5.2 * n, 4.0), squeeze=False)
    label = result["objective_name"].replace("_", " ") + (f", {unit}" if unit else "")
    best = result.get("best")
    for ax, name in zip(axes[0], names):
        ok = [p for p in points if p["valid"] and p["objective"] is not None]
        bad = [p for p in points if not (p["valid"] and p["objective"] is not None)]
        order = sorted(ok, key=lambda p: p["params"][name])
        x = np.array([p["params"][name] for p in order])
        y = np.array([p["objective"] for p in order])
        err = np.array([p["error_95"] or 0.0 for p in order])
        if result.get("search") == "grid" and len(names) == 1:
            ax.plot(x, y, "-", color="0.6", lw=1)
        ax.errorbar(x, y, yerr=err if err.any() else None, fmt="o", ms=4, capsize=3,
                    label="points" + (" (95 % error bars)" if err.any() else ""))
        if bad:
            floor = min(y) if y.size else 0.0
            ax.plot([p["params"][name] for p in bad], [floor] * len(bad), "x", color="C3",
                    label="failed or invalid")
        if best is not None:
            ax.plot(best["params"][name], best["objective"], "o", ms=12, mfc="none",
                    mec="C1", mew=2, label=f"best: {name} = {best['params'][name]:.4g}")
        ax.set_xlabel(name)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{result['provenance']['model']}: {label} ({result['search']})", fontsize=10)
    fig.tight_layout()
    if path is not None:
        save(fig, path)
    return fig
