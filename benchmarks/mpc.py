"""Real-time cost of linear MPC (`make bench`): solve time per step and a 600 s closed loop.

Model: RM3 (two bodies, 36 states) reduced by balanced truncation to 30 states, the MPC's
control plant; horizon 40 steps of 0.2 s (8 s), force limit 2 MN, stroke limit 2 m, JONSWAP
Hs 2.5 m, Tp 8 s, 600 s, Kalman estimation of state and excitation, auto-regressive forecast.
Both QP paths on the same problem in one run: the real-time path (dense condensed QP,
qpOASES through CasADi) and the prototyping path (cvxpy with Parameters, Clarabel); the
ratio of their median solve times is the speed-up. Reported per path: median and 95th
percentile solve time per step (ms), the closed loop's wall time and real-time factor (the
nonlinear plant simulated at dt 0.02 s plus the controller), mean absorbed power (from work)
and max force and stroke. Aim (issue 5): median under 2 ms, run faster than real time by 50x.

Example: python benchmarks/mpc.py --out out/bench/mpc
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.controllers.mpc import Mpc
from mbcontrol.analysis import pto_metrics
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

MODEL, ORDER, HORIZON_STEPS, DT_S = "rm3", 30, 40, 0.2
FORCE_MAX, STROKE_MAX = 2e6, 2.0
DURATION, DT = 600.0, 0.02


def run(solver: str, plant, wave) -> dict:
    mpc = Mpc(horizon_s=HORIZON_STEPS * DT_S, dt_s=DT_S, force_max=FORCE_MAX,
              stroke_max=STROKE_MAX, wave=wave, forecast="ar", solver=solver, order=ORDER)
    start = time.perf_counter()
    ds = simulate(plant, wave, duration=DURATION, dt=DT, controller=mpc)
    wall = time.perf_counter() - start
    solve_ms = np.asarray(mpc.stats["solve_s"]) * 1e3
    m = pto_metrics(ds, plant.scene.ptos[0])
    return {"solver": solver, "states": mpc.cp.nz, "horizon_steps": mpc.N,
            "solve_ms_median": float(np.median(solve_ms)),
            "solve_ms_p95": float(np.percentile(solve_ms, 95)),
            "failures": mpc.stats["failures"], "closed_loop_wall_s": wall,
            "real_time_factor": DURATION / wall, "mean_power_kW": m["mean_power_W"] / 1e3,
            "max_force_MN": m["max_force"] / 1e6, "max_stroke_m": m["max_stroke"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out/bench/mpc"), help="output folder")
    ap.add_argument("--solvers", nargs="+", default=["qpoases", "cvxpy"],
                    choices=["qpoases", "cvxpy"], help="QP paths to time (both)")
    args = ap.parse_args(argv)
    plant = build_plant(MODEL)
    wave = waves.irregular(2.5, 8.0, seed=1, duration=DURATION)
    rows = [run(solver, plant, wave) for solver in args.solvers]
    args.out.mkdir(parents=True, exist_ok=True)
    tmp = args.out / "mpc.json.tmp"
    tmp.write_text(json.dumps(rows, indent=2))
    tmp.replace(args.out / "mpc.json")
    print(f"MPC on {MODEL} reduced to {ORDER} states, {HORIZON_STEPS}-step horizon "
          f"({HORIZON_STEPS * DT_S:g} s), {DURATION:g} s JONSWAP closed loop:")
    print(f"{'path':8s} {'median ms':>10s} {'p95 ms':>8s} {'wall s':>7s} {'RTF':>6s} "
          f"{'P kW':>7s} {'F MN':>6s} {'z m':>6s} fails")
    for r in rows:
        print(f"{r['solver']:8s} {r['solve_ms_median']:10.3f} {r['solve_ms_p95']:8.3f} "
              f"{r['closed_loop_wall_s']:7.2f} {r['real_time_factor']:6.0f} "
              f"{r['mean_power_kW']:7.1f} {r['max_force_MN']:6.3f} {r['max_stroke_m']:6.3f} "
              f"{r['failures']}")
    if len(rows) == 2:
        print(f"qpOASES is {rows[1]['solve_ms_median'] / rows[0]['solve_ms_median']:.1f}x "
              f"faster than cvxpy/Clarabel per solve (median)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
