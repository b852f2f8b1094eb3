"""What an identification shows: per run and channel the measured and modelled first-harmonic
amplitudes, their errors per channel, the parameter table, the JSON contract of `mbcontrol
identify --json` and the figures (response amplitude over frequency per DOF, before and after;
time series of one run).

Errors per channel, over the runs where the channel's DOF is free: `rms_error`, the RMS of
model minus measured amplitude (the channel's unit); `rms_relative_error`, the RMS of
(model - measured) / measured (dimensionless).
"""
from __future__ import annotations

import math

import numpy as np

from ...results import jsonable
from ...textsafe import plain_text
from .costs import harmonic, whole_periods


def channel_unit(channel: str) -> str:
    """SI unit of a measured channel (records are converted on reading): rad or m."""
    return "rad" if channel.lower().startswith(("roll", "pitch", "yaw")) else "m"


def amplitude_rows(problem, values: dict) -> list[dict]:
    """Per run and free channel: {run, group, omega (rad/s), incident (m), channel, unit,
    measured, model (first-harmonic amplitudes, channel unit), relative_error, extrapolated
    (why the run lies where the model was not fitted, `extrapolation.reasons`; [] if not)}."""
    from .extrapolation import reasons
    sims = problem.simulate(values)
    rows = []
    for run, sim in zip(problem.runs, sims):
        start, end, _ = whole_periods(run.time, run.omega, *run.window)
        for channel, (t, y, _) in sim.items():
            measured = abs(harmonic(run.time, run.channels[channel], run.omega, start, end))
            model = abs(harmonic(t, y, run.omega, start, end))
            rows.append({"run": run.name, "group": run.group, "omega": run.omega,
                         "incident": run.amplitude, "channel": channel,
                         "unit": channel_unit(channel), "measured": measured, "model": model,
                         "relative_error": (model - measured) / measured,
                         "extrapolated": reasons(problem, run.omega)})
    return rows


def channel_errors(rows: list[dict]) -> dict:
    """{channel: {rms_error, rms_relative_error, runs}} over the rows."""
    out = {}
    for channel in sorted({r["channel"] for r in rows}):
        mine = [r for r in rows if r["channel"] == channel]
        diff = np.array([r["model"] - r["measured"] for r in mine])
        rel = np.array([r["relative_error"] for r in mine])
        out[channel] = {"rms_error": float(np.sqrt(np.mean(diff ** 2))),
                        "rms_relative_error": float(np.sqrt(np.mean(rel ** 2))),
                        "runs": len(mine)}
    return out


def repeatability(rows: list[dict]) -> dict:
    """The data's own floor: runs of one group at the same frequency (repetitions), each
    channel's amplitude per unit incident wave against their mean. {channel: {"sets": number
    of repeated (group, omega) sets, "runs", "rms_relative_spread": RMS over those runs of
    (a / mean - 1), "max_relative_spread"}}; a model that predicted each set's mean exactly
    would show this RMS relative error, so no model is expected to beat it."""
    sets = {}
    for r in rows:
        sets.setdefault((r["channel"], r["group"], round(r["omega"], 6)), []).append(
            r["measured"] / r["incident"])
    out = {}
    for (channel, _, _), values in sorted(sets.items()):
        if len(values) < 2:
            continue
        v = np.asarray(values)
        entry = out.setdefault(channel, {"sets": 0, "runs": 0, "spread": []})
        entry["sets"] += 1
        entry["runs"] += v.size
        entry["spread"] += list(v / v.mean() - 1)
    for entry in out.values():
        spread = np.asarray(entry.pop("spread"))
        entry["rms_relative_spread"] = float(np.sqrt(np.mean(spread ** 2)))
        entry["max_relative_spread"] = float(np.max(np.abs(spread)))
    return out


def errors_block(rows: list[dict], residuals=None) -> dict:
    """{runs, rms_error, channels, repeatability}: the "fit" / "validation" block of the JSON
    contract; rms_error is the RMS of the relative amplitude errors over every run and channel;
    repeatability the spread between repeated runs (`repeatability`), the data's floor."""
    rel = np.array([r["relative_error"] for r in rows])
    return {"runs": sorted({r["run"] for r in rows}),
            "rms_error": float(np.sqrt(np.mean(rel ** 2))) if rel.size else None,
            "channels": channel_errors(rows), "repeatability": repeatability(rows)}


def forward_validity(problem, values: dict, rows: list[dict]) -> dict:
    """The physics checks on an identified model's forward runs (`amplitude_rows` at
    `values`): every model amplitude finite; a rotation within the angle where linear
    hydrodynamics hold and a heave within the body's mean draft
    (`mbcontrol.analysis.validity`); and no fitted hydro correction that makes the model
    create energy (a negative radiation or damping scale). {"valid", "invalid_reasons"}."""
    from ... import defaults
    from ...analysis import mean_draft
    angle_max = defaults.get("validity.angle_max")
    draft_factor = defaults.get("validity.draft_factor")
    reasons = []
    for name, value in values.items():
        dissipative = name.endswith(("__radiation_scale", "__damping")) or "viscous" in name
        if dissipative and value < 0:
            reasons.append(f"{name} = {value:.4g} < 0: the model would create energy")
    drafts = {}
    for plant in problem._plants.values():
        data = plant.hydro.data if plant.hydro is not None else None
        if data is not None and "body" in data.coords:
            drafts.update({str(b): mean_draft(data, str(b)) for b in data["body"].values})
    draft = min((d for d in drafts.values() if d), default=None)
    for row in rows:
        model, where = row["model"], f"run {row['run']}, channel {row['channel']}"
        if not np.isfinite(model):
            reasons.append(f"{where}: the model's amplitude is not finite")
        elif row["unit"] == "rad" and model > angle_max:
            reasons.append(f"{where}: model amplitude {np.degrees(model):.3g} deg beyond "
                           f"{np.degrees(angle_max):.0f} deg (linear hydrodynamics)")
        elif (row["unit"] == "m" and "heave" in row["channel"].lower() and draft
              and model > draft_factor * draft):
            reasons.append(f"{where}: model amplitude {model:.3g} m beyond the mean draft "
                           f"{draft:.3g} m (linear hydrodynamics)")
    return {"valid": not reasons, "invalid_reasons": reasons}


def summary(model: str, problem, result, fit_rows, validation_rows=None) -> dict:
    """The JSON contract of `mbcontrol identify --json`; "valid" and "invalid_reasons" check
    the fitted model's forward runs (`forward_validity`) on the fit and validation runs."""
    verdict = forward_validity(problem, result.values, fit_rows + (validation_rows or []))
    params = {}
    for p in problem.fit:
        std = result.std.get(p.name)
        params[p.name] = {"initial": p.initial, "value": result.values[p.name],
                          "std": None if std is None or math.isnan(std) else std,
                          "at_bound": result.at_bound.get(p.name), "lo": p.lo, "hi": p.hi}
    return jsonable({
        "model": model, "valid": verdict["valid"], "invalid_reasons": verdict["invalid_reasons"],
        "method": result.method, "cost": problem.cost,
        "uncertainty_method": result.uncertainty_method,
        "parameters": params, "correlation": np.asarray(result.correlation).tolist(),
        "fit": errors_block(fit_rows),
        "validation": errors_block(validation_rows) if validation_rows else None,
        "simulations": result.simulations, "wall_time_s": result.wall_time_s,
        "cost_initial": result.cost_initial, "cost_final": result.cost,
        "warnings": list(result.warnings),
    })


def parameter_table(problem, result) -> str:
    """Plain-text table: parameter, initial, identified +- sigma, bounds. Names pass
    `plain_text` (a newline or an escape sequence in one would forge a row or reach a
    terminal raw)."""
    lines = [f"{'parameter':36s} {'initial':>11s} {'identified':>11s} {'+- sigma':>10s}  bounds"]
    for p in problem.fit:
        v, s = result.values[p.name], result.std.get(p.name, math.nan)
        side = result.at_bound.get(p.name)
        sigma = f"{'at ' + side:>10s}" if side else f"{s:10.3g}"
        lines.append(f"{plain_text(p.name):36s} {p.initial:11.4g} {v:11.4g} {sigma}  "
                     f"[{p.lo:.3g}, {p.hi:.3g}]{' log' if p.log else ''}")
    lines.append(f"sigma: {plain_text(result.uncertainty_method)}")
    lines.append(f"cost (1/2 |r|^2, {problem.cost}): {result.cost_initial:.4g} -> {result.cost:.4g}"
                 f"; {result.simulations} simulations, {result.wall_time_s:.1f} s")
    return "\n".join(lines)


def error_table(rows: list[dict], label: str) -> str:
    """Per channel: RMS error (unit) and RMS relative error over the runs, and beside it the
    repeated runs' own spread (`repeatability`; "-" where no run was repeated). Channel names
    and the label pass `plain_text`."""
    floor, label = repeatability(rows), plain_text(label)
    lines = [f"{label}: {'channel':8s} {'runs':>4s} {'rms error':>12s} {'rms relative':>13s}"
             f" {'repeat spread':>14s}"]
    for channel, e in channel_errors(rows).items():
        unit = next(r["unit"] for r in rows if r["channel"] == channel)
        f = floor.get(channel)
        spread = f"{100 * f['rms_relative_spread']:5.1f}% ({f['sets']})" if f else "-"
        lines.append(f"{'':{len(label) + 2}s}{plain_text(channel):8s} {e['runs']:4d} "
                     f"{e['rms_error']:10.3g} {unit:3s} {100 * e['rms_relative_error']:10.1f}%"
                     f" {spread:>14s}")
    return "\n".join(lines)


def plot_amplitudes(rows_by_label: dict, path=None, title: str | None = None):
    """Response amplitude per unit incident amplitude against frequency, one panel per channel,
    measured (dots) and each labelled model (lines), runs grouped by `group` (markers); runs
    where the model extrapolates (rows' "extrapolated") crossed in red.
    Returns the figure (written to path when given)."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    first = next(iter(rows_by_label.values()))
    channels = sorted({r["channel"] for r in first})
    fig, axes = plt.subplots(1, len(channels), figsize=(4.2 * len(channels), 3.6), squeeze=False)
    markers = dict(zip(sorted({r["group"] for r in first}), "osD^v<>"))
    for ax, channel in zip(axes[0], channels):
        mine = [r for r in first if r["channel"] == channel]
        unit = mine[0]["unit"]
        for group, marker in markers.items():
            pts = sorted((r["omega"], r["measured"] / r["incident"]) for r in mine
                         if r["group"] == group)
            if pts:
                ax.plot(*zip(*pts), marker, color="k", mfc="none", label=f"measured, {group}")
        far = [(r["omega"], r["measured"] / r["incident"]) for r in mine if r.get("extrapolated")]
        if far:
            ax.plot(*zip(*far), "x", color="tab:red", ms=9,
                    label="model extrapolated there (see warnings)")
        for k, (label, rows) in enumerate(rows_by_label.items()):
            for group, marker in markers.items():
                pts = sorted((r["omega"], r["model"] / r["incident"]) for r in rows
                             if r["channel"] == channel and r["group"] == group)
                if pts:
                    ax.plot(*zip(*pts), "-" + marker, color=f"C{k}", ms=3, lw=1,
                            label=f"{label}, {group}")
            bars = [r for r in rows if r["channel"] == channel and "interval_95" in r]
            if bars:
                centre = np.array([r["model"] / r["incident"] for r in bars])
                lo, hi = (np.array([r["interval_95"][i] / r["incident"] for r in bars])
                          for i in (0, 1))
                ax.errorbar([r["omega"] for r in bars], centre, yerr=[centre - lo, hi - centre],
                            fmt="none", ecolor=f"C{k}", capsize=3, lw=0.8,
                            label=f"{label}: 95 % prediction interval")
        ax.set_xlabel("wave frequency, rad/s")
        ax.set_ylabel(f"{channel} per wave amplitude, {unit}/m")   # the RAO
        ax.set_title(channel)
        ax.grid(alpha=0.3)
    legend = {}
    for ax in axes[0]:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            legend.setdefault(label, handle)
    fig.legend(legend.values(), legend.keys(), fontsize=7, loc="lower center",
               ncol=min(len(legend), 4), frameon=False)
    if title:
        fig.suptitle(title)
    fig.tight_layout(rect=(0, 0.06 * math.ceil(len(legend) / 4), 1, 0.93 if title else 1))
    if path is not None:
        save(fig, path)
    return fig


def plot_time_series(problem, run_name: str, values_by_label: dict, path=None):
    """One run's free channels over its steady window: measured and each labelled model.
    Returns the figure (written to path when given)."""
    import matplotlib.pyplot as plt

    from ...plotting import save
    k = next(i for i, r in enumerate(problem.runs) if r.name == run_name)
    run = problem.runs[k]
    sims = {label: problem.simulate(values)[k] for label, values in values_by_label.items()}
    fig, axes = plt.subplots(len(run.channels), 1, figsize=(8, 2.6 * len(run.channels)),
                             squeeze=False, sharex=True)
    for ax, channel in zip(axes[:, 0], run.channels):
        keep = (run.time >= run.window[0]) & (run.time <= run.window[1])
        ax.plot(run.time[keep], run.channels[channel][keep], "k", lw=1.2, label="measured")
        for i, (label, sim) in enumerate(sims.items()):
            t, y, _ = sim[channel]
            ax.plot(t, y, color=f"C{i}", lw=1, label=label)
        ax.set_ylabel(f"{channel}\n[{channel_unit(channel)}]"
                      + (" (up)" if channel.lower() == "heave" else ""))
        ax.grid(alpha=0.3)
    axes[0, 0].set_title(f"{run.name}: {run.group}, omega {run.omega:.3f} rad/s, wave amplitude "
                         f"{1000 * run.amplitude:.1f} mm")
    axes[-1, 0].set_xlabel("time on the run's clock, s")
    axes[0, 0].legend(fontsize=7)
    fig.tight_layout()
    if path is not None:
        save(fig, path)
    return fig
