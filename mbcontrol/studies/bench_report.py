"""`mbcontrol bench MODEL`: the work-precision chart, table and stability limits, written out.

Files (atomic writes) in the output folder: work_precision.png, work_precision.csv,
work_precision.nc and, with stability, stability.csv.
"""
from __future__ import annotations

import csv
from pathlib import Path

from ..atomic import atomic_path
from ..results import write_dataset
from ..sim import stability_table
from . import workprecision as wp


def bench(scene, wave, *, duration: float, methods, radiation_tols=(), stability=False,
          repeats: int = 3, out="out/bench", tol: float = 0.01, echo=print) -> dict:
    """Measure, write and print; returns {"work_precision": Dataset, "stability": rows|None,
    "cheapest": the cheapest run within tol (dict) or None}."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ds = wp.work_precision(scene, wave, duration=duration, methods=methods,
                           radiation_tols=radiation_tols, repeats=repeats, progress=True)
    write_dataset(ds, out / "work_precision.nc")
    _atomic(out / "work_precision.csv", lambda path: ds.to_dataframe().to_csv(path))
    wp.plot(ds, out / "work_precision.png", tol=tol)
    echo(wp.table(ds))
    best = wp.cheapest(ds, tol, series=[m for m in methods])
    if best is None:
        echo(f"\nno method reached {tol:.0%} RMS on the full model")
    else:
        setting = (f"rtol {best['rtol']:.0e}" if best["rtol"] == best["rtol"]
                   else f"dt {best['dt_s']:.4g} s")
        echo(f"\ncheapest within {tol:.0%} RMS: {best['method']} at {setting}: error "
             f"{best['rms_error']:.2e}, {best['rtf']:,.0f}x real time")
    rows = None
    if stability:
        rows = _stability(scene, wave, methods)
        _atomic(out / "stability.csv", lambda path: _write_csv(rows, path))
        echo("\nlargest stable step (s): linearised step map | simulated search "
             "(stable .. unstable)")
        for r in rows:
            lin = f"{r['linear_limit_s']:.4g}" if r["linear_limit_s"] else "n/a"
            unstable = f"{r['unstable_s']:.4g}" if r["unstable_s"] != float("inf") else "none"
            echo(f"  {r['scenario']:22s} {r['method']:8s} {r['states']:4d} states  "
                 f"{lin:>9s} | {r['stable_s']:.4g} .. {unstable}")
    echo(f"\nwrote {out}/work_precision.png, .csv, .nc" + (", stability.csv" if rows else ""))
    return {"work_precision": ds, "stability": rows, "cheapest": best}


def _stability(scene, wave, methods):
    from mbcontrol.controllers import Latching
    fixed = [m for m in methods if m in ("rk3", "rk4", "dopri5", "exp-rk4")]
    stop, latching = None, None
    if scene.ptos:
        pto = scene.ptos[0]
        if pto.joint:
            # engaged by the wave: the stop sits at a fifth of the wave height, stiff enough
            # to ring 30x faster than the wave
            travel = max(wave.settings.get("height", wave.settings.get("hs", 1.0)) / 5, 1e-3)
            stop = (pto.joint, travel, _stop_stiffness(scene, pto, wave))
        latching = Latching(damping=pto.damping or 1.0, latch_time=wave.period / 8)
    return stability_table(scene, wave, methods=fixed, duration=min(60.0, 10 * wave.period),
                                end_stop=stop, latching=latching,
                                tight_radiation_tol=scene.hydro.radiation_tol / 5,
                                progress=True)


def _stop_stiffness(scene, pto, wave) -> float:
    """A stop ringing at 30 x the wave frequency (N/m or N m/rad), on the joint's effective
    inertia at rest: 1 / (d s_j' / d u_pto), with the PTO acting along its own joint."""
    import numpy as np

    from ..plant import build_plant, jacobians
    plant = build_plant(scene)
    B_u = np.array(jacobians(plant)(plant.x0(), np.zeros(len(plant.inputs)),
                                    np.zeros(len(plant.disturbances)), plant.p0)[1])
    row = plant.states.index(f"{pto.joint}__vel")
    inverse_inertia = abs(B_u[row, plant.inputs.index(f"u__{pto.name}")])
    return float((30 * 2 * np.pi / wave.period) ** 2 / inverse_inertia)


def _write_csv(rows, path):
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def _atomic(path: Path, write) -> None:
    """write(tmp) then rename: a reader never sees half a file."""
    with atomic_path(path, path.suffix) as tmp:
        write(str(tmp))
