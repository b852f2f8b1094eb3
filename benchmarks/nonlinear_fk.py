"""Speed against accuracy of the nonlinear hydrostatics and Froude-Krylov paths (issue 56).

The case of the issue's goals: the R = 5 m hemisphere in heave (tests/plant/sphere_nonlinear.toml),
a 600 s JONSWAP sea (Hs 2.5 m, Tp 8 s) at dt 0.01 s, RK4; the PTO damper at 1e6 N s/m so the
body moves apart from the wave. For each path and resolution: the wall time of `simulate`
(compiled code ready: its first compile is reported apart), the real-time factor, and the
heave error against a reference run: the panel path at the finest size given (the exact
incident surface, no flat-waterline assumption), its pressure integrated at every RK4 stage.
Each panel size runs both ways ([hydro] nonlinear_update): "stage" (the integral at every
stage) and "step" (once per step, moved to the other stages by its rest increments:
mbcontrol.plant.held_pressure). The linear plant (models/sphere.toml) is the baseline of all:
how much the nonlinear pressure changes the answer, and what it costs. The issue's mesh case
beside them: WEC-Sim's OSWEC flap from its own STL (models/oswec.toml, 1,563 points) in the
same sea on the panel path, both ways (its real-time factor; no reference run).

    python benchmarks/nonlinear_fk.py --out out/bench/nonlinear_fk [--sizes 2 1 0.6 0.5]

Writes nonlinear_fk.json and nonlinear_fk.png (real-time factor against error).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

import numpy as np

from mbcontrol import sim, waves
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mbcontrol.atomic import write_text
from mbcontrol.plant import build_plant
from mbcontrol.plotting import save
from mbcontrol.scene import load_scene

DURATION, DT, DAMPING = 600.0, 0.01, 1.0e6
SCENE = Path(__file__).resolve().parents[1] / "tests" / "plant" / "sphere_nonlinear.toml"
OSWEC = Path(__file__).resolve().parents[1] / "models" / "oswec.toml"


def _timed(plant, sea, repeats: int = 3, params=None,
           output: str = "heave") -> tuple[np.ndarray, float, float]:
    params = plant.params(pto__damping=DAMPING) if params is None else params
    start = time.perf_counter()
    sim.simulate(plant, sea, duration=20.0, dt=DT, params=params)        # compiles
    compile_s = time.perf_counter() - start
    best, ds = np.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        ds = sim.simulate(plant, sea, duration=DURATION, dt=DT, params=params)
        best = min(best, time.perf_counter() - start)
    return ds[output].values, best, compile_s


def run(sizes) -> dict:
    sea = waves.irregular(2.5, 8.0, seed=1, duration=DURATION)
    scene = load_scene(str(SCENE))
    cases = [("linear", build_plant("sphere"), None),
             ("analytic", build_plant(scene), None)]
    for size in sizes:
        # the reference (the finest size) only at every stage
        for update in ("stage", "step") if size != sizes[-1] else ("stage",):
            hydro = dataclasses.replace(scene.hydro, nonlinear_path="panels",
                                        nonlinear_panel_size=size, nonlinear_update=update)
            plant = build_plant(dataclasses.replace(scene, hydro=hydro))
            label = f"panels {plant.pressure[0].model.n} points" + ", per step" * (
                update == "step")
            cases.append((label, plant, size))
    rows = []
    for label, plant, size in cases:
        heave, wall, compile_s = _timed(plant, sea, 3 if size is None or size > 0.9 else 2)
        rows.append({"case": label, "panel_size_m": size, "wall_s": wall,
                     "nonlinear_update": plant.scene.hydro.nonlinear_update,
                     "real_time_factor": DURATION / wall, "first_compile_s": compile_s,
                     "field_rows": plant.wave_rows, "heave": heave})
        print(f"{label:34s} {DURATION / wall:9.0f} x real time  (first run {compile_s:.1f} s)")
    reference = rows[-1]["heave"]
    scale = np.sqrt(np.mean(reference ** 2))
    for row in rows:
        row["heave_rms_error"] = float(np.sqrt(np.mean((row.pop("heave") - reference) ** 2))
                                       / scale)
    return {"case": "sphere_nonlinear, JONSWAP Hs 2.5 m Tp 8 s, 600 s, dt 0.01 s, rk4, "
                    "PTO 1e6 N s/m", "reference": rows[-1]["case"], "rows": rows,
            "mesh": [mesh_case(update) for update in ("stage", "step")]}


def mesh_case(update: str) -> dict:
    """WEC-Sim's OSWEC flap (its STL, 1,563 points) on the panel path in the same sea, cut to
    its data's band: the real-time factor of a CAD mesh, its pressure integrated per `update`."""
    scene = load_scene(str(OSWEC))
    hydro = dataclasses.replace(scene.hydro, hydrostatics="nonlinear", froude_krylov="nonlinear",
                                nonlinear_update=update)
    plant = build_plant(dataclasses.replace(scene, hydro=hydro))
    sea = waves.irregular(2.5, 8.0, seed=1, duration=DURATION, band=(0.4, 3.5))
    _, wall, compile_s = _timed(plant, sea, 1, plant.p0, "hinge")
    field = plant.pressure[0].field
    row = {"case": f"OSWEC flap mesh, {plant.pressure[0].model.n} points"
                   + ", per step" * (update == "step"), "nonlinear_update": update,
           "field_terms": [field.n_xi, field.n_depth], "wall_s": wall,
           "real_time_factor": DURATION / wall, "first_compile_s": compile_s}
    print(f"{row['case']:34s} {DURATION / wall:9.0f} x real time  (first run {compile_s:.1f} s)")
    return row


STYLE = {"stage": ("o", "C0", "pressure at every RK4 stage"),
         "step": ("s", "C3", "pressure once per step (nonlinear_update = \"step\")"),
         None: ("D", "0.3", "linear / analytic")}


def chart(result: dict, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(7.2, 4.8))
    labelled = set()
    for row in result["rows"]:
        if row["case"] == result["reference"]:
            continue                     # its own error is zero: off a log scale
        error = row["heave_rms_error"]
        update = row["nonlinear_update"] if row["panel_size_m"] is not None else None
        marker, colour, what = STYLE[update]
        ax.loglog(row["real_time_factor"], error, marker, color=colour,
                  label=None if update in labelled else what)
        labelled.add(update)
        ax.annotate(row["case"].replace(", per step", ""), (row["real_time_factor"], error),
                    textcoords="offset points", fontsize=7, ha="left" if update == "step"
                    else "center", xytext=(5, -11) if update == "step" else (0, 6))
    ax.set_xlabel("real-time factor (600 s simulated / wall s of the whole simulate call)")
    ax.set_ylabel(f"heave RMS error / RMS\nagainst {result['reference']}")
    for mesh in result.get("mesh") or []:
        _, colour, _ = STYLE[mesh["nonlinear_update"]]
        ax.axvline(mesh["real_time_factor"], color=colour, ls="--", lw=1)
        ax.annotate(f"{mesh['case']}: {mesh['real_time_factor']:.0f}x",
                    (mesh["real_time_factor"], 0.5), xycoords=("data", "axes fraction"),
                    rotation=90, fontsize=7, xytext=(3, 0), textcoords="offset points",
                    va="center", color=colour)
    ax.axvline(100.0, color="0.6", lw=0.8, ls=":")
    ax.annotate("goal at 1,000 panels: 100x", (100.0, 0.6), xycoords=("data", "axes fraction"),
                rotation=90, fontsize=7, xytext=(-9, 0), textcoords="offset points",
                color="0.4")
    ax.legend(fontsize=7, loc="lower right")
    ax.set_title("Nonlinear hydrostatics + Froude-Krylov: speed against accuracy\n"
                 "sphere R = 5 m, 600 s JONSWAP Hs 2.5 m Tp 8 s, dt 0.01 s, RK4", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    save(fig, path)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/bench/nonlinear_fk"))
    parser.add_argument("--sizes", type=float, nargs="+", default=[2.0, 1.0, 0.6, 0.5],
                        help="panel sizes (m); the last is the reference")
    parser.add_argument("--redraw", action="store_true",
                        help="draw the chart again from OUT/nonlinear_fk.json, without running")
    args = parser.parse_args(argv)
    if args.redraw:
        result = json.loads((args.out / "nonlinear_fk.json").read_text())
    else:
        result = run(args.sizes)
        args.out.mkdir(parents=True, exist_ok=True)
        write_text(args.out / "nonlinear_fk.json", json.dumps(result, indent=2))
    chart(result, args.out / "nonlinear_fk.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
