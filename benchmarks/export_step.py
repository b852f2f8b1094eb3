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
         ("sphere", "mpc", "sea"), ("sphere", "mpc", "binding"), ("wavestar", "mpc", "sea")]
SEAS = {"sphere": (2.0, 9.0), "wavestar": (0.1, 2.0)}    # Hs m, Tp s (Wavestar: tank scale)
# where the MPC works hardest: `mbcontrol export sphere --controller mpc --wave regular
# --height 2.5 --period 9.6664` (issue 38): force, stroke and slew limits all bind
BINDING = (2.5, 9.6664)                                # H m, T s


def run_case(model, name, kind, steps, python_steps, folder):

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
    hs, tp = BINDING if kind == "binding" else SEAS[model]
    regular_wave = kind in ("swell", "binding")
    parameters, _, _, extra = tune(plant, regular(hs, tp) if regular_wave else
                                   irregular(hs, tp, seed=0, duration=600.0), name,
                                   plant.scene.ptos[0], True, None, [])
    # the C engine does not hold the MPC's envelope: exported without it, as `mbcontrol export`
    controller = make(name, **parameters, **extra, **({"envelope": False} if name == "mpc" else {}))
    period = getattr(controller, "period", None)
    dt = tp / 200 if period is None else period / max(1, round(period / (tp / 200)))
    duration = steps * (period or dt)
    wave = regular(hs, tp) if regular_wave else irregular(hs, tp, seed=0, duration=duration)
    exported = export_controller(controller, plant, folder / f"{model}_{name}_{kind}")
    c = CController.from_export(exported, period=period)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        record = simulate(plant, wave, duration=duration, dt=dt, controller=c, audit=False)
    timing = step_timing(controller, exported, record, plant, python_steps=python_steps)
    # the check: 200 s of the sea (20 periods of the swell), Python against C and the FMUs
    check_s = 20 * tp if regular_wave else 200.0
    check_wave = wave if regular_wave else irregular(hs, tp, seed=1, duration=check_s)
    plant_fmu = export_plant(plant, check_wave, folder / f"{model}_{name}_{kind}", dt=dt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = closed_loop_check(plant, check_wave, controller, exported, duration=check_s,
                                  dt=dt, plant_fmu=plant_fmu)["check"]
    return {"model": model, "controller": name, "wave": kind, "check": check,
            "c_us": timing["c"],
            "python_us": timing["python"], "speed_up_median": timing["speed_up_median"],
            **footprint(exported), "dt_s": dt, "period_s": period,
            "kalman_states": int(exported.spec.defines.get("MBC_NK", 0)),
            "qp_max_iter": int(exported.spec.defines.get("MBC_QP_MAX_ITER", 0))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out/bench/export")
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--python-steps", type=int, default=10_000)
    parser.add_argument("--case", action="append", metavar="MODEL:CONTROLLER:WAVE",
                        help="only these cases, e.g. sphere:mpc:binding (repeatable)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for model, name, kind in CASES:
            if args.case and f"{model}:{name}:{kind}" not in args.case:
                continue
            row = run_case(model, name, kind, args.steps, args.python_steps, Path(tmp))
            rows.append(row)
            print(f"{model} {name}: C median {row['c_us']['median']:.3g} us", flush=True)
    (out / "export_step.json").write_text(json.dumps(rows, indent=2))
    print("\n| model | controller | C step median / p99 / max (us) | Python step median (us) "
          "| speed-up | C context (bytes) | library (kB) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        c = r["c_us"]
        print(f"| {r['model']} | {r['controller']}{' (H 2.5 m regular)' if r['wave'] == 'binding' else ''} | "
              f"{c['median']:.3g} / {c['p99']:.3g} / "
              f"{c['max']:.3g} | {r['python_us']['median']:.3g} | {r['speed_up_median']:.0f}x "
              f"| {r['context_bytes']:,} | {r['library_bytes'] / 1e3:.0f} |")
    print("\n| model, controller | C vs Python: force, mean power | FMUs in fmpy vs Python: "
          "force, PTO position | Python vs itself from x0 + 1e-12: force, mean power "
          "| mean power (W), run's physics checks |")
    print("|---|---|---|---|---|")
    for r in rows:
        k, f, z = r["check"], r["check"]["fmu"], r["check"]["round_off_floor"]
        label = " (H 2.5 m regular)" if r["wave"] == "binding" else ""
        print(f"| {r['model']}, {r['controller']}{label} | {k['max_rel_force_error']:.1e}, "
              f"{k['mean_power_rel_error']:.1e} | {f['max_rel_force_error']:.1e}, "
              f"{f['max_rel_position_error']:.1e} | {z['max_rel_force_error']:.1e}, "
              f"{z['mean_power_rel_error']:.1e} | {k['python_mean_power_W']:.4g}, "
              f"{'valid' if k['python_run_valid'] else 'INVALID'} |")
    for r in rows:
        for reason in r["check"]["python_run_invalid_reasons"]:
            print(f"{r['model']} {r['controller']}: {reason}")
    print(f"\n{rows[0]['c_us']['steps']:,} C steps per row, {args.python_steps:,} Python steps; "
          f"written to {out / 'export_step.json'}")


if __name__ == "__main__":
    main()
