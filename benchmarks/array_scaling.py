"""How a farm's cost grows with its size: array_grid with n x n = 4, 9, 16, 25 cylinders (`make bench`).

Per grid, on a cold cache (a fresh folder per grid: nothing reused, as on a user's first run),
measured in one run on this machine, from the scene file to a 60 s simulation:
  - BEM: Capytaine, all floats solved together (80 mm panels, 64 frequencies, 2 headings);
  - fit: the radiation model (the scene's method: column by column, symmetric columns shared,
    passivity enforced; tolerance 2 %), with its error, states and peak memory of the process;
  - build: symbolic assembly of the process plant (CasADi);
  - compile: C code generation and gcc of the RK4 step, and the size of its C (bytes: a
    deterministic proxy of gcc's time; a farm's couplings are data there, module plant.pieces);
  - simulate: 60 s of JONSWAP (Hs 5 cm, Tp 1.1 s, RK4, dt 0.01 s), and the real-time factor.
"total" is scene to simulated record, the sum. The growth exponent of each cost is the slope
of log(cost) against log(number of floats); the ratio of the two largest grids' costs is printed
beside the ratio of their sizes (proportional growth). Writes a CSV, a JSON and a log-log chart.
benchmarks/farm_compile.py measures build and compile alone up to 49 floats, without the BEM.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import resource
import tempfile
import time
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.hydro import fit_hydro_model, fit_method, load_hydro_data
from mbcontrol.hydro.model import fit_band_limit
from mbcontrol.multibody import build_topology
from mbcontrol.plant import active_hydro_dofs, build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate
from mbcontrol.sim.integrators import chunk_length, chunk_symbolic, prepare

from farm_compile import c_bytes, growth

DURATION, DT = 60.0, 0.01


def measure(n_side: int, fit_tol: float) -> dict:
    """Every cost of one grid, in the cache folder in force (the caller makes it fresh)."""
    scene = load_scene("array_grid", {"n": n_side, "fit_tol": fit_tol})
    dofs = active_hydro_dofs(scene, build_topology(scene))
    t0 = time.perf_counter()
    source, data = load_hydro_data(scene, dofs)
    t_bem = time.perf_counter() - t0
    t0 = time.perf_counter()
    hydro = fit_hydro_model(data, dofs, scene.hydro.radiation_tol, source, scene.hydro.fit_omega_max,
                            scene.hydro.response_band, fit_method(scene.hydro.radiation_fit, dofs, data))
    t_fit = time.perf_counter() - t0
    rss_fit = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t0 = time.perf_counter()
    plant = build_plant(scene, hydro)
    t_build = time.perf_counter() - t0
    steps = int(round(DURATION / DT))
    step_c = c_bytes(chunk_symbolic(plant, "rk4", None, chunk_length(steps)))
    t0 = time.perf_counter()
    prepare(plant, steps, "rk4")
    t_compile = time.perf_counter() - t0
    sea = waves.irregular(0.05, 1.1, gamma=3.3, seed=1, duration=DURATION,
                          data_band=(float(data["omega"].min()), float(data["omega"].max())))
    t0 = time.perf_counter()
    out = simulate(plant, sea, duration=DURATION, dt=DT, method="rk4")
    t_sim = time.perf_counter() - t0
    rad = hydro.radiation
    return {"floats": n_side ** 2, "states": plant.nx, "radiation_states": rad.order,
            "fit_error": rad.fit_error, "fit_tol": scene.hydro.radiation_tol,
            "fit_method": hydro.fit_method, "column_classes": rad.report.get("column_classes"),
            "passive": bool(rad.report["passivity"].get("passive")),
            "fit_band_rad_s": fit_band_limit(data, scene.hydro.fit_omega_max),
            "bem_s": t_bem, "fit_s": t_fit, "build_s": t_build, "compile_s": t_compile,
            "step_c_bytes": step_c,
            "simulate_s": t_sim, "total_s": t_bem + t_fit + t_build + t_compile + t_sim,
            "rtf": DURATION / out.attrs["wall_time_s"], "peak_rss_mb": rss_fit,
            "shunt_terms": len(rad.report["passivity"].get("shunt_terms", [])),
            "valid": bool(out.attrs.get("valid", True))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[2, 3, 4, 5],
                    help="floats per side of the grids measured (2 3 4 5: 4, 9, 16, 25 floats)")
    ap.add_argument("--fit-tol", type=float, nargs="+", default=None,
                    help="radiation fit tolerance per grid (default 0.02 each; 25 floats reach "
                         "passivity at 3.4 %%: give 0.06 there)")
    ap.add_argument("--cache", type=Path, default=None,
                    help="reuse this cache folder (warm runs) instead of a fresh one per grid")
    ap.add_argument("--out", type=Path, default=Path("out/bench/array_scaling"), help="output folder")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    print(f"array_grid (heaving cylinders, 1 m apart), cold cache per grid; {DURATION:.0f} s JONSWAP, "
          f"RK4 dt = {DT} s")
    head = (f"{'floats':>6} {'rad. states':>11} {'fit tol':>7} {'fit err':>8} {'BEM (s)':>8} {'fit (s)':>8} {'build (s)':>9} "
            f"{'compile (s)':>11} {'C (kB)':>7} {'sim (s)':>8} {'total (s)':>9} {'RTF':>6} {'peak MB':>8}")
    print(head)
    previous = os.environ.get("MBCONTROL_CACHE")
    tols = args.fit_tol or [0.02] * len(args.n)
    if len(tols) != len(args.n):
        ap.error(f"--fit-tol: {len(tols)} values for {len(args.n)} grids")
    for n, tol in zip(args.n, tols):
        with tempfile.TemporaryDirectory() as fresh:
            os.environ["MBCONTROL_CACHE"] = str(args.cache or fresh)
            try:
                r = measure(n, tol)
            finally:
                if previous is None:
                    os.environ.pop("MBCONTROL_CACHE")
                else:
                    os.environ["MBCONTROL_CACHE"] = previous
        rows.append(r)
        print(f"{r['floats']:6d} {r['radiation_states']:11d} {r['fit_tol']:7.0%} {r['fit_error']:8.2%} {r['bem_s']:8.1f} "
              f"{r['fit_s']:8.1f} {r['build_s']:9.1f} {r['compile_s']:11.1f} {r['step_c_bytes'] / 1e3:7.0f} "
              f"{r['simulate_s']:8.1f} "
              f"{r['total_s']:9.1f} {r['rtf']:6.0f} {r['peak_rss_mb']:8.0f}", flush=True)
    if len(rows) > 1:
        print("growth exponents (cost ~ floats^k): " + ", ".join(
            f"{k.removesuffix('_s')} {growth(rows, k):.2f}" for k in (
                "bem_s", "fit_s", "build_s", "compile_s", "step_c_bytes", "simulate_s", "total_s")))
        a, b = rows[-2], rows[-1]
        print(f"{b['floats']} over {a['floats']} floats (proportional: {b['floats'] / a['floats']:.2f}x): "
              + ", ".join(f"{k.removesuffix('_s')} {b[k] / a[k]:.2f}x"
                          for k in ("build_s", "compile_s", "step_c_bytes")))
        print(f"total of the largest over the smallest grid: {rows[-1]['total_s'] / rows[0]['total_s']:.2f}x")
    with open(args.out / "array_scaling.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (args.out / "array_scaling.json").write_text(json.dumps(rows, indent=2))
    _chart(rows, args.out / "array_scaling.png")
    print(f"wrote {args.out / 'array_scaling.csv'}, .json and .png")
    return 0


def _chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["floats"] for r in rows]
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for key, mark, label in (("bem_s", "o-", "BEM (Capytaine)"), ("fit_s", "s-", "radiation fit"),
                             ("compile_s", "^-", "code generation + gcc"),
                             ("simulate_s", "v-", f"{DURATION:.0f} s simulation"),
                             ("total_s", "k*-", "total: scene to record")):
        ax.loglog(n, [r[key] for r in rows], mark, label=label)
    ax.set_xticks(n, [str(v) for v in n])
    ax.minorticks_off()
    ax.set_xlabel("floats in the grid")
    ax.set_ylabel("wall time (s), cold cache")
    ax.set_title("array_grid: cost against the number of floats")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
