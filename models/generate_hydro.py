#!/usr/bin/env python3
"""Regenerate the cached BEM data of the catalogue models into models/<name>_hydro.nc.

The body definitions live in CATALOGUE below (n-frame NED inputs, SI units); later they will
be read from the scene files. Each run goes through mbcontrol.hydro.compute, so a result is
taken from the cache when the inputs have not changed, and the final body-frame dataset is
copied from the cache next to this script (written to a temporary file, then renamed).

Frequency grid of hinged_barge (150 frequencies, rad/s):
- 0.3–2: 12 log-spaced points. A and B vary slowly here; B → 0 at the low end.
- 2–15: uniform, Δω = 0.1. The heave/pitch resonances of the barges are near 6–9 rad/s and the
  4 cm gap between the barges has a lightly damped potential-flow resonance near 10.2 rad/s
  (half-width ≈ 0.3 rad/s), which a log grid would under-sample. A uniform grid also makes the
  cosine transform for K(t) reliable up to t ≈ π/Δω ≈ 30 s.
- 15–30: 7 more log-spaced points for the high-frequency tail that the radiation fit needs. Above
  the dataset attribute ``omega_max_mesh`` (8 panel sizes per wavelength) the values lose accuracy.

Examples
--------
    python models/generate_hydro.py --timing-only          # 3 frequencies, prints the estimate
    nice -n 10 python models/generate_hydro.py             # full run (about 10 min on one core)
    python models/generate_hydro.py --fit-report           # radiation fit of the saved dataset
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _grid():
    import numpy as np
    return np.unique(np.concatenate([np.geomspace(0.3, 2.0, 12, endpoint=False),
                                     np.round(np.arange(2.0, 15.0 + 1e-9, 0.1), 10),
                                     np.geomspace(15.0, 30.0, 8)[1:]]))


def catalogue(panel_size: float | None = None) -> dict:
    """name -> keyword arguments of mbcontrol.hydro.compute (except cache/progress)."""
    from mbcontrol.hydro import BemBody

    rho, draft = 1000.0, 0.1
    h = 0.02 if panel_size is None else panel_size
    mass = rho * 0.6 * 0.3 * draft  # 18 kg: floats level with 0.1 m draft
    barges = [BemBody(name=name, geometry={"type": "box", "size": [0.6, 0.3, 0.2], "center": [x, 0.0, 0.0]},
                      cog=(x, 0.0, 0.0), mass=mass, panel_size=h, dofs=("Surge", "Heave", "Pitch"))
              for name, x in (("barge1", 0.32), ("barge2", 0.96))]
    return {"hinged_barge": dict(bodies=barges, rho=rho, g=9.81, depth=float("inf"), omegas=_grid(),
                                 headings=(0.0,))}


def _copy_atomic(src: Path, dst: Path) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{dst.name}.", suffix=".tmp", dir=dst.parent)
    os.close(fd)
    try:
        shutil.copyfile(src, tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, dst)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def fit_report(path: Path, tol: float, omega_max: str | None) -> None:
    from mbcontrol.hydro import fit_radiation
    from mbcontrol.hydro._io import read_netcdf

    ds = read_netcdf(path)
    wmax = None if omega_max is None else ds.attrs["omega_max_mesh"] if omega_max == "mesh" else float(omega_max)
    t0 = time.perf_counter()
    model = fit_radiation(ds, tol=tol, omega_max=wmax)
    r = model.report
    print(f"{path.name}: radiation fit of all {len(model.dofs)} DOFs {list(model.dofs)}, "
          f"ω = {r['omega_fit'][0]:.3g}–{r['omega_fit'][1]:.3g} rad/s")
    print(f"  order {model.order} states, fit error {model.fit_error:.4f} (tol {tol}), "
          f"max Re eig(A) {r['max_real_eig']:.4g} 1/s, |K_fit(0)|/max|K| {r['K0_relative']:.2e}, "
          f"{time.perf_counter() - t0:.1f} s")
    p = r["passivity"]
    print(f"  passivity: min eig(K+Kᴴ) {p['min_eig']:.4g} at ω = {p['omega_at_min']:.3g} rad/s "
          f"(max eig {p['max_eig']:.4g}; grid {p['omega_range'][0]:.3g}–{p['omega_range'][1]:.3g} rad/s)")
    for grp in r["groups"]:
        print(f"  group {grp['dofs']}: {grp['history'][-1]['poles']} poles -> {grp['order']} states")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--models", nargs="+", default=["hinged_barge"], help="catalogue entries to regenerate")
    ap.add_argument("--out-dir", type=Path, default=HERE, help="where <name>_hydro.nc is written (default: models/)")
    ap.add_argument("--cache-dir", type=Path, default=Path.home() / ".cache" / "mbcontrol" / "hydro",
                    help="BEM cache folder (default: ~/.cache/mbcontrol/hydro)")
    ap.add_argument("--panel-size", type=float, default=None, help="override the panel size (m)")
    ap.add_argument("--timing-only", action="store_true", help="solve 3 frequencies, print the time estimate")
    ap.add_argument("--fit-report", action="store_true", help="only fit the radiation model of the saved files")
    ap.add_argument("--tol", type=float, default=0.01, help="radiation fit tolerance for --fit-report")
    ap.add_argument("--fit-omega-max", default=None,
                    help="fit only up to this ω (rad/s), or 'mesh' for the dataset's omega_max_mesh")
    ap.add_argument("--n-jobs", type=int, default=1, help="Capytaine processes")
    ap.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    args = ap.parse_args(argv)

    import numpy as np
    from mbcontrol.hydro import compute

    cat = catalogue(args.panel_size)
    unknown = [m for m in args.models if m not in cat]
    if unknown:
        ap.error(f"unknown model(s) {unknown}; known: {sorted(cat)}")
    for name in args.models:
        out = args.out_dir / f"{name}_hydro.nc"
        if args.fit_report:
            fit_report(out, args.tol, args.fit_omega_max)
            continue
        kw = dict(cat[name])
        if args.timing_only:
            w = kw["omegas"]
            kw["omegas"] = np.array([w[0], w[len(w) // 2], w[-1]])
            t0 = time.perf_counter()
            ds = compute(**kw, cache_dir=None, progress=not args.no_progress, n_jobs=args.n_jobs)
            dt = time.perf_counter() - t0
            print(f"{name}: 3 frequencies (+ ω = 0, ∞) in {dt:.1f} s; panels hull {ds.attrs['hull_panels']}, "
                  f"lid {ds.attrs['lid_panels']}; estimate for {len(w)} frequencies: "
                  f"{dt / 5 * (len(w) + 2) / 60:.1f} min")
            continue
        t0 = time.perf_counter()
        ds = compute(**kw, cache_dir=args.cache_dir, progress=not args.no_progress, n_jobs=args.n_jobs)
        key = ds.attrs["cache_key"]
        _copy_atomic(args.cache_dir / f"bem_{key[:16]}.nc", out)
        print(f"{name}: wrote {out} ({time.perf_counter() - t0:.1f} s, BEM solve {ds.attrs['solve_seconds']:.1f} s; "
              f"{ds.sizes['omega']} frequencies; panels hull {ds.attrs['hull_panels']}, lid {ds.attrs['lid_panels']}; "
              f"omega_max_mesh {ds.attrs['omega_max_mesh']:.1f} rad/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
