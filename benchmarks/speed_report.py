"""The speed benchmark's report: the table, the CSV files and the chart (see speed.py)."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from speed_cases import (ERROR_MEASURE, REF_CONV, REF_SS, REF_TARGET, RTF_TARGET, SPEEDUP_TARGET, TOL,
                         Trial)


def setting(trial: Trial | None, side: str) -> str:
    if trial is None:
        return "none met 1 %"
    if side == "mbcontrol":
        step = f"rtol {trial.rtol:g}" if trial.rtol is not None else f"dt {trial.step:.4g}"
        return f"{trial.method}, {step}, {trial.radiation_tol:g}"
    return f"{trial.step:.4g}, {trial.rtol:g}"


def print_table(results, args, elapsed):
    print(f"Real-time factors at 1 % RMS accuracy, {args.duration:.0f} s JONSWAP seas (gamma 3.3, "
          f"seed {args.seed}); one core, best of {args.repeat} for mbcontrol")
    print(f"error: {ERROR_MEASURE} (mbcontrol: RK4 at Tp/{REF_SS} of the full model; baseline: "
          f"its convolution equations by RK4 at Tp/{REF_CONV}; either halved in step until it "
          f"moves less than {REF_TARGET:g} from the 2x coarser step)")
    head = (f"{'model':16s} {'states':>6s}  {'toolbox (method, dt, rad.tol)':34s} {'rms err':>8s} "
            f"{'RTF':>10s} | {'baseline (delta, rtol)':22s} {'rms err':>8s} {'RTF':>8s} | "
            f"{'speed-up':>9s} | {'SS vs conv':>10s}")
    print(head)
    print("-" * len(head))
    for r in results:
        tb, bl = r.toolbox, r.baseline
        states = f"{tb.states}" if tb else "-"
        tb_err = f"{tb.error:.1e}" if tb else "-"
        tb_rtf = f"{tb.rtf:,.0f}" if tb else "-"
        bl_err = f"{bl.error:.1e}" if bl else "-"
        bl_rtf = (f"{bl.rtf:,.1f}" + ("*" if bl.extrapolated else "")) if bl else "-"
        speedup = f"{tb.rtf / bl.rtf:,.0f}x" if tb and bl else "-"
        print(f"{r.case.name:16s} {states:>6s}  {setting(tb, 'mbcontrol'):34s} {tb_err:>8s} "
              f"{tb_rtf:>10s} | {setting(bl, 'baseline'):22s} {bl_err:>8s} {bl_rtf:>8s} | "
              f"{speedup:>9s} | {r.model_diff:10.1e}")
    print()
    print(f"targets: >= {RTF_TARGET:,}x real time (sphere, rm3, hinged_barge) and >= "
          f"{SPEEDUP_TARGET}x faster than the baseline (every model)")
    for r in results:
        tb, bl = r.toolbox, r.baseline
        parts = []
        if r.case.rtf_target:
            ok = tb is not None and tb.rtf >= RTF_TARGET
            parts.append(f"real time {'MET' if ok else 'MISSED'} "
                         f"({tb.rtf:,.0f}x)" if tb else "real time MISSED (no setting met 1 %)")
        if tb and bl:
            ratio = tb.rtf / bl.rtf
            parts.append(f"speed-up {'MET' if ratio >= SPEEDUP_TARGET else 'MISSED'} "
                         f"({ratio:,.0f}x)")
        else:
            parts.append("speed-up not measured (a side met no setting)")
        print(f"  {r.case.name:16s} " + "; ".join(parts))
    print()
    print("references converged: " + "; ".join(
        f"{r.case.name} mbcontrol {r.ss_check:.0e} (Tp/{r.ss_k}), convolution "
        f"{r.conv_check:.0e} (Tp/{r.conv_k})" for r in results) +
        " (difference to the 2x coarser step)")
    print("largest error in: " + "; ".join(
        f"{r.case.name} mbcontrol {r.toolbox.worst if r.toolbox else '-'}, baseline "
        f"{r.baseline.worst if r.baseline else '-'}" for r in results))
    for r in results:
        diff = sorted(r.model_diff_by_coordinate.items(), key=lambda kv: -kv[1])
        if len(diff) > 1:
            print(f"SS vs conv, {r.case.name}: {diff[0][0]} {diff[0][1]:.1e}, the other "
                  f"coordinates <= {diff[1][1]:.1e}")
    extrapolated = [r for r in results if r.baseline and r.baseline.extrapolated]
    for r in extrapolated:
        print(f"* {r.case.name}: baseline timed on a {r.baseline.record_s:.0f} s record and "
              f"EXTRAPOLATED to {args.duration:.0f} s (constant cost per step once the "
              f"{r.baseline.note.split('kernel ')[-1]} kernel is filled)")
    print("SS vs conv: the two converged references compared with the same measure (state-"
          "space radiation fit vs direct convolution of the BEM kernel)")
    print(f"wrote {Path(args.out) / 'speed_summary.csv'}, speed_trials.csv, speed.png "
          f"({elapsed / 60:.1f} min)")


def write_csv(results, out: Path) -> None:
    fields = ["model", "side", "method", "step_s", "rtol", "radiation_tol", "states", "record_s",
              "rms_error", "worst_coordinate", "wall_s", "runs", "rtf", "status", "chosen",
              "note"]
    with open(out / "speed_trials.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(fields)
        for r in results:
            for t in r.trials:
                writer.writerow([t.model, t.side, t.method, t.step, t.rtol, t.radiation_tol,
                                 t.states, t.record_s, t.error, t.worst, t.wall_s, t.runs, t.rtf,
                                 t.status, t.chosen, t.note])
    summary = ["model", "toolbox_method", "toolbox_dt_s", "toolbox_rtol", "radiation_tol",
               "states", "toolbox_rms_error", "toolbox_rtf", "baseline_delta_s", "baseline_rtol",
               "baseline_rms_error", "baseline_rtf", "baseline_record_s", "speedup",
               "model_difference_ss_vs_conv", "model_difference_by_coordinate",
               "toolbox_worst_coordinate", "baseline_worst_coordinate", "reference_check_toolbox",
               "reference_check_convolution", "rtf_target", "speedup_target", "error_measure"]
    with open(out / "speed_summary.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(summary)
        for r in results:
            tb, bl = r.toolbox, r.baseline
            writer.writerow([
                r.case.name, tb.method if tb else "", tb.step if tb else "",
                tb.rtol if tb and tb.rtol is not None else "", tb.radiation_tol if tb else "",
                tb.states if tb else "", tb.error if tb else "", tb.rtf if tb else "",
                bl.step if bl else "", bl.rtol if bl else "", bl.error if bl else "",
                bl.rtf if bl else "", bl.record_s if bl else "",
                tb.rtf / bl.rtf if tb and bl else "", r.model_diff,
                json.dumps(r.model_diff_by_coordinate), tb.worst if tb else "",
                bl.worst if bl else "", r.ss_check, r.conv_check,
                RTF_TARGET if r.case.rtf_target else "", SPEEDUP_TARGET, ERROR_MEASURE])


def chart(results, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mbcontrol import plotting

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5))
    names = [r.case.name for r in results]
    x = np.arange(len(results))
    tb = [r.toolbox.rtf if r.toolbox else np.nan for r in results]
    bl = [r.baseline.rtf if r.baseline else np.nan for r in results]
    ax1.bar(x - 0.2, tb, 0.4, label="mbcontrol (cheapest setting at 1 %)")
    ax1.bar(x + 0.2, bl, 0.4, label="solve_ivp + direct convolution (cheapest at 1 %)")
    for i, r in enumerate(results):
        if r.toolbox and r.baseline:
            ax1.annotate(f"{tb[i] / bl[i]:,.0f}x", (x[i], tb[i]), ha="center", va="bottom",
                         fontsize=8)
    ax1.axhline(RTF_TARGET, ls="--", c="k", lw=0.8, label=f"target {RTF_TARGET:,}x")
    ax1.set_yscale("log")
    ax1.set_ylim(1.0, 10 ** np.ceil(np.log10(np.nanmax(tb + [RTF_TARGET])) + 1.5))
    ax1.set_xticks(x, names, fontsize=8)
    ax1.set_ylabel("real-time factor (simulated s per wall s)")
    ax1.set_title("real-time factor at 1 % RMS accuracy")
    ax1.legend(fontsize=7)
    default_tol = {r.case.name: r.trials[0].radiation_tol for r in results if r.trials}
    markers = {"rk4": "o", "rk3": "v", "dopri5": "D", "exp-rk4": "s", "cvodes": "^",
               "adams": "P"}
    for i, r in enumerate(results):
        color = f"C{i}"
        for t in r.trials:
            if t.status != "ok" or not np.isfinite(t.error) or t.error <= 0:
                continue
            marker = "x" if t.side == "baseline" else markers.get(t.method, "o")
            crude = t.side == "mbcontrol" and t.radiation_tol != default_tol.get(r.case.name)
            ax2.loglog(t.rtf, t.error, marker, color=color, ms=9 if t.chosen else 4,
                       mfc="none" if crude else color, alpha=0.8)
        ax2.plot([], [], "o", color=color, label=r.case.name)
    for method, marker in markers.items():
        ax2.plot([], [], marker, color="grey", label=method)
    ax2.plot([], [], "x", color="grey", label="baseline")
    ax2.axhline(TOL, ls="--", c="k", lw=0.8)
    ax2.set_xlabel("real-time factor")
    ax2.set_ylabel("relative RMS error (max over coordinates)")
    ax2.set_title("every setting tried (large: chosen; hollow: cruder radiation fit)")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=7, ncol=2)
    plotting.save(fig, path)
    plt.close(fig)
