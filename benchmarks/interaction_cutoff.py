"""What an interaction cut-off costs and saves: array_grid solved with every float coupled, and
with each float coupled only to those within R (array_grid's `cutoff` parameter, i.e. `[hydro]
interaction_radius`, module mbcontrol.hydro.bem.neighbours), for several R (`make bench`).

Per R, on a cold cache (a fresh folder each, as on a user's first run), one run on this machine:
  - BEM: wall time, distinct clusters solved and the largest;
  - hydrodynamic error against the full coupled solve (neighbours.cut_error): relative RMS of
    A(ω), B(ω), K(jω) = B + jω(A - A∞) and the excitation; whether the cut B(ω) is still
    positive semi-definite (least eigenvalue over the largest);
  - farm power error: the mean power of the passive farm in JONSWAP seas solved in the frequency
    domain from the BEM data alone (no radiation fit, no time stepping: the cut's own error),
    P = Σ_k 2 S(ω_k) Δω_k · ½ c ω_k² Σ_i |X_i(ω_k)|², and its q-factor against one float alone.
Writes a CSV, a JSON and a chart (errors and BEM time against R).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from mbcontrol.hydro import load_hydro_data, matrix
from mbcontrol.hydro.bem.neighbours import cut_error
from mbcontrol.scene import load_scene
from mbcontrol.waves.spectra import jonswap_spectrum

SEAS = ((0.04, 1.0), (0.06, 1.4), (0.08, 2.0))     # (Hs m, Tp s) at tank scale


def scene_with_radius(n: int, radius: float | None):
    """array_grid with n x n floats 1 m apart, coupled within radius (m; None: all coupled)."""
    return load_scene("array_grid", {"n": n, "cutoff": float("inf") if radius is None else radius})


def farm_power(scene, data) -> np.ndarray:
    """Mean power (W) of the passive farm in each of SEAS, heading 0, from the BEM data alone."""
    dofs = [f"{b.name}__Heave" for b in scene.bodies]
    w = data["omega"].values
    A, B = matrix(data["added_mass"], dofs), matrix(data["radiation_damping"], dofs)
    K = matrix(data["hydrostatic_stiffness"], dofs)
    F = data["excitation_force"].sel(wave_direction=0.0, influenced_dof=dofs).values
    M, c, eye = np.diag([b.mass for b in scene.bodies]), scene.ptos[0].damping, np.eye(len(dofs))
    per_amp2 = np.array([np.sum(0.5 * c * wk**2 * np.abs(np.linalg.solve(
        -wk**2 * (M + A[k]) - 1j * wk * (B[k] + c * eye) + K, F[k])) ** 2) for k, wk in enumerate(w)])
    dw = np.gradient(w)
    return np.array([np.sum(2 * jonswap_spectrum(w, hs, tp) * dw * per_amp2) for hs, tp in SEAS])


def measure(n: int, radius: float | None, full) -> dict:
    scene = scene_with_radius(n, radius)
    dofs = [f"{b.name}__Heave" for b in scene.bodies]
    t0 = time.perf_counter()
    _, data = load_hydro_data(scene, dofs)
    t_bem = time.perf_counter() - t0
    row = {"radius_m": radius if radius is not None else float("inf"), "bem_s": t_bem,
           "clusters": int(data.attrs.get("distinct_clusters", 1)),
           "largest_cluster": int(data.attrs.get("largest_cluster", len(dofs))),
           "power_W": farm_power(scene, data).tolist(), "data": data}
    B = matrix(data["radiation_damping"], dofs)
    ev = np.linalg.eigvalsh(0.5 * (B + np.swapaxes(B, 1, 2)))
    row["min_damping_eig"] = float(ev[:, 0].min() / ev[:, -1].max())   # over all ω: B(0) is ~0
    if full is not None:
        row.update(cut_error(full, data, dofs))
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=4, help="floats per side (4: 16 floats, 1 m apart)")
    ap.add_argument("--radius", type=float, nargs="+", default=[1.0, 1.5, 2.3],
                    help="interaction radii to measure, m (1.0: the 4 nearest; 1.5: and the diagonals)")
    ap.add_argument("--out", type=Path, default=Path("out/bench/interaction_cutoff"), help="output folder")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    previous = os.environ.get("MBCONTROL_CACHE")
    rows, full, alone = [], None, None
    print(f"array_grid {args.n} x {args.n}, cold cache per run; farm power from the BEM data "
          f"(frequency domain) in {len(SEAS)} JONSWAP seas, heading 0")
    print(f"{'R (m)':>6} {'clusters':>8} {'largest':>7} {'BEM (s)':>8} {'A err':>7} {'B err':>7} {'K err':>7} "
          f"{'exc err':>7} {'B min eig':>9} {'power err (per sea)':>22} {'q (per sea)':>20}")
    for radius in [None, *args.radius, "alone"]:
        with tempfile.TemporaryDirectory() as fresh:
            os.environ["MBCONTROL_CACHE"] = fresh
            try:
                if radius == "alone":
                    one = load_scene("array_grid", {"n": 1})
                    alone = farm_power(one, load_hydro_data(one, ["float1__Heave"])[1]) * args.n ** 2
                    continue
                row = measure(args.n, radius, full)
            finally:
                if previous is None:
                    os.environ.pop("MBCONTROL_CACHE")
                else:
                    os.environ["MBCONTROL_CACHE"] = previous
        if full is None:
            full, reference = row["data"], np.array(row["power_W"])
        row["power_error"] = (np.array(row["power_W"]) / reference - 1).tolist()
        rows.append(row)
    for row in rows:
        row.pop("data")
        row["q"] = (np.array(row["power_W"]) / alone).tolist()
        err = lambda k: f"{row[k]:7.1%}" if k in row else f"{'-':>7}"   # noqa: E731
        print(f"{row['radius_m']:6.2f} {row['clusters']:8d} {row['largest_cluster']:7d} {row['bem_s']:8.1f} "
              f"{err('added_mass')} {err('radiation_damping')} {err('kernel')} {err('excitation')} "
              f"{row['min_damping_eig']:9.3f} {' '.join(f'{e:+6.1%}' for e in row['power_error']):>22} "
              f"{' '.join(f'{q:6.3f}' for q in row['q']):>20}", flush=True)
    (args.out / "interaction_cutoff.json").write_text(json.dumps(
        {"n": args.n, "seas": SEAS, "rows": rows}, indent=1, default=float))
    with open(args.out / "interaction_cutoff.csv", "w", newline="") as f:
        keys = [k for k in rows[-1] if not isinstance(rows[-1][k], list)]
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    chart(rows, args.out / "interaction_cutoff.png", args.n)
    print(f"wrote {args.out}/interaction_cutoff.csv, .json and .png")
    return 0


def chart(rows, path: Path, n: int) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cut = [r for r in rows if np.isfinite(r["radius_m"])]
    R = [r["radius_m"] for r in cut]
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    for key, label in (("kernel", "radiation kernel K(jω)"), ("excitation", "excitation force")):
        a.plot(R, [100 * r[key] for r in cut], "o-", label=label)
    for s in range(len(SEAS)):
        a.plot(R, [100 * abs(r["power_error"][s]) for r in cut], "s--",
               label=f"farm power, Hs {SEAS[s][0]} m, Tp {SEAS[s][1]} s")
    a.set_xlabel("interaction radius R (m; floats 1 m apart)")
    a.set_ylabel("error against the full coupled solve (%)")
    a.set_title(f"{n} x {n} floats: what the cut leaves out")
    a.legend(fontsize=8)
    a.grid(alpha=0.3)
    b.bar([f"{r['radius_m']:g}" if np.isfinite(r["radius_m"]) else "all" for r in rows],
          [r["bem_s"] for r in rows])
    b.set_xlabel("interaction radius R (m)")
    b.set_ylabel("BEM wall time, cold (s)")
    b.set_title("cost")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
