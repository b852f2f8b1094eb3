"""The exported MPC (C, with its iteration cap and fallback) against its Python twin across a
site's seas and more than one device: one closed loop per sea, 300 s at dt 0.05 s, the MPC's
horizon one peak period in 0.2 s steps, with the settings `mbcontrol export` exports it with
(`Mpc.export_settings`: no envelope, which the C engine does not hold, and the force held over
16 blocks of the horizon). Prints per sea the largest force difference relative to the run's
peak force (above the export's bar, 1e-6, the cap or the fallback changed a command) and the
blocked law's mean absorbed power against the same MPC without blocking (the cost of the move
blocking, sea by sea), with each run's physics verdict.

    python benchmarks/export_site.py [--models sphere rm3] [--every 4]
"""
from __future__ import annotations

import argparse
import csv
import tempfile
import warnings
from pathlib import Path

import numpy as np

SITE = Path(__file__).resolve().parents[2] / "shared" / "data" / "sites" / "pacwave_cluster_32.csv"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--models", nargs="+", default=["sphere", "rm3"])
    parser.add_argument("--every", type=int, default=4, help="every k-th sea of the site")
    parser.add_argument("--site", default=str(SITE), help="seas file (Hm0, Tp columns)")
    args = parser.parse_args(argv)
    from mbcontrol.analysis import summary
    from mbcontrol.controllers import REGISTRY, make
    from mbcontrol.export import CController, export_controller, force_error
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    from mbcontrol.waves import irregular
    warnings.simplefilter("ignore")
    with open(args.site, newline="") as f:
        seas = list(csv.DictReader(f))[::args.every]
    worst, costs = 0.0, []
    for model in args.models:
        plant = build_plant(model)
        om = plant.hydro.omega
        for row in seas:
            hs, tp = float(row["Hm0"]), float(row["Tp"])
            wave = irregular(hs, tp, seed=0, duration=300.0, data_band=(float(om[0]), float(om[-1])))
            exported_settings = dict(REGISTRY["mpc"].export_settings)
            controller = make("mpc", horizon_s=tp, dt_s=0.2, wave=wave, **exported_settings)
            unblocked = make("mpc", horizon_s=tp, dt_s=0.2, wave=wave,
                             **{**exported_settings, "blocks": None})
            with tempfile.TemporaryDirectory() as tmp:
                exported = export_controller(controller, plant, tmp)
                runs = [simulate(plant, wave, duration=300.0, dt=0.05, method="rk4", controller=c)
                        for c in (controller, CController.from_export(exported, period=0.2),
                                  unblocked)]
            error = max(force_error(runs[0][k].values, runs[1][k].values)
                        for k in runs[0].data_vars if k.startswith("u__"))
            worst = max(worst, error)
            blocked, free = (summary(ds, plant) for ds in (runs[0], runs[2]))
            power = [sum(p["mean_power_W"] for p in r["ptos"].values()) for r in (blocked, free)]
            cost = power[0] / power[1] - 1
            costs.append(cost)
            print(f"{model:8s} Hs {hs:5.2f} m  Tp {tp:5.1f} s  C vs Python force {error:.1e}  "
                  f"power {power[0] / 1e3:8.1f} kW, {cost:+.2%} against no "
                  f"blocking ({'valid' if blocked['valid'] else 'INVALID'}, "
                  f"{'valid' if free['valid'] else 'INVALID'})", flush=True)
            for reason in blocked["invalid_reasons"]:
                print(f"    invalid: {reason[:110]}")
    print(f"largest: {worst:.1e} (the export's bar: 1e-6); blocking's power cost: median "
          f"{np.median(costs):+.2%}, range {min(costs):+.2%} to {max(costs):+.2%}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
