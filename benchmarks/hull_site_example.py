"""Hull size x site: the loop a frequency-domain sweep makes cheap (`make bench`).

Every hull scale s of a device against every site, by Froude similarity of one BEM data set:
a device s times larger (lengths x s, masses and added mass x s^3, frequencies x s^-1/2,
radiation damping and its PTO damping x s^2.5, excitation per unit amplitude x s^2) absorbs
in a sea (Hs, Tp) exactly s^3.5 times what the original absorbs in (Hs / s, Tp / sqrt(s))
(`studies.sweep.froude_seas`; tests/studies/sweep/test_frequency_domain.py checks it to 1e-9
against a device built from scaled BEM data). So each (scale, site) is one frequency-domain
sweep of the original plant over the site's seas mapped to its scale, records of
600 / sqrt(s) s (600 s at full scale). Linear theory, no force or stroke limit: the scene's
damper scaled with the hull, and the complex-conjugate bound beside it.

Sites: PacWave South (32 clustered seas, JONSWAP gamma 3.3, the file's Te / Tp), Humboldt Bay
(the Reference Model Project's 127 Hm0 x Te bins, Pierson-Moskowitz, Tp = Te / 0.857) and
Monterey Bay (NDBC buoy 46042's 1996 hourly spectra binned by Hm0 (0.5 m) x Te (1 s),
gamma 3.3). Writes hull_site.json, hull_site.csv and hull_site.png (annual energy against
hull diameter, one line per site and device) to --out, and prints the table and the time.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import time
from pathlib import Path

import numpy as np

SITES_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sites"
DIAMETER_M = {"sphere": 10.0, "rm3": 20.0}     # the float's diameter at scale 1 (m)


def sites() -> dict:
    """name -> weighted SeaStates of each site file in ../shared/data/sites."""
    from mbcontrol.waves import bin_seas, occurrence, read_ndbc_spectra, read_seas, \
        spectral_hm0_te
    out = {"PacWave South": read_seas(SITES_DIR / "pacwave_cluster_32.csv"),
           "Humboldt Bay": read_seas(SITES_DIR / "humboldt_bay_rmp.csv", 1.0)}
    f, S, _ = read_ndbc_spectra(SITES_DIR / "46042w1996.txt.gz")
    hm0, te = spectral_hm0_te(f, S)
    table = occurrence(hm0, te, np.arange(0.0, 10.5, 0.5), np.arange(2.0, 21.0, 1.0))
    seas = bin_seas(table, 3.3)
    total = sum(s.weight for s in seas)            # records outside the table: left out
    import dataclasses
    out["Monterey Bay (NDBC 46042, 1996)"] = [dataclasses.replace(s, weight=s.weight / total)
                                              for s in seas]
    return out


def hull_scale_energy(plant, seas, scales) -> dict:
    """Annual energy (MWh) per scale of the scene's law scaled with the hull, and of the
    complex-conjugate bound: one frequency-domain sweep of the original plant per scale."""
    from mbcontrol.studies.sweep import froude_seas, sea_powers
    from mbcontrol.studies.sweep.frequency_domain import linear_gains
    from mbcontrol.waves import HOURS_PER_YEAR
    gains = linear_gains(plant, None, {}, None)   # scaled with the hull: the same law here
    weights = np.array([s.weight for s in seas])
    energy, bound, unbounded = [], [], []
    for s in scales:
        out = sea_powers(plant, froude_seas(seas, s), gains, duration=600.0 / math.sqrt(s))
        power = s ** 3.5 * np.nan_to_num(out["power_W"])
        energy.append(float(weights @ power) * HOURS_PER_YEAR / 1e6)
        # a sea exciting the PTO where the data give it no dissipation: an unbounded bound,
        # left out of the chart (NaN) and counted
        b = np.nan_to_num(out["bound_W"], nan=0.0, posinf=np.nan)
        bound.append(float(weights @ (s ** 3.5 * b)) * HOURS_PER_YEAR / 1e6)
        unbounded.append(int(np.sum(np.isinf(out["bound_W"]) & (weights > 0))))
    return {"energy_MWh": energy, "bound_MWh": bound, "unbounded_seas": unbounded}


def chart(results: list, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(DIAMETER_M), figsize=(11, 4.2))
    for ax, model in zip(axes, DIAMETER_M):
        for k, r in enumerate(x for x in results if x["model"] == model):
            d = DIAMETER_M[model] * np.asarray(r["scales"])
            ax.plot(d, r["energy_MWh"], "o-", color=f"C{k}", label=r["site"])
            ax.plot(d, r["bound_MWh"], ":", color=f"C{k}", lw=1)
        ax.set_yscale("log")
        ax.set_xlabel(f"{model} float diameter, m (Froude scale x {DIAMETER_M[model]:g} m)")
        ax.set_ylabel("annual absorbed energy, MWh")
        ax.set_title(f"{model}: scene damper scaled (solid), conjugate bound (dotted)",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/bench/hull_site")
    parser.add_argument("--scales", type=float, nargs="+",
                        default=[0.5, 0.63, 0.79, 1.0, 1.26, 1.59, 2.0])
    args = parser.parse_args(argv)
    from mbcontrol.plant import build_plant
    site_seas = sites()
    results = []
    for model in DIAMETER_M:
        plant = build_plant(model)
        for name, seas in site_seas.items():
            start = time.perf_counter()
            r = hull_scale_energy(plant, seas, args.scales)
            wall = time.perf_counter() - start
            results.append({"model": model, "site": name, "seas": len(seas),
                            "scales": args.scales, **r, "wall_s": wall})
            print(f"{model:6s} {name:32s} {len(seas):3d} seas x {len(args.scales)} scales in "
                  f"{1e3 * wall:.0f} ms")
    print(f"\n{'model':6s} {'site':32s} " + " ".join(f"{s:>8.3g}" for s in args.scales)
          + "   (hull scale; annual energy MWh, scene damper scaled)")
    for r in results:
        print(f"{r['model']:6s} {r['site']:32s} "
              + " ".join(f"{e:8.4g}" for e in r["energy_MWh"]))
        print(f"{'':6s} {'  conjugate bound':32s} "
              + " ".join(f"{b:8.4g}" for b in r["bound_MWh"])
              + (f"   (unbounded seas per scale: {r['unbounded_seas']})"
                 if any(r["unbounded_seas"]) else ""))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "hull_site.json").write_text(json.dumps(results, indent=2))
    with (out / "hull_site.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["model", "site", "scale", "diameter_m", "annual_energy_MWh",
                    "conjugate_bound_MWh"])
        for r in results:
            for s, e, b in zip(r["scales"], r["energy_MWh"], r["bound_MWh"]):
                w.writerow([r["model"], r["site"], s, DIAMETER_M[r["model"]] * s, e, b])
    chart(results, out / "hull_site.png")
    print(f"wrote {out / 'hull_site.json'}, hull_site.csv, hull_site.png")
    return results


if __name__ == "__main__":
    main()
