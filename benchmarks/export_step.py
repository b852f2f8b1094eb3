"""The exported controllers' step, timed in C, against the Python controllers' step: median,
99th percentile and max over 10^5 steps of a closed-loop run on this machine, and each
controller's memory (its C context: all its state; its library on disk).

Each controller is designed as `mbcontrol export` designs it (the tuners of `mbcontrol
design`; the MPC: a horizon of one peak period in 40 steps, AR forecast, Kalman estimator)
for the sphere and the Wavestar float in a JONSWAP sea (switching laws: the regular wave at
the sea's peak period, where their tuners work). The measurements come from a closed-loop run
of the exported controller itself, long enough for 10^5 controller steps; the C library steps
through them from a fresh start, timed per step inside C (clock_gettime); the Python
controller steps through the first 10^4 of the same measurements (time.perf_counter_ns).

Run: python benchmarks/export_step.py [--out out/bench/export] [--steps 100000]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CASES = [("sphere", "passive", "sea"), ("sphere", "reactive", "sea"),
         ("sphere", "latching", "swell"), ("sphere", "declutching", "swell"),
         ("sphere", "mpc", "sea"), ("sphere", "mpc", "binding"), ("sphere", "mpc", "worst"),
         ("wavestar", "mpc", "sea")]
SEAS = {"sphere": (2.0, 9.0), "wavestar": (0.1, 2.0)}    # Hs m, Tp s (Wavestar: tank scale)
# where the MPC works hardest: `mbcontrol export sphere --controller mpc --wave regular
# --height 2.5 --period 9.6664` (issue 38): force, stroke and slew limits all bind
BINDING = (2.5, 9.6664)                                # H m, T s
SITE = ROOT.parent / "shared" / "data" / "sites" / "pacwave_cluster_32.csv"


def worst_sea(path=SITE) -> tuple[float, float]:
    """(Hs m, Tp s) of the site's highest sea (columns Hm0, Tp): the MPC's worst, JONSWAP."""
    import csv
    with open(path, newline="") as f:
        row = max(csv.DictReader(f), key=lambda r: float(r["Hm0"]))
    return float(row["Hm0"]), float(row["Tp"])


LABELS = {"binding": " (H 2.5 m regular)", "worst": " (site's worst sea)"}


def run_case(model, name, kind, steps, python_steps, folder, blocks="default"):
    """One case's row; blocks: the MPC's move blocking ("default": as `mbcontrol export`
    exports it, the Mpc's export_settings; None: none; a count of blocks)."""

    from mbcontrol.controllers import make
    from mbcontrol.studies.design import tune
    from mbcontrol.export import CController, export_controller
    from mbcontrol.export.checks import closed_loop_check, footprint, step_timing
    from mbcontrol.export.plant import export_plant
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import load_scene
    from mbcontrol.sim import simulate
    from mbcontrol.waves import irregular, regular
    plant = build_plant(load_scene(model))
    hs, tp = BINDING if kind == "binding" else worst_sea() if kind == "worst" else SEAS[model]
    regular_wave = kind in ("swell", "binding")
    parameters, _, _, extra = tune(plant, regular(hs, tp) if regular_wave else
                                   irregular(hs, tp, seed=0, duration=600.0), name,
                                   plant.scene.ptos[0], True, None, [])
    # the settings the C engine needs (the MPC: no envelope; its move blocking), as
    # `mbcontrol export` adds them, or the layout asked for
    from mbcontrol.controllers import REGISTRY
    settings = dict(getattr(REGISTRY[name], "export_settings", {}))
    if name == "mpc" and blocks != "default":
        settings["blocks"] = blocks
    controller = make(name, **parameters, **extra, **settings)
    period = getattr(controller, "period", None)
    dt = tp / 200 if period is None else period / max(1, round(period / (tp / 200)))
    duration = steps * (period or dt)
    wave = regular(hs, tp) if regular_wave else irregular(hs, tp, seed=0, duration=duration)
    # a folder (so a library path) per layout: ctypes loads one path's library only once
    tag = "" if blocks == "default" else f"_blocks{blocks}"
    exported = export_controller(controller, plant, folder / f"{model}_{name}_{kind}{tag}")
    c = CController.from_export(exported, period=period)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        record = simulate(plant, wave, duration=duration, dt=dt, controller=c, audit=False)
    timing = step_timing(controller, exported, record, plant, python_steps=python_steps)
    from mbcontrol.controllers import mean_power
    power = mean_power(record, plant.scene.ptos[0].name)     # the C law's, over the run
    # the check: 200 s of the sea (20 periods of the swell), Python against C and the FMUs
    check_s = 20 * tp if regular_wave else 200.0
    check_wave = wave if regular_wave else irregular(hs, tp, seed=1, duration=check_s)
    plant_fmu = export_plant(plant, check_wave, folder / f"{model}_{name}_{kind}{tag}", dt=dt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = closed_loop_check(plant, check_wave, controller, exported, duration=check_s,
                                  dt=dt, plant_fmu=plant_fmu)["check"]
    return {"model": model, "controller": name, "wave": kind, "check": check,
            "blocks": getattr(getattr(controller, "settings", None), "blocks", None),
            "c_us": timing["c"], "c_cpu_us": timing["c_cpu"], "run_mean_power_W": power,
            "python_us": timing["python"], "speed_up_median": timing["speed_up_median"],
            **footprint(exported), "dt_s": dt, "period_s": period,
            "kalman_states": int(exported.spec.defines.get("MBC_NK", 0)),
            "qp_max_iter": int(exported.spec.defines.get("MBC_QP_MAX_ITER", 0)),
            "c_counts": timing.get("c_counts", {})}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out/bench/export")
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--python-steps", type=int, default=10_000)
    parser.add_argument("--case", action="append", metavar="MODEL:CONTROLLER:WAVE",
                        help="only these cases, e.g. sphere:mpc:binding (repeatable)")
    parser.add_argument("--blocks", action="append", metavar="none|COUNT",
                        help="MPC cases: run with this move blocking instead of the export's "
                             "default (repeatable: a row each; 'none': one force per step)")
    args = parser.parse_args()
    layouts = ["default"] if not args.blocks else [
        None if b == "none" else int(b) for b in args.blocks]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for model, name, kind in CASES:
            if args.case and f"{model}:{name}:{kind}" not in args.case:
                continue
            for blocks in (layouts if name == "mpc" else ["default"]):
                row = run_case(model, name, kind, args.steps, args.python_steps, Path(tmp),
                               blocks)
                rows.append(row)
                print(f"{model} {name} {kind} blocks {row['blocks']}: C median "
                      f"{row['c_us']['median']:.3g} us, CPU {row['c_cpu_us']['median']:.3g}",
                      flush=True)
    (out / "export_step.json").write_text(json.dumps(rows, indent=2))
    print_timing_table(rows)
    print_blocks_table(rows)
    print(f"\n{rows[0]['c_us']['steps']:,} C steps per row, {args.python_steps:,} Python steps; "
          f"written to {out / 'export_step.json'}")


def print_timing_table(rows) -> None:
    """The step times (wall and thread CPU), the checks and the MPC engine's counts."""
    print("\n| model | controller | C step median / p99 / max (us), wall | thread CPU "
          "| Python step median (us) "
          "| speed-up | C context (bytes) | library (kB) |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        c, cpu = r["c_us"], r["c_cpu_us"]
        print(f"| {r['model']} | {r['controller']}{LABELS.get(r['wave'], '')} | "
              f"{c['median']:.3g} / {c['p99']:.3g} / "
              f"{c['max']:.3g} | {cpu['median']:.3g} / {cpu['p99']:.3g} / {cpu['max']:.3g} "
              f"| {r['python_us']['median']:.3g} | {r['speed_up_median']:.0f}x "
              f"| {r['context_bytes']:,} | {r['library_bytes'] / 1e3:.0f} |")
    print("\n| model, controller | C vs Python: force, mean power | FMUs in fmpy vs Python: "
          "force, PTO position | Python vs itself from x0 + 1e-12: force, mean power "
          "| mean power (W), run's physics checks |")
    print("|---|---|---|---|---|")
    for r in rows:
        k, f, z = r["check"], r["check"]["fmu"], r["check"]["round_off_floor"]
        label = LABELS.get(r["wave"], "")
        print(f"| {r['model']}, {r['controller']}{label} | {k['max_rel_force_error']:.1e}, "
              f"{k['mean_power_rel_error']:.1e} | {f['max_rel_force_error']:.1e}, "
              f"{f['max_rel_position_error']:.1e} | {z['max_rel_force_error']:.1e}, "
              f"{z['mean_power_rel_error']:.1e} | {k['python_mean_power_W']:.4g}, "
              f"{'valid' if k['python_run_valid'] else 'INVALID'} |")
    for r in rows:
        if r["c_counts"]:
            k = r["c_counts"]
            print(f"{r['model']} {r['controller']} {r['wave']}: {k['solves']:,} QP solves, "
                  f"{k['soft_solves']:,} soft, "
                  f"{k['failures']:,} fallbacks (previous plan); {k['ar_fits']:,} AR fits, "
                  f"{k['ar_unstable_fits']:,} stabilised")
    for r in rows:
        for reason in r["check"]["python_run_invalid_reasons"]:
            print(f"{r['model']} {r['controller']}: {reason}")


def print_blocks_table(rows) -> None:
    """Per MPC case and move-blocking layout: the step times and the C law's mean power over
    the run against the same case without blocking (a row with blocks None), when run."""
    mpc = [r for r in rows if r["controller"] == "mpc"]
    if len({r["blocks"] for r in mpc}) < 2:
        return
    print("\n| case | blocks | C step median / p99 (us), wall | thread CPU | mean power "
          "(W) | against no blocking |")
    print("|---|---|---|---|---|---|")
    for r in mpc:
        ref = next((x for x in mpc if x["blocks"] is None and x["model"] == r["model"]
                    and x["wave"] == r["wave"]), None)
        c, cpu, p = r["c_us"], r["c_cpu_us"], r["run_mean_power_W"]
        vs = f"{p / ref['run_mean_power_W'] - 1:+.2%}" if ref else "-"
        print(f"| {r['model']} {r['wave']} | {r['blocks']} | {c['median']:.3g} / {c['p99']:.3g} "
              f"| {cpu['median']:.3g} / {cpu['p99']:.3g} | {p:.5g} | {vs} |")


if __name__ == "__main__":
    main()
