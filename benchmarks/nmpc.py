"""Real-time cost of nonlinear MPC (controllers.nmpc): solve time per step and the closed loop.

Case: the 10 m sphere in the regular wave H 2.5 m, T 9.6664 s (ramp one period), force limit
2 MN, stroke limit 4 m, NMPC with a horizon of one wave period in 40 steps of T / 40 =
0.24 s (2 RK4 substeps each), the plant simulated at T / 200. Rows:

- sphere: the catalogue sphere (linear hydrostatics; 10 states), NMPC on its own model;
- sphere, large-angle buoyancy: the same sphere with large_angle hydrostatics, NMPC on that
  nonlinear model (as tests/controllers/test_nmpc.py's nonlinear case); skip with --no-nonlinear.

Reported per row: median, 95th percentile and largest solve time per controller step (ms),
mean IPOPT iterations, failures, the share of the controller period the 95th-percentile
solve takes (real-time margin: below 1 keeps up), and the closed loop's real-time factor
(simulated time over wall time, plant and controller together), with the mean absorbed
power (from work) over the last 3 periods. One core; times vary with machine load.

Writes nmpc.json (summary) and nmpc_solve_times.csv (every solve) to --out.
Example: python benchmarks/nmpc.py --out out/bench/nmpc
"""
from __future__ import annotations

import argparse
import csv
import json
import time
import tomllib
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.controllers.nmpc import Nmpc
from mbcontrol.analysis import pto_metrics
from mbcontrol.plant import build_plant
from mbcontrol.scene import catalogue_dir, parse_scene
from mbcontrol.sim import simulate

T = 9.6664                                   # s
FORCE_MAX, STROKE_MAX = 2e6, 4.0             # N, m


def large_angle_sphere():
    """The catalogue sphere with large-angle buoyancy (mass = half the sphere's
    displacement, so that rest is an equilibrium)."""
    path = catalogue_dir() / "sphere.toml"
    data = tomllib.loads(path.read_text())
    data["hydro"]["file"] = str(catalogue_dir() / "sphere_hydro.nc")
    data["hydro"]["hydrostatics"] = "large_angle"
    data["body"][0]["geometry"] = {"type": "sphere", "radius": 5.0, "center": [0.0, 0.0, 0.0]}
    data["body"][0]["mass"] = 1000.0 * 2 / 3 * np.pi * 5.0 ** 3
    return build_plant(parse_scene(data, path))


def run(label: str, plant, periods: int, horizon_periods: float, steps: int) -> dict:
    wave = waves.regular(2.5, T, ramp_time=T)
    dt_s = T / steps
    nmpc = Nmpc(wave, horizon_s=horizon_periods * T, dt_s=dt_s, force_max=FORCE_MAX,
                stroke_max=STROKE_MAX)
    start = time.perf_counter()
    ds = simulate(plant, wave, duration=periods * T, dt=dt_s / 5, controller=nmpc)
    wall = time.perf_counter() - start              # reset (problem build) included
    m = pto_metrics(ds, "pto", start=(periods - 3) * T, end=periods * T)
    times = np.asarray(nmpc.solve_times)
    return {"case": label, "states": plant.nx, "horizon_steps": round(horizon_periods * steps),
            "dt_s": dt_s, "solves": nmpc.solves, "failures": nmpc.failures,
            "iterations_mean": float(np.mean(nmpc.iterations)),
            "solve_median_ms": 1e3 * float(np.median(times)),
            "solve_p95_ms": 1e3 * float(np.percentile(times, 95)),
            "solve_max_ms": 1e3 * float(times.max()),
            "p95_over_period": float(np.percentile(times, 95)) / dt_s,
            "wall_s": wall, "real_time_factor": periods * T / wall,
            "mean_power_kW": m["mean_power_W"] / 1e3, "max_force_MN": m["max_force"] / 1e6,
            "max_stroke_m": m["max_stroke"], "times": times}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out/bench/nmpc"), help="output folder")
    ap.add_argument("--periods", type=int, default=10,
                    help="wave periods simulated (>= 4; power over the last 3)")
    ap.add_argument("--horizon-periods", type=float, default=1.0,
                    help="prediction horizon in wave periods")
    ap.add_argument("--steps", type=int, default=40, help="controller steps per wave period")
    ap.add_argument("--no-nonlinear", action="store_true",
                    help="skip the large-angle-buoyancy sphere")
    args = ap.parse_args(argv)
    if args.periods < 4:
        ap.error("--periods must be >= 4")
    args.out.mkdir(parents=True, exist_ok=True)

    cases = [("sphere", build_plant("sphere"))]
    if not args.no_nonlinear:
        cases.append(("sphere, large-angle buoyancy", large_angle_sphere()))
    rows = [run(label, plant, args.periods, args.horizon_periods, args.steps)
            for label, plant in cases]

    with open(args.out / "nmpc_solve_times.csv", "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["case", "step", "solve_time_s"])
        for r in rows:
            writer.writerows((r["case"], i, f"{t:.6g}") for i, t in enumerate(r["times"]))
    summary = [{k: v for k, v in r.items() if k != "times"} for r in rows]
    (args.out / "nmpc.json").write_text(json.dumps(summary, indent=2))

    print(f"NMPC, regular wave H 2.5 m T {T} s, limits 2 MN / 4 m, {args.periods} periods, "
          f"horizon {rows[0]['horizon_steps']} steps of {rows[0]['dt_s']:.4g} s")
    print(f"{'case':30s} {'nx':>3s} {'median ms':>9s} {'p95 ms':>7s} {'max ms':>7s} "
          f"{'iter':>5s} {'fail':>4s} {'p95/dt_s':>8s} {'x real time':>11s} {'P kW':>7s} "
          f"{'stroke m':>8s}")
    for r in rows:
        print(f"{r['case']:30s} {r['states']:3d} {r['solve_median_ms']:9.1f} "
              f"{r['solve_p95_ms']:7.1f} {r['solve_max_ms']:7.1f} {r['iterations_mean']:5.1f} "
              f"{r['failures']:4d} {r['p95_over_period']:8.3f} {r['real_time_factor']:11.1f} "
              f"{r['mean_power_kW']:7.1f} {r['max_stroke_m']:8.4f}")
    if len(rows) == 2:
        print(f"\nlarge-angle model / linear model: median solve "
              f"{rows[1]['solve_median_ms'] / rows[0]['solve_median_ms']:.1f}x, "
              f"real-time factor {rows[0]['real_time_factor'] / rows[1]['real_time_factor']:.1f}x "
              f"lower")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
