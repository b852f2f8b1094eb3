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


def _edges(centres) -> np.ndarray:
    """Cell edges around sorted centres: midpoints, the ends half a step out."""
    c = np.asarray(centres, float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])


def spread_95(summary: dict) -> np.ndarray:
    """Per sea the half-width of its power's 95 % interval over its mean (-, NaN: none): from
    its seeds (Student), else 1.96 x the spectral standard error of a linear law."""
    out = []
    for row in summary["seas"]:
        mean = row["mean_power_W"]
        if not isinstance(mean, float) or not mean > 0:
            out.append(np.nan)
        elif row.get("mean_power_ci95_W"):
            lo, hi = row["mean_power_ci95_W"]
            out.append((hi - lo) / 2 / mean)
        elif row.get("spectral_stderr_W") is not None:
            out.append(1.959964 * row["spectral_stderr_W"] / mean)
        else:
            out.append(np.nan)
    return np.array(out, float)


def _label(value: float, spread: float) -> str:
    """A cell's power (kW) with its 95 % spread (%) beneath, when there is one."""
    return f"{value:.3g}" + (f"\n±{100 * spread:.0f}%" if np.isfinite(spread) else "")


def _matrix(fig, ax, ds, table, period, spread=None):
    """A grid of sea states: cells on the real Hs and Tp values, annotated (power, kW, and
    its 95 % spread), invalid hatched."""
    import matplotlib.pyplot as plt
    x, y = table[period].values, table.hs.values
    xe, ye = _edges(x), _edges(y)
    image = ax.pcolormesh(xe, ye, np.ma.masked_invalid(table.values), cmap="viridis")
    spreads = np.full(table.shape, np.nan)
    if spread is not None:
        spreads = power_matrix(ds.assign(spread_95=("sea", spread)), "spread_95",
                               period).values
    if table.size <= 120:
        for (i, j), v in np.ndenumerate(table.values):
            if np.isfinite(v):
                ax.text(x[j], y[i], _label(v, spreads[i, j]), ha="center", va="center",
                        fontsize=8, color="w")
    for (i, j), n in _invalid_cells(ds, table, period).items():   # shown, never averaged
        ax.add_patch(plt.Rectangle((xe[j], ye[i]), xe[j + 1] - xe[j], ye[i + 1] - ye[i],
                                   fill=False, hatch="xx", edgecolor="C3", lw=0))
        ax.text(x[j], y[i], f"{n} invalid", ha="center", va="center", fontsize=8, color="C3",
                bbox={"facecolor": "white", "edgecolor": "none", "pad": 1})
    fig.colorbar(image, ax=ax, label="mean power, kW")
    ax.set_xlabel("peak period Tp, s")
    ax.set_ylabel("significant wave height Hs, m")


def _scattered(fig, ax, ds, spread=None):
    """Sea states that do not fill a grid (a site's list): a dot each at its Hs and Tp,
    coloured and labelled by mean power (kW, and its 95 % spread); invalid ones as red
    crosses."""
    power = ds["mean_power_W"].mean([d for d in ds["mean_power_W"].dims if d != "sea"]) / 1e3
    ok = np.isfinite(power.values)
    spread = np.full(ok.size, np.nan) if spread is None else spread
    dots = ax.scatter(ds["tp"].values[ok], ds["hs"].values[ok], c=power.values[ok],
                      cmap="viridis", s=60, edgecolor="k", lw=0.3)
    for tp, hs, v, e in zip(ds["tp"].values[ok], ds["hs"].values[ok], power.values[ok],
                            spread[ok]):
        ax.annotate(_label(v, e), (tp, hs), textcoords="offset points", xytext=(0, 5),
                    ha="center", fontsize=6)
    if (~ok).any():
        ax.scatter(ds["tp"].values[~ok], ds["hs"].values[~ok], marker="x", color="C3", s=30,
                   label="invalid (left out)")
        ax.legend(fontsize=7, loc="upper left")
    fig.colorbar(dots, ax=ax, label="mean power, kW")
    ax.set_xlabel("peak period Tp, s")
    ax.set_ylabel("significant wave height Hs, m")
    ax.grid(alpha=0.3)


def _controller(summary: dict, designed: bool) -> str:
    """The law the sweep ran, for a title: "passive (damping 4e+05)", "mpc designed per sea"."""
    made_by = summary.get("provenance") or {}
    name = made_by.get("controller") or "the scene's PTO laws"
    settings = {k: v for k, v in (made_by.get("settings") or {}).items()
                if isinstance(v, (int, float)) and not isinstance(v, bool)}
    if designed:
        return f"{name} designed per sea"
    shown = ", ".join(f"{k} {v:.3g}" for k, v in list(settings.items())[:2])
    return f"{name} ({shown})" if shown else name


def plot_sweep(ds, summary: dict, path=None):
    """Panels on the same axes, peak period Tp (s) across and Hs (m) up: the power
    matrix (mean power, kW, cells on the real Hs and Tp values, a colourbar), capture width
    (or its ratio) against Tp, a line per Hs, for a weighted list each sea state's
    annual energy (MWh) as a bubble at its Hs and Tp, for a --design sweep each sea's
    mean power as a share of its bound inside the envelope (%), and with MoorDyn moorings each
    sea's largest fairlead tension (kN). Returns the figure, written to path when
    given."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    weighted = summary.get("annual_energy_MWh") is not None
    designed = "bound_W" in ds
    budgeted = summary.get("annual_energy_budget") is not None
    moored = "mooring_max_N" in ds
    n = 2 + weighted + designed + budgeted + moored
    # two panels a row: a page (A4) wide, whatever the number of panels (in one row, a site's
    # five were 27 inches wide)
    cols = min(n, 2)
    fig, grid = plt.subplots(-(-n // cols), cols, figsize=(5.6 * cols, 4.4 * -(-n // cols)),
                             squeeze=False)
    axes = list(grid.ravel())
    for spare in axes[n:]:
        spare.set_axis_off()
    axes = axes[:n]
    period = "tp"
    try:
        table = power_matrix(ds, period=period) / 1e3
        spread = spread_95(summary) if ds["mean_power_W"].ndim == 2 else None
        measured = "record" in ds.coords        # records: never a grid, whatever their number
        if np.isfinite(table.values).mean() >= 0.5 and not measured:
            _matrix(fig, axes[0], ds, table, period, spread)
        else:                       # a site's scattered list, records: each sea where it lies
            _scattered(fig, axes[0], ds, spread)
        n_bad = summary.get("invalid_cases", 0)
        law = _controller(summary, designed)
        axes[0].set_title(f"{ds.attrs.get('model')}, {law}: mean power by sea state, kW"
                          + (" (± 95 % spread)" if spread is not None
                             and np.isfinite(spread).any() else "")
                          + (f"\n{n_bad} invalid cases left out (red crosses / hatched)"
                             if n_bad else "")
                          + ("\nmeasured records, each at its Hs (4 std) and Tp (periodogram "
                             "peak)" if measured else ""), fontsize=9)
    except ValueError as exc:                       # other quantities varied: no single table
        axes[0].text(0.5, 0.5, str(exc), ha="center", va="center", wrap=True, fontsize=8)
        axes[0].set_axis_off()
    _capture_width(fig, axes[1], ds, summary)
    if weighted:
        ax = axes[2]
        power = ds["mean_power_W"].mean([d for d in ds["mean_power_W"].dims if d != "sea"])
        energy = np.nan_to_num(ds["weight"].values * power.values * 8766 / 1e6)
        size = 400 * energy / max(energy.max(), 1e-300) + 4
        bubbles = ax.scatter(ds["tp"].values, ds["hs"].values, s=size, c=energy,
                             cmap="magma_r", edgecolor="k", lw=0.4)
        fig.colorbar(bubbles, ax=ax, label="energy per year, MWh")
        ax.set_xlabel("peak period Tp, s")
        ax.set_ylabel("significant wave height Hs, m")
        ax.grid(alpha=0.3)
        ax.set_title(f"annual energy {summary['annual_energy_MWh']:.4g} MWh: each sea state's "
                     f"share (area)", fontsize=9)
    if designed:
        _share_of_bound(fig, axes[2 + weighted], ds)
    if moored:
        _mooring_loads(fig, axes[2 + weighted + designed], ds)
    if budgeted:
        _budget(axes[-1], summary)
    fig.tight_layout()
    if path is not None:
        save(fig, path)
    return fig


def _capture_width(fig, ax, ds, summary):
    """Capture width (or its ratio) against Tp: a line per Hs for a grid, a dot per sea
    coloured by Hs for a site's list."""
    import matplotlib.pyplot as plt
    ratio = "capture_width_ratio" if "capture_width_ratio" in ds else "capture_width_m"
    values = ds[ratio].mean([d for d in ds[ratio].dims if d != "sea"])
    # a marker per Hs, largest first: a linear law's capture width does not depend on Hs,
    # and equal points would hide each other
    heights = np.unique(ds["hs"].values)
    if len(heights) <= 8 and len(heights) < ds["hs"].size:       # a grid: a line per Hs
        colours = plt.cm.viridis(np.linspace(0, 0.9, len(heights)))
        for k, (hs, colour) in enumerate(zip(heights, colours)):
            at = ds["hs"].values == hs
            order = np.argsort(ds["tp"].values[at])
            ax.plot(ds["tp"].values[at][order], values.values[at][order], "o-", color=colour,
                    lw=0.8, ms=max(10 - 8 * k / max(len(heights) - 1, 1), 2),
                    label=f"Hs {hs:.3g} m")
        ax.legend(fontsize=8, title=None if len(heights) < 2 else "(equal for a linear law)",
                  title_fontsize=7)
    else:                                  # a site's list: one point per sea, coloured by Hs
        dots = ax.scatter(ds["tp"].values, values, c=ds["hs"].values, cmap="viridis", s=18)
        fig.colorbar(dots, ax=ax, label="Hs, m")
    ax.set_xlabel("peak period Tp, s")
    ax.set_ylabel("capture width ratio, -" if ratio == "capture_width_ratio"
                  else "capture width, m")
    ax.grid(alpha=0.3)
    ax.set_title("capture width" + (", valid cases only" if summary.get("invalid_cases")
                                    else ""), fontsize=9)


def _sea_dots(fig, ax, ds, values, ringed, *, cmap, label, ring_label, title, **colour):
    """Each sea's value as a dot at its Hs and Tp, annotated, with a colourbar; the seas in
    `ringed` (a mask) ringed in red, said in a legend below the axes (inside, it would hide a
    sea: a site's largest seas sit in a corner)."""
    ok = np.isfinite(values)
    dots = ax.scatter(ds["tp"].values[ok], ds["hs"].values[ok], c=values[ok], cmap=cmap, s=60,
                      edgecolor="k", lw=0.3, **colour)
    for tp, hs, v in zip(ds["tp"].values[ok], ds["hs"].values[ok], values[ok]):
        ax.annotate(f"{v:.0f}", (tp, hs), textcoords="offset points", xytext=(0, 5),
                    ha="center", fontsize=6)
    if ringed.any():
        ax.scatter(ds["tp"].values[ringed], ds["hs"].values[ringed], s=150, facecolor="none",
                   edgecolor="C3", lw=1.2, label=ring_label)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False)
    fig.colorbar(dots, ax=ax, label=label)
    ax.margins(y=0.1)                      # the top sea's label inside the axes
    ax.set_xlabel("peak period Tp, s")
    ax.set_ylabel("significant wave height Hs, m")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)


def _share_of_bound(fig, ax, ds):
    """--design: each sea's mean power over its bound inside the envelope (%), a dot at its
    Hs and Tp; seas where no setting stayed inside ringed in red."""
    over = [d for d in ds["mean_power_W"].dims if d != "sea"]
    share = 100 * (ds["mean_power_W"].mean(over) / ds["bound_W"].mean(over)).values
    _sea_dots(fig, ax, ds, share, ~ds["inside_envelope"].all(over).values, cmap="cividis",
              vmin=0, vmax=100, label="mean power / bound inside the envelope, %",
              ring_label="no setting inside the envelope",
              title="designed per sea: share of the bound")


def _mooring_loads(fig, ax, ds):
    """MoorDyn moorings: each sea's largest fairlead tension (kN, the largest over seeds) as
    a dot at its Hs and Tp; seas whose record exceeds its Gaussian 3-hour estimate (snap
    loads) ringed in red."""
    over = [d for d in ds["mooring_max_N"].dims if d != "sea"]
    peak = ds["mooring_max_N"].max(over).values / 1e3
    snap = np.isfinite(peak) & (peak > ds["mooring_mpm_3h_N"].max(over).values / 1e3) \
        if "mooring_mpm_3h_N" in ds else np.zeros(peak.shape, bool)
    _sea_dots(fig, ax, ds, peak, snap, cmap="inferno_r", label="largest fairlead tension, kN",
              ring_label="max above its Gaussian 3-h estimate",
              title="mooring loads: the most loaded fairlead per sea")


def _budget(ax, summary):
    """The annual energy's budget: each component's standard uncertainty (MWh, 1 sigma) as a
    bar, absent ones named with a dash; the annual energy and its 95 % interval in the title."""
    rows = summary["annual_energy_budget"]["components"]
    names = [r["component"].replace("_", " ") for r in rows]
    values = [r["std_MWh"] or 0.0 for r in rows]
    y = np.arange(len(rows))[::-1]
    ax.barh(y, values, color=["C0" if r["type"] == "A" else "C1" for r in rows])
    for yi, r in zip(y, rows):
        text = "absent" if r["std_MWh"] is None else \
            f"{r['std_MWh']:.3g} ({100 * r['share_of_variance']:.0f} %)"
        ax.text(0, yi, " " + text, va="center", fontsize=7)
    ax.set_yticks(y, [f"{n} ({r['type']})" for n, r in zip(names, rows)], fontsize=8)
    ax.set_xlabel("standard uncertainty of the annual energy, MWh (1 sigma)")
    lo, hi = summary["annual_energy_ci95_MWh"]
    ax.set_title(f"annual energy {summary['annual_energy_MWh']:.4g} MWh, 95 % interval "
                 f"[{lo:.4g}, {hi:.4g}]\n(A statistical, B systematic; share of the "
                 f"variance)", fontsize=9)
    ax.grid(alpha=0.3, axis="x")
