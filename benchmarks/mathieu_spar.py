"""Parametric roll of a spar: the stability diagram over wave period x height, nonlinear
hydrostatics and Froude-Krylov forces beside the linear model (issue 56, item 5).

    python benchmarks/mathieu_spar.py --out out/bench/mathieu

The spar (tests/plant/spar_mathieu.toml) heaves in head seas, its roll offset 0.02 rad at the
start; each cell is the largest |roll| over the last 50 s of 300 s over that offset (above 1:
roll grew). Writes mathieu_spar.nc and mathieu_spar.png.
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import xarray as xr

from mbcontrol.plant import Fidelity, build_plant, plant_for
from mbcontrol.studies import natural_period, plot_stability_maps, stability_map

SCENE = str(Path(__file__).resolve().parents[1] / "tests" / "plant" / "spar_mathieu.toml")
ROLL = "float__Roll"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("out/bench/mathieu"))
    args = parser.parse_args(argv)
    periods, heights = np.arange(5.0, 10.51, 0.5), np.array([0.1, 0.25, 0.5, 1.0, 1.5, 2.0])
    nonlinear = build_plant(SCENE)
    lti = plant_for(SCENE, Fidelity(pressure="linear", kinematics="linear"))
    start = time.perf_counter()
    maps = {"nonlinear hydrostatics + Froude-Krylov": stability_map(nonlinear, ROLL, periods,
                                                                    heights),
            "linear model": stability_map(lti, ROLL, periods, heights)}
    print(f"{2 * periods.size * heights.size} runs of 300 s in {time.perf_counter() - start:.0f} s")
    for label, growth in maps.items():
        print(label)
        for height, row in zip(heights, growth.values):
            print(f"  H {height:4.2f} m " + " ".join(f"{v:6.1f}" for v in row))
    args.out.mkdir(parents=True, exist_ok=True)
    xr.Dataset({("nonlinear" if "nonlinear" in k else "linear"): v.drop_attrs()
                for k, v in maps.items()}).to_netcdf(args.out / "mathieu_spar.nc")
    plot_stability_maps(maps, args.out / "mathieu_spar.png", natural_period=natural_period(lti, ROLL))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
