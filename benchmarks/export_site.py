"""The exported MPC (C, with its iteration cap and fallback) against its Python twin across a
site's seas and more than one device: one closed loop per sea, 300 s at dt 0.05 s, the MPC's
horizon one peak period in 0.2 s steps, without the envelope (which the C engine does not
hold). Prints the largest force difference relative to the run's peak force, per sea: above
the export's bar (1e-6) would mean the cap or the fallback changed a command.

    python benchmarks/export_site.py [--models sphere rm3] [--every 4]
"""
from __future__ import annotations

import argparse
import csv
import tempfile
import warnings
from pathlib import Path

SITE = Path(__file__).resolve().parents[2] / "shared" / "data" / "sites" / "pacwave_cluster_32.csv"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--models", nargs="+", default=["sphere", "rm3"])
    parser.add_argument("--every", type=int, default=4, help="every k-th sea of the site")
    parser.add_argument("--site", default=str(SITE), help="seas file (Hm0, Tp columns)")
    args = parser.parse_args(argv)
    from mbcontrol.controllers import make
    from mbcontrol.export import CController, export_controller, force_error
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    from mbcontrol.waves import irregular
    warnings.simplefilter("ignore")
    with open(args.site, newline="") as f:
        seas = list(csv.DictReader(f))[::args.every]
    worst = 0.0
    for model in args.models:
        plant = build_plant(model)
        om = plant.hydro.omega
        for row in seas:
            hs, tp = float(row["Hm0"]), float(row["Tp"])
            wave = irregular(hs, tp, seed=0, duration=300.0, data_band=(float(om[0]), float(om[-1])))
            controller = make("mpc", horizon_s=tp, dt_s=0.2, wave=wave, envelope=False)
            with tempfile.TemporaryDirectory() as tmp:
                exported = export_controller(controller, plant, tmp)
                runs = [simulate(plant, wave, duration=300.0, dt=0.05, method="rk4", controller=c)
                        for c in (controller, CController.from_export(exported, period=0.2))]
            error = max(force_error(runs[0][k].values, runs[1][k].values)
                        for k in runs[0].data_vars if k.startswith("u__"))
            worst = max(worst, error)
            print(f"{model:8s} Hs {hs:5.2f} m  Tp {tp:5.1f} s  C vs Python force {error:.1e}",
                  flush=True)
    print(f"largest: {worst:.1e} (the export's bar: 1e-6)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
