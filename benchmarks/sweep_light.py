"""Sweep throughput where cases are light (`make bench`, issue 18): rm3 (WEC-Sim's two-body
point absorber, 36 states), one hour at dt 0.05 s (72,000 RK4 steps, ~21 ms of stepping a
case), the scene's PTO, JONSWAP seas Hs 1.5-4.5 m x Tp 7-13 s (16 seas) x seeds.

Measured in one run, per case count (256 and 64 by default):
- the plain loop: the plant built once (untimed, its code compiled), then per case the wave
  as the sweep builds it, `simulate`, `summary`;
- `sweep(..., workers=0)`: serial in this process;
- `sweep(..., workers=2)`: 2 local Dask workers when the sweep pays for the cluster (its
  start and each worker's plant counted, as a user's sweep pays them), else serial.
The sweeps are whole calls (plant, cases, records, assembled Dataset). Prints cases per minute
and the ratio to the plain loop, checks the three give the same mean powers (to 1e-9), and
writes sweep_light.json and sweep_light.csv into --out.
"""
from __future__ import annotations

import argparse
import csv
import json
import time
from pathlib import Path

import numpy as np

HS = (1.5, 2.5, 3.5, 4.5)
TP = (7.0, 9.0, 11.0, 13.0)


def plain_loop(plant, seas, seeds, duration, dt) -> tuple[float, list]:
    from mbcontrol import waves
    from mbcontrol.analysis import summary
    from mbcontrol.sim import simulate
    omega = plant.hydro.omega
    band = (float(omega[0]), float(omega[-1]))
    headings = plant.hydro.data["wave_direction"].values
    direction = float(headings[0]) if len(headings) == 1 else 0.0
    powers = []
    start = time.perf_counter()
    for s in seas:
        for seed in range(seeds):
            wave = waves.irregular(s.hs, s.tp, gamma=s.gamma, seed=seed, duration=duration,
                                   data_band=band, direction=direction)
            ds = simulate(plant, wave, duration=duration, dt=dt)
            powers.append(sum(m["mean_power_W"] for m in summary(ds, plant)["ptos"].values()))
    return time.perf_counter() - start, powers


def timed_sweep(seas, seeds, duration, dt, workers) -> tuple[float, list, str]:
    from mbcontrol.studies.sweep import study, sweep
    seen = {}
    execute = study.execute

    def recording(*args, **kwargs):            # where the cases ran (serial or cluster)
        seen.update(execute(*args, **kwargs))
        return seen
    study.execute = recording
    try:
        start = time.perf_counter()
        ds, _ = sweep("rm3", seas, seeds=seeds, duration=duration, dt=dt, workers=workers,
                      progress=False)
        wall = time.perf_counter() - start
    finally:
        study.execute = execute
    return wall, ds["mean_power_W"].values.ravel().tolist(), seen.get("where", "?")


def measure(n_cases: int, duration: float, dt: float) -> dict:
    from mbcontrol import waves
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    from mbcontrol.studies.sweep import grid
    seas = grid(HS, TP)
    if n_cases % len(seas):
        raise SystemExit(f"--cases must be a multiple of {len(seas)} (seas), got {n_cases}")
    seeds = n_cases // len(seas)
    plant = build_plant("rm3")
    simulate(plant, waves.regular(1.0, 8.0), duration=60.0, dt=dt)        # compile, untimed
    walls, powers, where = {}, {}, {}
    walls["plain loop"], powers["plain loop"] = plain_loop(plant, seas, seeds, duration, dt)
    for label, workers in (("sweep, serial", 0), ("sweep, 2 workers", 2)):
        walls[label], powers[label], where[label] = timed_sweep(seas, seeds, duration, dt,
                                                                workers)
    loop = np.array(powers["plain loop"])
    difference = {k: float(np.max(np.abs(np.array(v) - loop) / np.abs(loop)))
                  for k, v in powers.items() if k != "plain loop"}
    base = walls["plain loop"]
    return {"model": "rm3", "cases": n_cases, "seas": len(seas), "seeds": seeds,
            "duration_s": duration, "dt_s": dt, "wall_time_s": walls,
            "cases_per_minute": {k: 60 * n_cases / v for k, v in walls.items()},
            "ratio_to_loop": {k: base / v for k, v in walls.items()},
            "where": where, "max_relative_power_difference": difference,
            "same_powers": all(d < 1e-9 for d in difference.values())}


def report(r: dict) -> None:
    print(f"light sweep, rm3 (scene PTO): {r['cases']} cases ({r['seas']} seas x {r['seeds']} "
          f"seeds) of {r['duration_s']:g} s at dt {r['dt_s']:g} s")
    for label, wall in r["wall_time_s"].items():
        ran = f"  ({r['where'][label]})" if label in r["where"] else ""
        print(f"  {label:18s} {wall:7.2f} s {r['cases_per_minute'][label]:8.1f} /min  "
              f"{r['ratio_to_loop'][label]:5.2f}x{ran}")
    print(f"  same mean powers as the loop (1e-9): {r['same_powers']} (largest relative "
          f"difference {max(r['max_relative_power_difference'].values()):.1e})")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--cases", type=int, nargs="+", default=[256, 64],
                        help="case counts, multiples of 16 (256 64)")
    parser.add_argument("--duration", type=float, default=3600.0, help="record length, s")
    parser.add_argument("--dt", type=float, default=0.05, help="step, s")
    parser.add_argument("--out", help="write sweep_light.json and .csv here (a folder)")
    args = parser.parse_args(argv)
    results = []
    for n in args.cases:
        results.append(measure(n, args.duration, args.dt))
        report(results[-1])
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "sweep_light.json").write_text(json.dumps(results, indent=2))
        with (out / "sweep_light.csv").open("w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow(["cases", "run", "wall_time_s", "cases_per_minute",
                             "ratio_to_loop", "where"])
            for r in results:
                for label, wall in r["wall_time_s"].items():
                    writer.writerow([r["cases"], label, f"{wall:.3f}",
                                     f"{r['cases_per_minute'][label]:.1f}",
                                     f"{r['ratio_to_loop'][label]:.3f}",
                                     r["where"].get(label, "")])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
