"""Radiation-model identification: accuracy, passivity and size against WEC-Sim's method.

For one hydrodynamic dataset and DOF set (default: the hinged barge's 6 DOFs, barge1/2 Surge,
Heave, Pitch, fitted up to the mesh limit omega_max_mesh) this sweeps the tolerance of
mbcontrol's coupled fit and records, per tolerance,
  - the unconstrained fit (vector fitting + balanced truncation, passive=False) and
  - the passivity-enforced fit (passive=True, the default),
and once the WEC-Sim baseline (per-entry Hankel/Kung realisation, R² >= 0.95, order <= 10,
block-diagonal assembly). For each: states, the global RMS error on K(jω) = B + jω(A - A∞) over
the band (all entries, same measure for all), mbcontrol's own error (the larger of that and the
worst per-frequency error in --response-band, which decides its order), the passivity margin min eig ½(K + Kᴴ) / max eig from the
exact test (negative = not passive), and the fit time.

Output: <out>/radiation_fit.csv and radiation_fit.png (error and margin against states), and
the table on stdout. Files: .nc (mbcontrol/Capytaine, read_netcdf) or anything
mbcontrol.hydro.readers reads (.out WAMIT, .h5 BEMIO); reader output is mapped to NED body
frames at the file's CoGs (or reference points) with readers.to_scene_frames.

Example: python benchmarks/radiation_fit.py --file models/rm3_hydro.nc --out out/bench_rm3
"""
from __future__ import annotations

import argparse
import csv
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_FILE = ROOT / "models" / "hinged_barge_hydro.nc"
DEFAULT_DOFS = [f"barge{k}__{d}" for k in (1, 2) for d in ("Surge", "Heave", "Pitch")]


def load(path: Path, read_kw: dict):
    """Dataset in NED body frames: read_netcdf for mbcontrol files, else the readers + frames."""
    from mbcontrol.hydro import read_netcdf

    if path.suffix == ".nc":
        ds = read_netcdf(path)
        if "frame" in ds.attrs and "NED" in str(ds.attrs["frame"]):
            return ds
    from mbcontrol.hydro import zup_to_ned
    from mbcontrol.hydro.readers import read_hydro, to_scene_frames  # lazy: optional module

    raw = read_hydro(path, **read_kw)
    src = raw["cog"] if "cog" in raw else raw["reference_point"]
    cogs = {str(b): zup_to_ned(src.sel(body=b).transpose("xyz").values) for b in raw["body"].values}
    return to_scene_frames(raw, cogs)


def row(method, tol, model, seconds, extra=None):
    p = model.report["passivity"]
    return {"method": method, "tol": "" if tol is None else tol, "n_states": model.order,
            "rms_error": model.report.get("rms_error", model.fit_error), "fit_error": model.fit_error,
            "passive": bool(p["passive"]), "margin": p["margin"],
            "min_eig": p["min_eig"], "omega_at_min": p["omega_at_min"], "max_eig": p["max_eig"],
            "seconds": seconds, **(extra or {})}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--file", type=Path, default=DEFAULT_FILE, help=f"hydro data (default {DEFAULT_FILE.name})")
    ap.add_argument("--dofs", nargs="+", default=None,
                    help="DOF names <body>__<Dof> (default: the hinged barge's 6, or all DOFs of --file)")
    ap.add_argument("--tols", type=float, nargs="+", default=[0.1, 0.05, 0.02, 0.01, 0.005],
                    help="fit tolerances to sweep (default 0.1 0.05 0.02 0.01 0.005)")
    ap.add_argument("--omega-max", type=float, default=None,
                    help="fit band limit, rad/s (default: the file's omega_max_mesh, else all)")
    ap.add_argument("--response-band", type=float, nargs=2, default=None, metavar=("LO", "HI"),
                    help="rad/s where mbcontrol judges its fit per frequency (default: the whole band)")
    ap.add_argument("--read-kw", default="{}",
                    help='JSON keyword arguments for readers.read_hydro, e.g. \'{"force_symmetric": true}\'')
    ap.add_argument("--out", type=Path, default=Path("out/bench_radiation"), help="folder for CSV and PNG")
    args = ap.parse_args(argv)

    from mbcontrol.hydro import fit_radiation
    from mbcontrol.hydro.fit.baseline import fit_radiation_hankel

    ds = load(args.file, json.loads(args.read_kw))
    all_dofs = [str(d) for d in ds["radiating_dof"].values]
    dofs = args.dofs or (DEFAULT_DOFS if set(DEFAULT_DOFS) <= set(all_dofs) else all_dofs)
    wmax = args.omega_max if args.omega_max is not None else ds.attrs.get("omega_max_mesh")
    wmax = float(wmax) if wmax is not None and np.isfinite(wmax) else None
    rows = []
    for tol in args.tols:
        t0 = time.perf_counter()
        raw = fit_radiation(ds, dofs, tol=tol, omega_max=wmax, passive=False, response_band=args.response_band)
        t1 = time.perf_counter()
        pas = fit_radiation(ds, dofs, tol=tol, omega_max=wmax, response_band=args.response_band)
        t2 = time.perf_counter()
        rows.append(row("vector fit (unconstrained)", tol, raw, t1 - t0))
        rows.append(row("vector fit + passivity", tol, pas, t2 - t1,
                        {"enforcement_s": pas.report["passivity"].get("enforcement_seconds", 0.0)}))
        print(f"  tol {tol:g}: {raw.order} -> {pas.order} states, {t1 - t0:.1f} + {t2 - t1:.1f} s", flush=True)
    t0 = time.perf_counter()
    hb = fit_radiation_hankel(ds, dofs, omega_max=wmax)
    rows.append(row("WEC-Sim Hankel (R2>=0.95)", None, hb, time.perf_counter() - t0,
                    {"min_r2": hb.report["min_r2"]}))

    args.out.mkdir(parents=True, exist_ok=True)
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with open(args.out / "radiation_fit.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    band = f"{float(ds['omega'].min()):.3g}-{wmax if wmax else float(ds['omega'].max()):.3g} rad/s"
    print(f"{args.file.name}: {len(dofs)} DOFs {dofs}, fit band {band}")
    print(f"{'method':30s} {'tol':>6s} {'states':>6s} {'RMS err':>8s} {'own err':>8s} {'passive':>7s} {'margin':>10s} "
          f"{'min eig @ rad/s':>18s} {'time (s)':>8s}")
    for r in rows:
        tol = f"{r['tol']:.3g}" if r["tol"] != "" else "-"
        print(f"{r['method']:30s} {tol:>6s} {r['n_states']:6d} {r['rms_error']:8.2%} {r['fit_error']:8.2%} {str(r['passive']):>7s} "
              f"{r['margin']:10.2e} {r['min_eig']:9.3g} @ {r['omega_at_min']:6.3g} {r['seconds']:8.1f}")
    plot(rows, args.out / "radiation_fit.png", f"{args.file.name}: {len(dofs)} DOFs, {band}")
    print(f"wrote {args.out / 'radiation_fit.csv'} and {args.out / 'radiation_fit.png'}")
    return 0


def plot(rows, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = {"vector fit (unconstrained)": ("o--", "C0"), "vector fit + passivity": ("s-", "C2"),
              "WEC-Sim Hankel (R2>=0.95)": ("*", "C3")}
    for method, (marker, color) in styles.items():
        sel = [r for r in rows if r["method"] == method]
        if not sel:
            continue
        x = [r["n_states"] for r in sel]
        kw = {"color": color, "label": method, "markersize": 12 if marker == "*" else 6}
        ax1.plot(x, [100 * r["rms_error"] for r in sel], marker, **kw)
        ax2.plot(x, [r["margin"] for r in sel], marker, **kw)
        for r in sel:
            if r["tol"] != "":
                ax1.annotate(f"{r['tol']:g}", (r["n_states"], 100 * r["rms_error"]), fontsize=7,
                             xytext=(3, 3), textcoords="offset points")
    ax1.set(xlabel="states", ylabel="RMS error on K(jω) over the band (%)", yscale="log", title="accuracy (labels: tol)")
    ax2.axhline(0.0, color="k", lw=0.8)
    ax2.set_yscale("symlog", linthresh=1e-6)
    lo, hi = min(r["margin"] for r in rows), max(r["margin"] for r in rows)
    ax2.set_ylim(min(3 * lo, -1e-5), max(3 * hi, 1e-5))
    ax2.set(xlabel="states", ylabel="min eig ½(K+Kᴴ) / max eig", title="passivity margin (< 0: not passive)")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", alpha=0.3)
    ax1.yaxis.set_major_locator(matplotlib.ticker.FixedLocator([0.1, 0.2, 0.5, 1, 2, 5, 10, 20]))
    ax1.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))   # 2, not 2x10^0
    ax1.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax1.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
