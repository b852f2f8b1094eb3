"""What per-sea design costs (`make bench`, issue 34): rm3 over PacWave's 32 weighted seas
(../shared/data/sites/pacwave_cluster_32.csv), reactive control, serial, in one run:

- plain: `sweep(..., controller="reactive", settings=...)` with one setting for every sea (the
  law `design` tunes for the site's most energetic sea);
- designed: `sweep(..., design=True)`: the law tuned for each sea inside the envelope, and
  each sea's bound inside it.

Both start from a warm compile cache for the plant; the designed sweep compiles each sea's
closed loop anew (a new gain is a new structure today: issue 34, Deliver 4, not built), which
is part of its cost. Prints and writes sweep_design.json into --out: wall times, their ratio,
annual energies, valid cases, and the designed sweep's least and largest share of the bound.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

SEAS = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sites" / \
    "pacwave_cluster_32.csv"


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/bench/sweep_design")
    parser.add_argument("--seas", default=str(SEAS), help="a weighted seas CSV")
    parser.add_argument("--duration", type=float, default=600.0, help="s per case")
    args = parser.parse_args(argv)
    from mbcontrol import build_plant, load_scene, waves
    from mbcontrol.studies.design import design_for_sea
    from mbcontrol.studies.sweep import read_seas, sweep

    seas = read_seas(args.seas)
    plant = build_plant(load_scene("rm3"))
    omega = plant.hydro.omega
    top = max(seas, key=lambda s: s.weight * s.hs ** 2 * s.tp)     # the most energy a year
    wave = waves.irregular(top.hs, top.tp, duration=args.duration,
                           data_band=(float(omega[0]), float(omega[-1])))
    one = {k: v for k, v in design_for_sea(plant, wave, "reactive")["settings"].items()
           if k in ("damping", "stiffness")}
    common = dict(controller="reactive", duration=args.duration, workers=0, progress=False)
    start = time.perf_counter()
    _, plain = sweep("rm3", seas, settings=one, **common)
    plain_s = time.perf_counter() - start
    start = time.perf_counter()
    _, designed = sweep("rm3", seas, design=True, **common)
    designed_s = time.perf_counter() - start
    shares = [r["percent_of_bound"] for r in designed["seas"] if r["percent_of_bound"]]
    result = {"model": "rm3", "seas": len(seas), "duration_s": args.duration,
              "one_setting": one, "one_setting_sea": {"hs": top.hs, "tp": top.tp},
              "plain_wall_s": plain_s, "designed_wall_s": designed_s,
              "ratio": designed_s / plain_s,
              "plain_annual_energy_MWh": plain["annual_energy_MWh"],
              "plain_valid_cases": plain["valid_cases"],
              "plain_coverage": plain["annual_energy_coverage"],
              "designed_annual_energy_MWh": designed["annual_energy_MWh"],
              "designed_valid_cases": designed["valid_cases"],
              "designed_coverage": designed["annual_energy_coverage"],
              "percent_of_bound_min": min(shares), "percent_of_bound_max": max(shares)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep_design.json").write_text(json.dumps(result, indent=1))
    print(f"rm3, {len(seas)} seas x {args.duration:g} s, reactive, serial:")
    print(f"  one setting for every sea: {plain_s:7.1f} s, {plain['annual_energy_MWh']:.4g} MWh "
          f"({plain['valid_cases']} valid, coverage {plain['annual_energy_coverage']:.3f})")
    print(f"  designed per sea:          {designed_s:7.1f} s, "
          f"{designed['annual_energy_MWh']:.4g} MWh ({designed['valid_cases']} valid, coverage "
          f"{designed['annual_energy_coverage']:.3f}); {min(shares):.0f}-{max(shares):.0f} % "
          f"of each sea's bound")
    print(f"  cost of designing: x{result['ratio']:.2f}")
    return result


if __name__ == "__main__":
    main()
