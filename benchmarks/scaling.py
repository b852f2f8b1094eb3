"""How cost grows with the number of bodies: barge_chain with N = 2, 4, 8, 16 (`make bench`).

Per N, in a fresh cache folder (a cold first use: nothing cached; what the catalogue ships,
N = 4's BEM data and fit, is used as a user gets it), in one run on this machine:
  - hydro: BEM data and radiation fit (the barges are solved alone and identical ones share one
    fit, so this grows slowly with N);
  - build: symbolic assembly of the process plant (CasADi), hydro already in memory;
  - compile: C code generation and gcc of the RK4 chunk;
  - first use: all of the above plus the first 600 s run (its output map compiles too);
  - real-time factor of a 600 s JONSWAP run (Hs 3 cm, Tp 1.1 s, dt 0.01 s), best of 3, compiled.
The growth exponent of each column is the slope of log(cost) against log(N) over the N measured.
Writes a CSV and a log-log chart.
"""
from __future__ import annotations

import argparse
import csv
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.hydro import load_hydro_model
from mbcontrol.sim.integrators import prepare
from mbcontrol.plant import active_hydro_dofs, build_plant, device_around
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate
from mbcontrol.multibody import build_topology

DURATION, DT = 600.0, 0.01


def measure(n: int, repeats: int = 3) -> dict:
    previous = os.environ.get("MBCONTROL_CACHE")
    with tempfile.TemporaryDirectory() as fresh:        # a cold first use: nothing cached
        os.environ["MBCONTROL_CACHE"] = fresh
        try:
            return _measure_cold(n, repeats)
        finally:
            if previous is None:
                os.environ.pop("MBCONTROL_CACHE")
            else:
                os.environ["MBCONTROL_CACHE"] = previous


def _measure_cold(n: int, repeats: int) -> dict:
    started = time.perf_counter()
    scene = load_scene("barge_chain", {"N": n})
    t0 = time.perf_counter()
    dofs = active_hydro_dofs(scene, build_topology(scene))
    judged = scene.hydro.fit_judged_by == "response"      # as build_plant fits it
    hydro = load_hydro_model(scene, dofs, device=(
        lambda source, data: device_around(scene, source, data, dofs)) if judged else None)
    t_hydro = time.perf_counter() - t0
    t0 = time.perf_counter()
    plant = build_plant(scene, hydro)
    t_build = time.perf_counter() - t0
    t0 = time.perf_counter()
    prepare(plant, int(round(DURATION / DT)), "rk4")
    t_compile = time.perf_counter() - t0
    sea = waves.irregular(0.03, 1.1, gamma=3.3, seed=1, duration=DURATION)
    walls = [simulate(plant, sea, duration=DURATION, dt=DT).attrs["wall_time_s"]]
    first_use = time.perf_counter() - started
    walls += [simulate(plant, sea, duration=DURATION, dt=DT).attrs["wall_time_s"]
              for _ in range(repeats - 1)]
    shipped = bool(scene.hydro.file) and Path(scene.hydro.file).exists()   # no BEM, no fit
    return {"N": n, "shipped": shipped, "states": plant.nx, "radiation_states": plant.hydro.radiation.order,
            "fit_error": plant.hydro.radiation.fit_error, "hydro_s": t_hydro, "build_s": t_build,
            "compile_s": t_compile, "first_use_s": first_use, "rtf": DURATION / min(walls)}


def growth(rows, key) -> float:
    n = np.array([r["N"] for r in rows], float)
    y = np.array([r[key] for r in rows], float)
    return float(np.polyfit(np.log(n), np.log(y), 1)[0])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[2, 4, 8, 16], help="chain lengths (2 4 8 16)")
    ap.add_argument("--out", type=Path, default=Path("out/bench/scaling"), help="output folder")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    print(f"barge_chain, {DURATION:.0f} s JONSWAP, RK4 dt = {DT} s")
    print(f"{'N':>3} {'states':>7} {'rad.':>5} {'fit err':>8} {'hydro (s)':>10} {'build (s)':>10} "
          f"{'compile (s)':>12} {'first use (s)':>14} {'RTF':>9}")
    for n in args.n:
        r = measure(n)
        rows.append(r)
        print(f"{r['N']:3d} {r['states']:7d} {r['radiation_states']:5d} {r['fit_error']:8.2%} "
              f"{r['hydro_s']:10.2f} {r['build_s']:10.2f} {r['compile_s']:12.2f} "
              f"{r['first_use_s']:14.2f} {r['rtf']:9.0f}", flush=True)
    if len(rows) > 1:
        print("growth exponents (cost ~ N^k): " + ", ".join(
            f"{k} {growth(rows, k):.2f}" for k in ("hydro_s", "build_s", "compile_s", "first_use_s")) +
            f", time per simulated second {-growth(rows, 'rtf'):.2f}")
    with open(args.out / "scaling.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    _chart(rows, args.out / "scaling.png")
    print(f"wrote {args.out / 'scaling.csv'} and {args.out / 'scaling.png'}")
    return 0


def _chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["N"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog(n, [r["build_s"] for r in rows], "o-", label="plant build (s)")
    ax.loglog(n, [r["compile_s"] for r in rows], "s-", label="compile (s)")
    ax.loglog(n, [r["first_use_s"] for r in rows], "D-", label="first use, cold cache (s)")
    for r in rows:
        if r["shipped"]:
            ax.annotate("BEM data and fit shipped", (r["N"], r["first_use_s"]), fontsize=8,
                        xytext=(0, -14), textcoords="offset points", ha="center")
    ax.loglog(n, [DURATION / r["rtf"] for r in rows], "^-", label=f"wall time of {DURATION:.0f} s run (s)")
    ax.set_xticks(n, [str(v) for v in n])      # the chain lengths run, not powers of ten
    ax.minorticks_off()
    ax.set_xlabel("barges N")
    ax.set_ylabel("seconds")
    ax.set_title("barge_chain: cost against chain length")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
