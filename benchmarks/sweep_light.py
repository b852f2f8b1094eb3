"""Sweep throughput where cases are light (`make bench`, issue 18): rm3 (WEC-Sim's two-body
point absorber, 36 states), one hour at dt 0.05 s (72,000 RK4 steps, ~21 ms of stepping a
case), the scene's PTO, JONSWAP seas x seeds. Two sets of seas (--seas): "grid", Hs 1.5-4.5 m
x Tp 7-13 s (16 seas; --cases 256 = 16 seeds), and "pacwave", PacWave South's 32 weighted
sea states (../shared/data/sites/pacwave_cluster_32.csv; --cases 256 = 8 seeds), which also
computes the sweep's annual energy and its budget.

Measured in one run, per case count (256 and 64 by default):
- the plain loop: the plant built once (untimed, its code compiled), then per case the wave
  as the sweep builds it, `simulate`, `summary`;
- `sweep(..., workers=0)`: serial in this process;
- `sweep(..., workers=2)`: 2 local Dask workers, per start method (--start; its start and
  each worker's plant counted, as a user's sweep pays them). --cluster always (the default
  here) starts the cluster whatever the machine's load: "auto", a user's default, runs the
  sweep serially on a machine whose other work leaves fewer than 2 cores idle
  (`runner.idle_cores`), which a shared benchmark machine often is.
The sweeps are whole calls (plant, cases, records, assembled Dataset, the seas' spectral
statistics and budget); "cases" is their `execute` (the cases alone). Prints per run the wall
time, cases per minute, the ratio to the plain loop, the CPU seconds of this process and its
children (the workers: what the machine's other load does not change), and the 2-worker
sweep's speed-up over the serial sweep; checks every run gives the loop's mean powers (to
1e-9); writes sweep_light.json and sweep_light.csv into --out, with --report a Dask
performance report of the first 2-worker sweep (sweep_light_dask_<seas>_<cases>.html; needs
bokeh).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import threading
import time
from pathlib import Path

import numpy as np

HS = (1.5, 2.5, 3.5, 4.5)
TP = (7.0, 9.0, 11.0, 13.0)
PACWAVE = Path(__file__).resolve().parents[2] / "shared" / "data" / "sites" / \
    "pacwave_cluster_32.csv"


class CpuMeter:
    """CPU seconds (user + system) of this process and every descendant (Dask's workers,
    a fork server's children) between start and stop, sampled every 0.1 s on a thread: a
    child that ends is counted up to its last sample."""

    def __init__(self):
        import psutil
        self._me, self._seen, self._stop = psutil.Process(), {}, threading.Event()
        self._thread = threading.Thread(target=self._sample_loop, daemon=True)

    def _sample(self):
        for p in [self._me, *self._me.children(recursive=True)]:
            try:
                t = p.cpu_times()
                self._seen[(p.pid, p.create_time())] = t.user + t.system
            except Exception:          # noqa: BLE001 - a child that ended meanwhile
                pass

    def _sample_loop(self):
        while not self._stop.wait(0.1):
            self._sample()

    def __enter__(self):
        self._sample()
        self._base = dict(self._seen)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self._sample()
        self.seconds = sum(v - self._base.get(k, 0.0) for k, v in self._seen.items())


def plain_loop(plant, seas, seeds, duration, dt) -> tuple[float, float, list]:
    """(wall s, CPU s, mean powers W) of the loop over seas x seeds."""
    from mbcontrol import waves
    from mbcontrol.analysis import summary
    from mbcontrol.sim import simulate
    omega = plant.hydro.omega
    band = (float(omega[0]), float(omega[-1]))
    headings = plant.hydro.data["wave_direction"].values
    direction = float(headings[0]) if len(headings) == 1 else 0.0
    powers = []
    with CpuMeter() as cpu:
        start = time.perf_counter()
        for s in seas:
            for seed in range(seeds):
                wave = waves.irregular(s.hs, s.tp, gamma=s.gamma, seed=seed, duration=duration,
                                       data_band=band, direction=direction)
                ds = simulate(plant, wave, duration=duration, dt=dt)
                powers.append(sum(m["mean_power_W"]
                                  for m in summary(ds, plant)["ptos"].values()))
        wall = time.perf_counter() - start
    return wall, cpu.seconds, powers


def timed_sweep(seas, seeds, duration, dt, workers, report=None) -> dict:
    """One whole sweep call: {"wall", "cases" (its execute, s), "cpu", "where", "powers"};
    report: a file for Dask's performance report of its cluster phase."""
    from mbcontrol.studies.sweep import runner, study, sweep
    seen, execute, on_dask = {}, study.execute, runner._on_dask

    def recording(*args, **kwargs):            # where the cases ran, and how long they took
        t0 = time.perf_counter()
        seen.update(execute(*args, **kwargs))
        seen["cases"] = time.perf_counter() - t0
        return seen

    def reported(*args, **kwargs):
        from dask.distributed import performance_report
        with performance_report(filename=str(report)):
            return on_dask(*args, **kwargs)
    study.execute = recording
    if report is not None:
        runner._on_dask = reported
    try:
        with CpuMeter() as cpu:
            start = time.perf_counter()
            ds, _ = sweep("rm3", seas, seeds=seeds, duration=duration, dt=dt, workers=workers,
                          progress=False)
            wall = time.perf_counter() - start
    finally:
        study.execute, runner._on_dask = execute, on_dask
    return {"wall": wall, "cases": seen["cases"], "cpu": cpu.seconds,
            "where": seen.get("where", "?"), "powers": ds["mean_power_W"].values.ravel().tolist()}


def the_seas(which: str) -> list:
    from mbcontrol.studies.sweep import grid, read_seas
    return grid(HS, TP) if which == "grid" else read_seas(PACWAVE)


def _report_file(out, seas_name: str, n_cases: int):
    """Where the Dask performance report goes (None: not asked, or bokeh missing)."""
    if out is None:
        return None
    try:
        import bokeh  # noqa: F401  (Dask's report draws with it)
    except ImportError:
        print("  (no Dask performance report: bokeh is not installed)")
        return None
    Path(out).mkdir(parents=True, exist_ok=True)
    return Path(out) / f"sweep_light_dask_{seas_name}_{n_cases}.html"


def measure(seas_name: str, n_cases: int, duration: float, dt: float, starts, cluster: str,
            report_to=None) -> dict:
    """The loop and the sweeps of one case count; walls s, CPU s, ratios."""
    from mbcontrol import waves
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    seas = the_seas(seas_name)
    if n_cases % len(seas):
        raise SystemExit(f"--cases must be a multiple of {len(seas)} (seas), got {n_cases}")
    seeds = n_cases // len(seas)
    plant = build_plant("rm3")
    simulate(plant, waves.regular(1.0, 8.0), duration=60.0, dt=dt)        # compile, untimed
    load = os.getloadavg()[0]
    runs = {}
    wall, cpu, powers = plain_loop(plant, seas, seeds, duration, dt)
    runs["plain loop"] = {"wall": wall, "cases": wall, "cpu": cpu, "powers": powers}
    runs["sweep, serial"] = timed_sweep(seas, seeds, duration, dt, 0)
    report = report_path = _report_file(report_to, seas_name, n_cases)
    os.environ["MBCONTROL_SWEEP_CLUSTER"] = cluster
    for start in starts:
        os.environ["MBCONTROL_SWEEP_START"] = start
        runs[f"sweep, 2 workers ({start})"] = timed_sweep(seas, seeds, duration, dt, 2, report)
        report = None
    loop = np.array(runs["plain loop"]["powers"])
    difference = {k: float(np.max(np.abs(np.array(r["powers"]) - loop) / np.abs(loop)))
                  for k, r in runs.items() if k != "plain loop"}
    base, serial = runs["plain loop"], runs["sweep, serial"]
    out = {"model": "rm3", "seas_set": seas_name, "cases": n_cases, "seas": len(seas),
           "seeds": seeds, "duration_s": duration, "dt_s": dt, "cluster": cluster,
           "load_average_1min": [load, os.getloadavg()[0]],
           "wall_time_s": {k: r["wall"] for k, r in runs.items()},
           "cases_time_s": {k: r["cases"] for k, r in runs.items()},
           "cpu_time_s": {k: r["cpu"] for k, r in runs.items()},
           "cases_per_minute": {k: 60 * n_cases / r["wall"] for k, r in runs.items()},
           "ratio_to_loop": {k: base["wall"] / r["wall"] for k, r in runs.items()},
           "cases_ratio_to_loop": {k: base["wall"] / r["cases"] for k, r in runs.items()},
           "speedup_over_serial_sweep": {k: serial["wall"] / r["wall"] for k, r in runs.items()
                                         if "workers" in k},
           "where": {k: r["where"] for k, r in runs.items() if "where" in r},
           "max_relative_power_difference": difference,
           "same_powers": all(d < 1e-9 for d in difference.values())}
    if report_path is not None:
        out["dask_report"] = str(report_path)
    return out


def report(r: dict) -> None:
    print(f"light sweep, rm3 (scene PTO), {r['seas_set']} seas: {r['cases']} cases "
          f"({r['seas']} seas x {r['seeds']} seeds) of {r['duration_s']:g} s at dt "
          f"{r['dt_s']:g} s; cluster {r['cluster']}; load average {r['load_average_1min'][0]:.1f}"
          f" -> {r['load_average_1min'][1]:.1f}")
    print(f"  {'run':30s} {'wall s':>7s} {'cases/min':>9s} {'x loop':>6s} {'cases s':>7s} "
          f"{'x loop':>6s} {'CPU s':>6s}")
    for label, wall in r["wall_time_s"].items():
        ran = f"  ({r['where'][label]})" if label in r["where"] else ""
        print(f"  {label:30s} {wall:7.2f} {r['cases_per_minute'][label]:9.1f} "
              f"{r['ratio_to_loop'][label]:5.2f}x {r['cases_time_s'][label]:7.2f} "
              f"{r['cases_ratio_to_loop'][label]:5.2f}x {r['cpu_time_s'][label]:6.1f}{ran}")
    for label, x in r["speedup_over_serial_sweep"].items():
        print(f"  {label} over the serial sweep: {x:.2f}x")
    print(f"  same mean powers as the loop (1e-9): {r['same_powers']} (largest relative "
          f"difference {max(r['max_relative_power_difference'].values()):.1e})")


def _write(out: Path, results: list) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_light.json").write_text(json.dumps(results, indent=2))
    with (out / "sweep_light.csv").open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["seas", "cases", "run", "wall_time_s", "cases_time_s", "cpu_time_s",
                         "cases_per_minute", "ratio_to_loop", "where"])
        for r in results:
            for label, wall in r["wall_time_s"].items():
                writer.writerow([r["seas_set"], r["cases"], label, f"{wall:.3f}",
                                 f"{r['cases_time_s'][label]:.3f}",
                                 f"{r['cpu_time_s'][label]:.2f}",
                                 f"{r['cases_per_minute'][label]:.1f}",
                                 f"{r['ratio_to_loop'][label]:.3f}",
                                 r["where"].get(label, "")])


def main(argv=None) -> int:
    from mbcontrol import defaults
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--cases", type=int, nargs="+", default=[256, 64],
                        help="case counts, multiples of the seas (256 64)")
    parser.add_argument("--seas", nargs="+", choices=("grid", "pacwave"), default=["grid"],
                        help="sets of seas (grid)")
    parser.add_argument("--duration", type=float, default=3600.0, help="record length, s")
    parser.add_argument("--dt", type=float, default=0.05, help="step, s")
    parser.add_argument("--start", nargs="+", choices=("spawn", "forkserver", "fork"),
                        help="how the 2 workers start, each a run (default: sweep.start, "
                             "and forkserver)")
    parser.add_argument("--cluster", choices=("always", "auto"), default="always",
                        help="sweep.cluster of the 2-worker runs (always)")
    parser.add_argument("--out", help="write sweep_light.json and .csv here (a folder)")
    parser.add_argument("--report", action="store_true",
                        help="and a Dask performance report of the first 2-worker sweep")
    args = parser.parse_args(argv)
    starts = args.start or list(dict.fromkeys([str(defaults.get("sweep.start")), "forkserver"]))
    results = []
    for seas in args.seas:
        for n in args.cases:
            results.append(measure(seas, n, args.duration, args.dt, starts, args.cluster,
                                   args.out if args.report else None))
            report(results[-1])
    if args.out:
        _write(Path(args.out), results)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
