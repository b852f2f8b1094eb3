"""The figure of a co-design study: the objective against each varied quantity."""
from __future__ import annotations

import numpy as np

from .compare import params_key

_AXIS = {"MWh": "annual energy, MWh", "W": "mean power, W"}


def plot_codesign(result: dict, path=None, unit: str = ""):
    """One panel per varied name: each point's objective against that name's value (valid
    points as dots, with their 95 % error bars where the objective has them; failed or
    invalid ones as red crosses at the panel's foot), the best point ringed and labelled.
    With several names, a grid's points are joined into one line per value of the others.
    A study run --against a second objective adds that objective's points (dashed, squares)
    and its optimum (a star); both share the unit (both are of one wave or of one site).
    Returns the figure, written to `path` when given."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    points = result["points"]
    names = list(points[0]["params"]) if points else []
    n = max(len(names), 1)
    fig, axes = plt.subplots(1, n, figsize=(5.6 * n, 5.4), squeeze=False)
    label = result["objective_name"].replace("_", " ") + (f", {unit}" if unit else "")
    best, other = result.get("best"), result.get("against")
    joined = result.get("search") == "grid"
    for ax, name in zip(axes[0], names):
        rest = [m for m in names if m != name]
        for i, (group, members) in enumerate(_groups(points, rest)):
            colour = f"C{i % 10}" if rest else "C0"
            tag = ", ".join(f"{m} = {v:.4g}" for m, v in group)
            drawn = _series(ax, members, name, colour, joined, tag or "points")
            if other is not None:
                keys = {params_key(p["params"]) for p in members}
                _series(ax, [p for p in other["points"] if params_key(p["params"]) in keys], name,
                        colour, joined, None if drawn else tag or None, dashed=True)
        bad = [p for p in points if not (p["valid"] and p["objective"] is not None)]
        if bad:                   # at the panel's foot: x in data, y in axes units
            ax.plot([p["params"][name] for p in bad], [0.03] * len(bad), "x", color="C3",
                    ms=8, transform=ax.get_xaxis_transform(),
                    label=f"{result['objective_name'].replace('_', ' ')} failed or invalid")
        if best is not None:
            ax.plot(best["params"][name], best["objective"], "o", ms=13, mfc="none",
                    mec="k", mew=2, label=f"best: {name} = {best['params'][name]:.4g}")
        # the comparison's optimum of the other objective (a tie resolved to ours), or its own
        b = ((result.get("comparison") or {}).get("other_best") or other.get("best")
             if other is not None else None)
        if b is not None:
            ax.plot(b["params"][name], b["objective"], "*", ms=15, color="gold", mec="k",
                    label=f"best of {other['objective_name'].replace('_', ' ')} (dashed): "
                          f"{name} = {b['params'][name]:.4g}")
        ax.set_xlabel(name)
        ax.set_ylabel(_AXIS.get(unit, unit) if other is not None else label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2)
    title = f"{result['provenance']['model']}: {label} ({result['search']})"
    if other is not None:
        title = (f"{result['provenance']['model']}: {result['objective_name']} (solid) against "
                 f"{other['objective_name']} (dashed)" + (f", {unit}" if unit else ""))
        verdict = (result.get("comparison") or {}).get("verdict")
        title += f"\noptimum: {verdict}" if verdict else ""
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is not None:
        save(fig, path)
    return fig


def _groups(points: list, rest: list) -> list:
    """[(((name, value), ...), points)]: the points grouped by the values of `rest`."""
    groups: dict = {}
    for p in points:
        groups.setdefault(tuple((m, p["params"][m]) for m in rest), []).append(p)
    return sorted(groups.items())


def _series(ax, members, name, colour, joined, tag, dashed=False) -> None:
    """Valid members against `name`, joined in order on a grid, error bars where given;
    whether anything was drawn."""
    ok = sorted((p for p in members if p["valid"] and p["objective"] is not None),
                key=lambda p: p["params"][name])
    if not ok:
        return False
    x = np.array([p["params"][name] for p in ok])
    y = np.array([p["objective"] for p in ok])
    err = np.array([p.get("error_95") or 0.0 for p in ok])
    if joined:
        ax.plot(x, y, "--" if dashed else "-", color=colour, lw=1, alpha=0.8)
    ax.errorbar(x, y, yerr=err if err.any() else None, fmt="s" if dashed else "o", ms=4,
                capsize=3, color=colour, mfc="none" if dashed else colour,
                label=None if tag is None else tag + (" (95 % error bars)" if err.any() else ""))
    return True
