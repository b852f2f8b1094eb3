"""Sweep throughput (`make bench`): cases per minute of `mbcontrol.studies.sweep` serially and on
a local Dask cluster of 1 and 2 workers, against a plain loop of `simulate` calls on one plant
built beforehand (same cases, same metrics), measured in one run on this machine.

Two loads:
- light: rm3 (WEC-Sim's two-body point absorber, 36 states), PacWave South's 32 sea states
  (JONSWAP, ../shared/data/sites) x 4 seeds, one hour each at dt 0.05 s, the scene's PTO:
  128 cases of about 0.06 s each, where fixed costs (cluster start, each worker building
  its plant) show;
- heavy: the sphere under linear MPC (a QP every 0.1 s), 4 seas x 4 seeds, 300 s each.
The Dask figures include starting the cluster and each worker building its plant (compiled
code from the on-disk cache), as a user's sweep would.
"""
from __future__ import annotations

import argparse
import inspect
import json
import time
from pathlib import Path

from mbcontrol import waves
from mbcontrol.analysis import summary
from mbcontrol.controllers import REGISTRY, make
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate
from mbcontrol.studies.sweep import grid, read_seas, sweep

SITES = Path(__file__).resolve().parents[2] / "shared" / "data" / "sites"


def measure(model, seas, seeds, duration, dt, controller=None) -> dict:
    plant = build_plant(model)
    simulate(plant, waves.regular(1.0, 8.0), duration=10.0, dt=dt)        # compile, untimed
    start = time.perf_counter()
    loop = []
    for s in seas:
        for seed in range(seeds):
            wave = waves.irregular(s.hs, s.tp, seed=seed, duration=duration,
                                   data_band=(float(plant.hydro.omega[0]),
                                              float(plant.hydro.omega[-1])))
            law = None
            if controller:      # a predictive law gets the simulated sea, as the sweep does
                takes_wave = "wave" in inspect.signature(REGISTRY[controller]).parameters
                law = make(controller, **({"wave": wave} if takes_wave else {}))
            ds = simulate(plant, wave, duration=duration, dt=dt, controller=law)
            loop.append(sum(m["mean_power_W"] for m in summary(ds, plant)["ptos"].values()))
    walls = {"plain loop of simulate": time.perf_counter() - start}
    powers = {}
    for label, workers in (("sweep, serial", 0), ("sweep, Dask 1 worker", 1),
                           ("sweep, Dask 2 workers", 2)):
        start = time.perf_counter()
        ds, _ = sweep(model, seas, seeds=seeds, duration=duration, dt=dt, workers=workers,
                      controller=controller, progress=False)
        walls[label] = time.perf_counter() - start
        powers[label] = ds["mean_power_W"].values.ravel().tolist()
    n = len(seas) * seeds
    return {"model": model, "controller": controller, "cases": n, "duration_s": duration,
            "wall_time_s": walls,
            "cases_per_minute": {k: 60 * n / v for k, v in walls.items()},
            "identical": all(p == powers["sweep, serial"] for p in powers.values()),
            "loop_difference": max(abs(a - b) / abs(b) for a, b in
                                   zip(powers["sweep, serial"], loop))}


def report(r: dict) -> None:
    base = r["wall_time_s"]["plain loop of simulate"]
    print(f"sweep throughput, {r['model']} ({r['controller'] or 'scene PTO'}): {r['cases']} "
          f"cases of {r['duration_s']:g} s (cases per minute; ratio to the plain loop)")
    for label, wall in r["wall_time_s"].items():
        print(f"  {label:24s} {r['cases_per_minute'][label]:8.1f} /min  {base / wall:5.2f}x")
    one, two = r["wall_time_s"]["sweep, Dask 1 worker"], r["wall_time_s"]["sweep, Dask 2 workers"]
    print(f"  1 -> 2 workers: {one / two:.2f}x; serial, 1 and 2 workers identical: "
          f"{r['identical']}; largest difference to the loop {r['loop_difference']:.1e}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--out", help="write sweep.json here (a folder)")
    args = parser.parse_args(argv)
    results = [measure("rm3", read_seas(SITES / "pacwave_cluster_32.csv"), 4, 3600.0, 0.05),
               measure("sphere", grid([1.5, 3.0], [8.0, 11.0]), 4, 300.0, 0.1, "mpc")]
    for r in results:
        report(r)
    if args.out:
        Path(args.out).mkdir(parents=True, exist_ok=True)
        (Path(args.out) / "sweep.json").write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
