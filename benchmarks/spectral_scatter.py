"""How much a record's mean power scatters, two ways (`make bench`, issue 35): the spectral
estimate (`mbcontrol.analysis.power_statistics`, from the frequency-domain solution, no
simulation) against the scatter of simulated random-amplitude records (brute force), side by
side in cost and agreement.

The sphere with a passive damper of 400 kN s/m, Hs 2 m, Tp 6, 8, 10 and 12 s, records of
--duration s with Rayleigh amplitudes. For n = 4, 8, 16, ... --seeds records per sea the
seed-based CV (std / mean) and its relative difference from the spectral CV, and the wall time
of each; the spectral estimate's own time. Writes spectral_scatter.json and a chart of the
difference against the cost into --out.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/bench/spectral_scatter")
    parser.add_argument("--seeds", type=int, default=32, help="records per sea at most")
    parser.add_argument("--duration", type=float, default=600.0, help="s per record")
    args = parser.parse_args(argv)
    from mbcontrol.studies.sweep import grid, sweep
    from mbcontrol.studies.sweep.spectral import sea_components, spectral_row
    from mbcontrol import build_plant, load_scene

    seas = grid([2.0], [6.0, 8.0, 10.0, 12.0])
    settings = {"damping": 4e5}
    plant = build_plant(load_scene("sphere"))

    def spectral_cv(sea):
        wave, rms = sea_components(plant, sea, args.duration)
        return spectral_row(plant, wave, rms, {"pto": (4e5, 0.0)}, args.duration, "random", 1,
                            None)["spectral_cv"]
    spectral_cv(seas[0])                         # imports and first calls, untimed
    start = time.perf_counter()
    spectral = [spectral_cv(sea) for sea in seas]
    spectral_s = time.perf_counter() - start
    sweep("sphere", seas[:1], seeds=1, controller="passive", settings=settings,
          duration=args.duration, workers=0, progress=False)          # compile once, untimed
    start = time.perf_counter()
    ds, _ = sweep("sphere", seas, seeds=args.seeds, controller="passive", settings=settings,
                  amplitudes="random", duration=args.duration, workers=0, progress=False)
    per_record = (time.perf_counter() - start) / (len(seas) * args.seeds)
    rows = []
    n = 4
    while n <= args.seeds:
        p = ds["mean_power_W"].isel(seed=slice(0, n)).values
        cv = np.std(p, axis=1, ddof=1) / np.mean(p, axis=1)
        rows.append({"records": n, "wall_s": n * len(seas) * per_record,
                     "cv": cv.tolist(),
                     "rms_relative_difference": float(np.sqrt(np.mean((cv / spectral - 1) ** 2)))})
        n *= 2
    result = {"model": "sphere", "seas": [{"hs": s.hs, "tp": s.tp} for s in seas],
              "duration_s": args.duration, "spectral_cv": spectral, "spectral_wall_s": spectral_s,
              "seeds": rows}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "spectral_scatter.json").write_text(json.dumps(result, indent=1))
    _chart(result, out / "spectral_scatter.png")
    print(f"sphere, passive, Hs 2 m, Tp 6-12 s, {args.duration:g} s records, random amplitudes:")
    print(f"  spectral CV {', '.join(f'{c:.3f}' for c in spectral)} in {spectral_s:.2f} s")
    for r in rows:
        print(f"  {r['records']:3d} records a sea: {r['wall_s']:7.1f} s, RMS difference from "
              f"the spectral CV {100 * r['rms_relative_difference']:.1f} %")
    return result


def _chart(result: dict, path: Path) -> None:
    import matplotlib.pyplot as plt

    from mbcontrol.plotting import save
    fig, ax = plt.subplots(figsize=(5.5, 4))
    rows = result["seeds"]
    ax.semilogx([r["wall_s"] for r in rows],
                [100 * r["rms_relative_difference"] for r in rows], "o-",
                label="seed scatter of simulated records")
    # the sampling error of a std from n records of a gamma law with 1 / cv^2 exponentials
    cv = float(np.mean(result["spectral_cv"]))
    expected = [100 * np.sqrt(1 / (2 * (r["records"] - 1)) + 1.5 * cv ** 2 / r["records"])
                for r in rows]
    ax.semilogx([r["wall_s"] for r in rows], expected, ":", color="0.4",
              label="expected sampling error of n records")
    for r in rows:
        ax.annotate(f"{r['records']} a sea", (r["wall_s"], 100 * r["rms_relative_difference"]),
                    textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.axvline(result["spectral_wall_s"], color="C1", ls="--",
               label=f"spectral estimate ({result['spectral_wall_s']:.2f} s)")
    ax.set_xlabel("wall time for 4 seas, s")
    ax.set_ylabel("CV: RMS difference from the spectral one, %")
    ax.set_title("record-to-record scatter of mean power:\nbrute force against the spectral "
                 "estimate", fontsize=9)
    from matplotlib.ticker import FixedLocator, NullFormatter, ScalarFormatter
    ticks = [result["spectral_wall_s"]] + [r["wall_s"] for r in rows]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_ylim(0, None)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save(fig, path)
    plt.close(fig)


if __name__ == "__main__":
    main()
