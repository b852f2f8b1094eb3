"""A site in milliseconds: the frequency-domain sweep (`mbcontrol sweep MODEL --seas SITE.csv
--domain frequency`, `mbcontrol.studies.sweep.frequency_sweep`) timed on 210 seas after the
plant is built (`make bench`).

For sphere and rm3 with the scene's PTO damper: 210 seas two ways, PacWave South's 32-sea
cluster file repeated (its own Te / Tp per sea) and a 15 x 14 Hs x Tp grid (Hs 0.5-7.5 m, Tp
4-17 s); each timed --repeats times after one untimed warm-up call (the median, min and max
printed; the first, cold call too: it fills waves' Te / Tp -> gamma cache and the plant's
first-call Jacobian), split into its stages, and against the same seas one at a time through
the per-sea path (`spectral.expected_power` and `analysis.multiport_bound` on each sea's
wave), as a ratio within the run. The published figure beside it: 210 seas in 39 ms by a
published frequency-domain design tool, other hardware. Writes frequency_sweep.json to --out.
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

PUBLISHED_MS = 39.0       # 210 seas, published, other hardware
SITE = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "sites" / \
    "pacwave_cluster_32.csv"


def site_seas(n: int = 210) -> dict:
    """{"pacwave x7": the cluster file repeated to n seas, "grid 15x14": Hs x Tp}."""
    from mbcontrol.waves import grid, read_seas
    cluster = read_seas(SITE)
    repeated = (cluster * (n // len(cluster) + 1))[:n]
    return {"pacwave_repeated": repeated,
            "grid_15x14": grid(np.linspace(0.5, 7.5, 15), np.linspace(4.0, 17.0, 14))}


def stages(plant, seas, gains) -> dict:
    """One call split into its stages (s): the sea matrix, the device's responses, the
    products, the energy flux."""
    from mbcontrol.studies.sweep.frequency_domain import (device_responses, sea_energy_fluxes,
                                                          sea_variances)
    t0 = time.perf_counter()
    omega, A2, _ = sea_variances(seas, 2 * np.pi / 600.0, (float(plant.hydro.omega[0]),
                                                           float(plant.hydro.omega[-1])))
    t1 = time.perf_counter()
    p, b = device_responses(plant, omega, gains)
    t2 = time.perf_counter()
    A2 @ p, A2 @ np.where(np.isfinite(b), b, 0.0)
    t3 = time.perf_counter()
    water = plant.scene.water
    sea_energy_fluxes(seas, water.depth, water.rho, water.g)
    t4 = time.perf_counter()
    return {"sea_matrix_s": t1 - t0, "responses_s": t2 - t1, "products_s": t3 - t2,
            "energy_flux_s": t4 - t3, "components": int(omega.size)}


def per_sea_path(plant, seas, gains) -> float:
    """The same seas one at a time (s): each sea's wave, expected power and bound."""
    from mbcontrol.analysis import multiport_bound
    from mbcontrol.studies.sweep.runner import sea_wave
    from mbcontrol.studies.sweep.spectral import expected_power
    start = time.perf_counter()
    for sea in seas:
        wave = sea_wave(plant, sea, 600.0)
        expected_power(plant, wave, gains)
        multiport_bound(plant, wave)
    return time.perf_counter() - start


def measure(model: str, seas, repeats: int, per_sea: int) -> dict:
    from mbcontrol.plant import build_plant
    from mbcontrol.studies.sweep import frequency_sweep
    from mbcontrol.studies.sweep.frequency_domain import linear_gains
    plant = build_plant(model)
    first = frequency_sweep(model, seas, plant=plant)[1]["compute_time_s"]
    times = [frequency_sweep(model, seas, plant=plant)[1]["compute_time_s"]
             for _ in range(repeats)]
    gains = linear_gains(plant, None, {}, None)
    split = stages(plant, seas, gains)
    loop = per_sea_path(plant, seas[:per_sea], gains) * len(seas) / per_sea
    median = statistics.median(times)
    return {"model": model, "seas": len(seas), "first_call_s": first, "median_s": median,
            "min_s": min(times), "max_s": max(times), "repeats": repeats,
            "seas_per_s": len(seas) / median, "stages": split,
            "per_sea_path_s": loop, "per_sea_over_vectorised": loop / median,
            "published_ms_210_seas": PUBLISHED_MS}


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/bench/frequency_sweep")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--per-sea", type=int, default=30,
                        help="seas timed through the per-sea path (scaled to all)")
    args = parser.parse_args(argv)
    results = []
    for model in ("sphere", "rm3"):
        for name, seas in site_seas().items():
            r = {**measure(model, seas, args.repeats, args.per_sea), "site": name}
            results.append(r)
            s = r["stages"]
            print(f"{model:6s} {name:17s} {r['seas']} seas: median {1e3 * r['median_s']:.1f} ms "
                  f"(min {1e3 * r['min_s']:.1f}, max {1e3 * r['max_s']:.1f}, {r['repeats']} "
                  f"runs; first call {1e3 * r['first_call_s']:.0f} ms), "
                  f"{r['seas_per_s']:,.0f} seas/s; published, other hardware: 210 seas in "
                  f"{PUBLISHED_MS:g} ms ({210 / PUBLISHED_MS * 1e3:,.0f} seas/s)")
            print(f"       stages: sea matrix {1e3 * s['sea_matrix_s']:.1f} ms "
                  f"({s['components']} frequencies), responses {1e3 * s['responses_s']:.1f} ms, "
                  f"products {1e3 * s['products_s']:.2f} ms, energy flux "
                  f"{1e3 * s['energy_flux_s']:.1f} ms; per-sea path "
                  f"{r['per_sea_path_s']:.2f} s ({r['per_sea_over_vectorised']:.0f}x slower)")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "frequency_sweep.json").write_text(json.dumps(results, indent=2))
    print(f"wrote {out / 'frequency_sweep.json'}")
    return results


if __name__ == "__main__":
    main()
