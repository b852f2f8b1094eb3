"""RM3 on MoorDyn lines: speed against tension error, by line segments and MoorDyn time step.

The issue-57 case: models/rm3_moored (RM3 in surge, heave and pitch on WEC-Sim's three-line
RM3 mooring, each line 240 m of chain to a subsurface buoy and 40 m on to the spar), a 600 s
JONSWAP sea (Hs 2.5 m, Tp 8 s) at dt 0.01 s, RK4, MoorDyn stepped beside the plant. Each row
scales the segments of the lower (240 m) and upper (40 m) lines and MoorDyn's own step dtM:
the wall time of the whole `simulate` call (its code compiled and its lines' settled state
cached by a first short run), the real-time factor, and the tension error against the finest
row (twice WEC-Sim's segments, a quarter of its dtM): the upper lines' fairlead tension (RMS of
the difference over the mean tension, and the error of the record's maximum), the lower
lines' anchor tension likewise. For comparison: a recent C++ WEC code reports 14.9x real time
for a WEC on MoorDyn lines; WEC-Sim's coupling runs MoorDyn in MATLAB's loop.

    python benchmarks/moordyn_rm3.py --out out/bench/moordyn_rm3 [--duration 600]

Writes moordyn_rm3.json and moordyn_rm3.png (real-time factor and tension error against the
segments per line).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import re
import tempfile
import time
from pathlib import Path

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from mbcontrol import sim, waves
from mbcontrol.atomic import write_text
from mbcontrol.plant import build_plant
from mbcontrol.plotting import save
from mbcontrol.scene import load_scene

DT = 0.01
LINES = Path(__file__).resolve().parents[1] / "models" / "rm3_moored_lines.txt"
# (lower, upper segments, dtM s): the finest first (the reference), then WEC-Sim's 15/5 at its
# dtM 5e-4 and coarser (models/rm3_moored_lines.txt: 15/5 at 2e-3)
ROWS = [(30, 10, 2.5e-4), (15, 5, 5e-4), (15, 5, 1e-3), (15, 5, 2e-3), (10, 4, 2e-3),
        (6, 2, 2e-3), (6, 2, 4e-3)]


def variant(folder: Path, lower: int, upper: int, dtm: float):
    """rm3_moored with its lines file's segments and dtM replaced."""
    text = LINES.read_text()
    for old, new in (("240.0     15", f"240.0     {lower}"), ("40.0      5", f"40.0      {upper}")):
        assert old in text, old
        text = text.replace(old, new)
    text, found = re.subn(r"(?m)^[0-9.eE+-]+(\s+dtM\b)", f"{dtm!r}\\1", text)
    assert found == 1, "the lines file's dtM option"
    path = folder / f"lines_{lower}_{upper}_{dtm:g}.txt"
    path.write_text(text)
    scene = load_scene("rm3_moored")
    mooring = dataclasses.replace(scene.moorings[0], file=str(path))
    return build_plant(dataclasses.replace(scene, moorings=(mooring,)))


def run(duration: float) -> dict:
    sea = waves.irregular(2.5, 8.0, seed=1, duration=duration)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for lower, upper, dtm in ROWS:
            plant = variant(Path(folder), lower, upper, dtm)
            sim.simulate(plant, sea, duration=1.0, dt=DT)        # compiles, settles (cached)
            start = time.perf_counter()
            ds = sim.simulate(plant, sea, duration=duration, dt=DT)
            wall = time.perf_counter() - start
            rows.append({"lower_segments": lower, "upper_segments": upper, "dtM_s": dtm,
                         "wall_s": wall, "real_time_factor": duration / wall,
                         "upper": ds["lines__line4__fairlead_tension"].values,
                         "lower": ds["lines__line1__anchor_tension"].values})
            print(f"segments {lower:2d}/{upper:2d}, dtM {dtm:g} s: {duration / wall:6.1f} x real "
                  f"time", flush=True)
    references = {key: rows[0][key] for key in ("upper", "lower")}
    for row in rows:
        for key, ref in references.items():
            x = row.pop(key)
            row[f"{key}_rms_error"] = float(np.sqrt(np.mean((x - ref) ** 2)) / np.mean(ref))
            row[f"{key}_max_error"] = float(abs(x.max() - ref.max()) / ref.max())
    return {"case": f"rm3_moored, JONSWAP Hs 2.5 m Tp 8 s, {duration:g} s, dt {DT} s, rk4",
            "reference": "segments 30/10, dtM 2.5e-4 s", "rows": rows}


def chart(result: dict, path: Path) -> None:
    fig, (speed, error) = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained")
    kinds = (("upper_rms_error", "o", "C0", "upper line, fairlead: RMS"),
             ("upper_max_error", "^", "C1", "upper line, fairlead: record max"),
             ("lower_rms_error", "s", "C2", "lower line, anchor: RMS"))
    for i, row in enumerate(result["rows"]):
        segments = row["lower_segments"] + row["upper_segments"]
        label = f"{row['lower_segments']}/{row['upper_segments']}, dtM {row['dtM_s']:g} s"
        speed.semilogy(segments, row["real_time_factor"], "o", color=f"C{i}")
        speed.annotate(label, (segments, row["real_time_factor"]), fontsize=7,
                       textcoords="offset points", xytext=(5, -3 if i % 2 else 4))
        if i == 0:                               # the reference: no error of its own
            continue
        for key, marker, colour, what in kinds:
            error.semilogy(segments + 0.25 * (i % 3), 100 * max(row[key], 1e-4), marker,
                           color=colour, label=what if i == 1 else None)
    speed.axhline(100.0, color="0.5", ls="--", lw=1)
    speed.annotate("goal 100x", (0.75, 100.0), xycoords=("axes fraction", "data"), fontsize=7,
                   xytext=(0, 3), textcoords="offset points")
    speed.axhline(14.9, color="0.7", ls=":", lw=1)
    speed.annotate("a C++ WEC code on MoorDyn: 14.9x", (0.45, 14.9),
                   xycoords=("axes fraction", "data"), fontsize=7, xytext=(0, 3),
                   textcoords="offset points")
    speed.set_xlim(right=max(r["lower_segments"] + r["upper_segments"]
                             for r in result["rows"]) + 12)
    for ax in (speed, error):
        ax.set_xlabel("segments per line (lower 240 m + upper 40 m)")
        ax.grid(True, which="both", alpha=0.3)
    speed.set_ylabel("real-time factor (simulated s / wall s)")
    error.set_ylabel("tension error, % of the mean tension")
    error.set_title(f"against {result['reference']}", fontsize=9)
    error.legend(fontsize=7)
    fig.suptitle("RM3 on MoorDyn: speed and tension error against line segments; "
                 f"{result['case']}", fontsize=10)
    save(fig, path)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/bench/moordyn_rm3"))
    parser.add_argument("--duration", type=float, default=600.0, help="s simulated per row")
    parser.add_argument("--redraw", action="store_true",
                        help="draw the chart again from OUT/moordyn_rm3.json, without running")
    args = parser.parse_args(argv)
    if args.redraw:
        result = json.loads((args.out / "moordyn_rm3.json").read_text())
    else:
        result = run(args.duration)
        args.out.mkdir(parents=True, exist_ok=True)
        write_text(args.out / "moordyn_rm3.json", json.dumps(result, indent=2))
    chart(result, args.out / "moordyn_rm3.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
