"""Figures: Bode plots, time series, time-domain vs frequency-domain responses.

Every function returns the matplotlib Figure and, given `path`, writes it (PNG) atomically.
Axes carry units and the sign convention (NED: heave positive down).
"""
from __future__ import annotations

from pathlib import Path

import matplotlib

# files, never a window (this runs in CI and on servers); a notebook's backend is kept
if not any(k in matplotlib.get_backend().lower() for k in ("inline", "module://", "widget", "nbagg")):
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .atomic import atomic_path
from .errors import InputError
from .lti import frequency_response
from .results import record


def save(fig, path) -> Path:
    """Write a figure to a temporary file, then rename it into place; its format is the
    suffix's (.png, .pdf, .svg, ...). An InputError names a path without one."""
    path = Path(path)
    kind = path.suffix.lstrip(".").lower()
    formats = fig.canvas.get_supported_filetypes()
    if kind not in formats:
        raise InputError(f"{path}: a figure's file name ends in the format to write, one of "
                         f"{', '.join('.' + f for f in sorted(formats))}; got "
                         f"{path.suffix or 'no suffix'}")
    with atomic_path(path, path.suffix) as tmp:
        fig.savefig(tmp, dpi=120, bbox_inches="tight", format=kind)
    return path


def bode(sys, pairs, omega, *, title=None, path=None, fd=None, units=None):
    """Magnitude and phase of sys from input to output, a column per (input, output) pair,
    titled by the channel, its magnitude in the output's unit per the input's (units: signal
    name -> unit, e.g. ProcessPlant.units; SI without).

    fd: optional {(input, output): complex response on omega} drawn as markers (e.g. the
    BEM-direct frequency-domain solution) over the state-space lines.
    """
    fig, axes = plt.subplots(2, len(pairs), sharex=True, squeeze=False,
                             figsize=(4.2 * len(pairs) + 0.8, 5.6))
    A, B, C, D = (np.asarray(M) for M in (sys.A, sys.B, sys.C, sys.D))
    for k, (inp, out) in enumerate(pairs):
        ax_mag, ax_ph = axes[:, k]
        i, o = sys.input_labels.index(inp), sys.output_labels.index(out)
        G = frequency_response(A, B[:, i], C[o], D[o, i], omega)[0, 0]
        ax_mag.loglog(omega, np.abs(G), label="linearised state space")
        ax_ph.semilogx(omega, np.degrees(np.unwrap(np.angle(G))))
        if fd and (inp, out) in fd:
            ax_mag.loglog(omega, np.abs(fd[(inp, out)]), "o", ms=3, color="C1", alpha=0.7,
                          label="frequency domain (BEM data)")
            ax_mag.legend(fontsize=8)
        unit_in, unit_out = ((units or {}).get(inp) or "SI", (units or {}).get(out) or "SI")
        ax_mag.set_title(f"{signal_label(inp)} → {signal_label(out)}", fontsize=10)
        ax_mag.set_ylabel(f"magnitude ({unit_out} per {unit_in})")
        ax_ph.set_ylabel("phase (deg)")
        ax_ph.set_xlabel("ω (rad/s)")
        for ax in (ax_mag, ax_ph):
            ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(title or f"Bode: {sys.name}")
    fig.tight_layout()
    if path:
        save(fig, path)
    return fig


_KINDS = {"power": "power", "force": "force", "velocity": "velocity", "position": "position",
          "vel": "rate", "tension": "tension"}


def signal_label(name: str) -> str:
    """A reader's name for a plant signal: "hinge_pto__power" -> "hinge_pto power",
    "barge2__Heave" -> "barge2 heave (z down)", "eta" -> "wave elevation (up)"."""
    if name == "eta":
        return "wave elevation (up)"
    if name.startswith("u__"):
        return f"{name[3:]} command"
    if name.startswith("w__"):
        body, _, dof = name[3:].rpartition("__")
        return f"wave load, {body} {dof.lower()}"
    base, _, kind = name.rpartition("__")
    if not base:
        return name                       # a joint coordinate: its own name
    if kind == "Heave":
        return f"{base} heave (z down)"
    return f"{base} {_KINDS.get(kind, kind.lower())}"


def _ylabel(ax, name, unit, label=None):
    ax.set_ylabel(f"{label or signal_label(name)}\n[{unit}]" if unit else
                  (label or signal_label(name)), fontsize=8)


def time_series(ds, names, *, title=None, path=None, units=None, labels=None):
    """Stacked time histories of named variables of a simulation result, each labelled for a
    reader with its unit (labels: name -> label, default `signal_label`); power panels carry
    their mean over the statistics window; the title says the model, the wave and the
    controller."""
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(8, 1.9 * len(names) + 0.6))
    axes = np.atleast_1d(axes)
    start = _window_start(ds)
    for ax, name in zip(axes, names):
        t, y = ds["time"].values, ds[name].values
        ax.plot(t, y, lw=0.9)
        unit = (units or {}).get(name, ds[name].attrs.get("units", ""))
        _ylabel(ax, name, unit, (labels or {}).get(name))
        if name.endswith("__power") and np.any(t >= start):
            mean = float(np.mean(y[t >= start]))
            ax.axhline(mean, color="0.25", lw=0.9, ls="--")   # red is for INVALID results
            ax.annotate(f"mean {mean:.3g} {unit} (t >= {start:.3g} s; grey: not in the "
                        f"statistics)", (0.01, 0.88), xycoords="axes fraction", fontsize=8,
                        color="0.15")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(title or _run_title(ds))
    mark_result(ds, axes, axes[0])
    if path:
        save(fig, path)
    return fig


def _run_title(ds) -> str:
    """A run's model, wave and controller, from its record: "sphere, JONSWAP Hs 2 m, Tp 8 s,
    seed 0; controller passive"."""
    wave = record(ds.attrs, "wave", {})
    kind = wave.get("type", "none")
    if kind == "regular" and "height" in wave:
        sea = f"regular wave H {wave['height']:.3g} m, T {wave['period']:.3g} s"
    elif "hs" in wave:
        sea = (f"{kind.upper()} Hs {wave['hs']:.3g} m, Tp {wave['tp']:.3g} s, seed "
               f"{wave.get('seed', 0)}")
    else:
        sea = "still water" if kind == "none" else f"{kind} wave"
    controller = record(ds.attrs, "controller")
    law = (controller or {}).get("name", "the scene's PTO laws")
    return f"{ds.attrs.get('model', '')}, {sea}; controller: {law}"


INVALID_FACE = "#fde4e4"        # axes of a result that failed its physics checks


def result_label(ds) -> str:
    """What a reader must know about a result beside its numbers: INVALID (failed its physics
    checks) and oracle (a controller that saw the future wave), or ''."""
    notes = []
    if ds.attrs.get("valid", 1) == 0:
        notes.append("INVALID: " + "; ".join(record(ds.attrs, "invalid_reasons", [])))
    if (record(ds.attrs, "controller") or {}).get("oracle"):
        notes.append("oracle forecast: a non-causal upper bound")
    return " | ".join(notes)


def _window_start(ds) -> float:
    """Where the statistics start (s): after the wave's ramp and the controller's warm-up."""
    wave = record(ds.attrs, "wave", {})
    controller = record(ds.attrs, "controller") or {}
    return max(float(wave.get("ramp_s", 0.0) or 0.0),
               float(controller.get("warm_up_s", 0.0) or 0.0))


def mark_result(ds, axes, title_ax) -> None:
    """Shade what the statistics leave out (the wave's ramp, the controller's warm-up) and
    mark an invalid or oracle result on its axes (red faces, a note under the title)."""
    import textwrap
    wave = record(ds.attrs, "wave", {})
    start = _window_start(ds)
    first = float(ds["time"].values[0])
    for ax in np.ravel(axes):
        if start > first and wave.get("type") != "regular":
            ax.axvspan(first, start, color="0.85", lw=0, zorder=0, label="not in statistics")
        if ds.attrs.get("valid", 1) == 0:
            ax.set_facecolor(INVALID_FACE)
    label = result_label(ds)
    if label:
        text = title_ax.get_title()
        title_ax.set_title(text + "\n" + textwrap.shorten(label, 110), fontsize=8,
                           color="C3" if ds.attrs.get("valid", 1) == 0 else "C1")


def compare_runs(runs: dict, names, *, title=None, units=None, path=None, labels=None,
                 notes=None, own_scale=(), scale=None):
    """Runs side by side: a column per run (titled by its label), a row per variable, each
    row on one y scale, so what the title of a column says is what it shows; a row named in
    `own_scale` gets a scale per column instead (a power whose peaks differ tenfold between
    laws), its tick labels on every column. labels: name -> the row's label (default
    `signal_label`); notes: name -> {run label: text} written in the panel (e.g. the run's
    mean power); scale: name -> factor the values are multiplied by (with its unit in
    `units`, e.g. 1e3 for mW)."""
    fig, axes = plt.subplots(len(names), len(runs), sharex=True, squeeze=False,
                             figsize=(3.2 * len(runs), 1.8 * len(names) + 0.9))
    for i, name in enumerate(names):                 # one scale per row, unless asked
        if name not in own_scale:
            for ax in axes[i, 1:]:
                ax.sharey(axes[i, 0])
                ax.tick_params(labelleft=False)
    for j, (label, ds) in enumerate(runs.items()):
        axes[0, j].set_title(label, fontsize=8)
        for i, name in enumerate(names):
            factor = (scale or {}).get(name, 1.0)
            axes[i, j].plot(ds["time"].values, factor * ds[name].values, lw=0.8)
            axes[i, j].grid(alpha=0.3)
            text = (notes or {}).get(name, {}).get(label)
            if text:
                axes[i, j].annotate(text, (0.02, 0.86), xycoords="axes fraction", fontsize=8,
                                    color="0.15", fontweight="bold",
                                    bbox={"facecolor": "white", "alpha": 0.8, "lw": 0})
            if j == 0:
                _ylabel(axes[i, j], name, (units or {}).get(name, ""), (labels or {}).get(name))
        axes[-1, j].set_xlabel("time (s)")
        mark_result(ds, axes[:, j], axes[0, j])
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    if path:
        save(fig, path)
    return fig


def response_comparison(omega, curves: dict, *, ylabel, title, path=None):
    """Amplitude per unit wave amplitude against frequency, one line or marker set each.

    curves: label -> (omega, values, style) with style a matplotlib format string.
    """
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for label, (w, values, style) in curves.items():
        ax.plot(w, values, style, label=label, ms=5)
    ax.set_xlabel("ω (rad/s)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    if path:
        save(fig, path)
    return fig
