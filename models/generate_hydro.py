#!/usr/bin/env python3
"""Regenerate the precomputed hydro data of catalogue models from their scene files.

For each scene named (default: every catalogue scene with a [hydro] file): if [hydro] names a
`source` (WAMIT .out, BEMIO .h5, Capytaine .nc), it is read, cleaned and mapped to body frames
at the scene's CoGs; otherwise the bodies' geometry, mass and CoG and the [hydro] table
(panel_size, omega, headings, dofs, lid) go through mbcontrol.hydro.compute (Capytaine). The
body-frame result is written next to the scene as its hydro file (to a temporary file, then
renamed). Scenes sharing one hydro file are made once; BEM results come from the cache when
their inputs have not changed.

Examples
--------
    python models/generate_hydro.py --timing-only hinged_barge   # 3 frequencies, an estimate
    nice -n 10 python models/generate_hydro.py hinged_barge      # full run (~7 min, one core)
    python models/generate_hydro.py --fit-report hinged_barge    # radiation fit of the saved file
    python models/generate_hydro.py --ship-fits                  # radiation fits shipped in models/

--ship-fits builds each catalogue model's plant (and the flume section's three blocked-DOF
variants the tank runs use) and copies the radiation fits they used into models/radiation_fits,
where a fresh machine finds them before fitting. Their names are the cache's keys (the data,
DOFs, tolerance, band and the fitting code), so after any change to those, rerun this: the
catalogue tests fail until the shipped fits match again.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

if __name__ == "__main__":      # run as a script from a checkout: the package beside models/
    sys.path.append(str(Path(__file__).resolve().parent.parent))   # (an installed one wins)

HERE = Path(__file__).resolve().parent


def bem_inputs(scene, panel_size: float | None = None) -> dict:
    """Keyword arguments of mbcontrol.hydro.compute for a scene (cache and progress aside)."""
    import numpy as np

    from mbcontrol.hydro import BemBody
    from mbcontrol.hydro import geometry_dict
    from mbcontrol.hydro import obstacle_bodies

    h = scene.hydro
    bodies = [BemBody(name=b.name, geometry=geometry_dict(b.geometry), cog=b.cog, mass=b.mass,
                      panel_size=panel_size or h.panel_size, dofs=h.dofs)
              for b in scene.bodies if b.hydro and b.geometry is not None]
    bodies += obstacle_bodies(scene, panel_size)   # fixed structures: scatter, no DOFs
    return dict(bodies=bodies, rho=scene.water.rho, g=scene.water.g, depth=scene.water.depth,
                omegas=np.array(h.omega), headings=h.headings, lid=h.lid)


def catalogue(names=None) -> dict:
    """hydro file path -> the first scene (by name) that makes it (a BEM grid or a source)."""
    from mbcontrol.scene import list_models, load_scene

    chosen = {}
    for name in names or list_models():
        scene = load_scene(name)
        h = scene.hydro
        if h.file and (h.omega or h.source) and h.file not in chosen:
            chosen[h.file] = scene
    return chosen


def convert(scene, out: Path) -> None:
    """Third-party data (scene.hydro.source) -> body-frame dataset at the scene's CoGs (the
    library's own conversion, mbcontrol.hydro.source), written as the scene's hydro file."""
    from mbcontrol.hydro import write_netcdf_atomic
    from mbcontrol.hydro import converted_source

    t0 = time.perf_counter()
    _, body_frames = converted_source(scene)
    for note in body_frames.attrs.get("notes", []):
        print(f"  note: {note}")
    write_netcdf_atomic(body_frames, out)
    print(f"{scene.name}: wrote {out} from {Path(scene.hydro.source).name} "
          f"({body_frames.sizes['omega']} frequencies, {time.perf_counter() - t0:.1f} s)")


def fit_report(path: Path, tol: float, omega_max: str | None) -> None:
    from mbcontrol.hydro import fit_radiation
    from mbcontrol.hydro import read_netcdf

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


SHIP_VARIANTS = {"flume_section": [("roll",), ("heave",), ("sway",)]}   # Fidelity(freeze=...)


def ship_fits(names=None) -> int:
    """Build the plants, copy the fits they used into models/radiation_fits (atomically)."""
    from mbcontrol.atomic import write_bytes
    from mbcontrol.cache import cache_dir
    from mbcontrol.hydro import recording_served_fits, shipped_fits_dir
    from mbcontrol.plant import Fidelity, build_plant, recording_served_statics
    from mbcontrol.scene import list_models
    out = shipped_fits_dir()
    out.mkdir(parents=True, exist_ok=True)
    wanted = set()
    with recording_served_statics() as statics:
        for name in names or list_models():
            for freeze in [()] + SHIP_VARIANTS.get(name, []):
                with recording_served_fits() as fits:
                    build_plant(name, fidelity=Fidelity(freeze=freeze) if freeze else None)
                wanted.update(fits)
    for fit in sorted(wanted):
        if (out / fit).exists():
            continue
        write_bytes(out / fit, (cache_dir() / fit).read_bytes())
    stale = [p for p in out.glob("radiation_*.npz") if p.name not in wanted and not names]
    for path in stale:
        path.unlink()
    _ship_statics(out.parent, statics)
    print(f"models/radiation_fits: {len(wanted)} fits ({len(stale)} stale removed)")
    return 0


def _ship_statics(models: Path, served) -> None:
    """The MoorDyn statics of the catalogue's lines files, beside them (plant.moordyn_statics):
    served, the (lines file, key, statics) the plants asked for (the first of each key)."""
    import json
    from mbcontrol.atomic import write_bytes
    from mbcontrol.plant import shipped_statics
    shipped = {}
    for lines, key, statics in served:
        if Path(lines).resolve().parent == models.resolve():
            shipped.setdefault(lines, {}).setdefault(key, statics)
    for lines, entries in shipped.items():
        write_bytes(shipped_statics(lines), json.dumps(entries, indent=1).encode())
        print(f"{shipped_statics(lines).name}: {len(entries)} statics")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("models", nargs="*", help="catalogue scene names (default: all with a hydro file)")
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
    ap.add_argument("--ship-fits", action="store_true",
                    help="copy the catalogue's radiation fits into models/radiation_fits")
    args = ap.parse_args(argv)
    if args.ship_fits:
        return ship_fits(args.models)

    import numpy as np
    from mbcontrol.hydro import compute, write_netcdf_atomic
    from mbcontrol.hydro import compute_isolated

    for file, scene in catalogue(args.models).items():
        out = Path(file)
        if args.fit_report:
            fit_report(out, args.tol, args.fit_omega_max)
            continue
        if scene.hydro.source:
            convert(scene, out)
            continue
        kw = bem_inputs(scene, args.panel_size)
        name = scene.name
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
        solve = compute if scene.hydro.interaction else compute_isolated
        ds = solve(**kw, cache_dir=args.cache_dir, progress=not args.no_progress, n_jobs=args.n_jobs)
        write_netcdf_atomic(ds, out)
        print(f"{name}: wrote {out} ({time.perf_counter() - t0:.1f} s, BEM solve {ds.attrs['solve_seconds']:.1f} s; "
              f"{ds.sizes['omega']} frequencies; panels hull {ds.attrs['hull_panels']}, lid {ds.attrs['lid_panels']}; "
              f"omega_max_mesh {ds.attrs['omega_max_mesh']:.1f} rad/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
