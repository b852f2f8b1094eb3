"""Figures of a sweep: the power matrix as an annotated heat map, capture width ratio (or
capture width) against the period, and each sea state's share of the annual energy."""
from __future__ import annotations

import numpy as np

from .power import power_matrix


def _invalid_cells(ds, table, period: str) -> dict:
    """(row, column) of the power matrix -> how many of its cases failed their checks."""
    if "valid" not in ds:
        return {}
    bad = (~ds["valid"]).sum([d for d in ds["valid"].dims if d != "sea"]).values
    cells = {}
    for k in np.flatnonzero(bad):
        i = int(np.searchsorted(table.hs.values, ds["hs"].values[k]))
        j = int(np.searchsorted(table[period].values, round(float(ds[period].values[k]), 9)))
        cells[(i, j)] = int(bad[k])
    return cells


def plot_sweep(ds, summary: dict, path=None):
    """Three panels (power matrix, capture width, annual energy by sea); returns the figure,
    written to path when given."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    weighted = summary.get("annual_energy_MWh") is not None
    fig, axes = plt.subplots(1, 3 if weighted else 2, figsize=(15 if weighted else 10, 4.2))
    period = "tp"
    try:
        table = power_matrix(ds, period=period) / 1e3
        ax = axes[0]
        image = ax.imshow(table.values, origin="lower", aspect="auto", cmap="viridis")
        ax.set_xticks(range(table[period].size), [f"{v:.3g}" for v in table[period].values],
                      rotation=90 if table[period].size > 12 else 0, fontsize=7)
        ax.set_yticks(range(table.hs.size), [f"{v:.3g}" for v in table.hs.values], fontsize=7)
        if table.size <= 120:
            for (i, j), v in np.ndenumerate(table.values):
                if np.isfinite(v):
                    ax.text(j, i, f"{v:.3g}", ha="center", va="center", fontsize=6, color="w")
        invalid = _invalid_cells(ds, table, period)
        for (i, j), n in invalid.items():        # failed physics checks: shown, never averaged
            ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="xx",
                                       edgecolor="C3", lw=0))
            ax.text(j, i, f"{n} invalid", ha="center", va="center", fontsize=7, color="C3",
                    bbox={"facecolor": "white", "edgecolor": "none", "pad": 1.5})
        fig.colorbar(image, ax=ax, label="mean power, kW")
        ax.set_xlabel("Tp, s")
        ax.set_ylabel("Hs, m")
        n_bad = summary.get("invalid_cases", 0)
        ax.set_title(f"{ds.attrs.get('model')}: power matrix"
                     + (f"\n{n_bad} invalid cases left out (hatched)" if n_bad else ""),
                     fontsize=10)
    except ValueError as exc:                       # other quantities varied: no single table
        axes[0].text(0.5, 0.5, str(exc), ha="center", va="center", wrap=True, fontsize=8)
        axes[0].set_axis_off()
    ax = axes[1]
    ratio = "capture_width_ratio" if "capture_width_ratio" in ds else "capture_width_m"
    values = ds[ratio].mean([d for d in ds[ratio].dims if d != "sea"])
    x = ds["te"].values if np.all(np.isfinite(ds["te"].values)) else ds["tp"].values
    ax.scatter(x, values, c=ds["hs"].values, cmap="viridis", s=18)
    ax.set_xlabel("Te, s" if np.all(np.isfinite(ds["te"].values)) else "Tp, s")
    ax.set_ylabel("capture width ratio" if ratio == "capture_width_ratio" else "capture width, m")
    ax.grid(alpha=0.3)
    ax.set_title("capture width (colour: Hs)" + (", valid cases only"
                                                  if summary.get("invalid_cases") else ""))
    if weighted:
        ax = axes[2]
        power = ds["mean_power_W"].mean([d for d in ds["mean_power_W"].dims if d != "sea"])
        energy = ds["weight"].values * power.values * 8766 / 1e6
        ax.bar(range(energy.size), energy)
        ax.set_xlabel("sea state")
        ax.set_ylabel("energy per year, MWh")
        ax.set_title(f"annual energy {summary['annual_energy_MWh']:.4g} MWh by sea state")
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    if path is not None:
        save(fig, path)
    return fig
