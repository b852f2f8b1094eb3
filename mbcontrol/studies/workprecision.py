"""Work-precision: the error of each integration method and radiation order against its cost.

For one model and one sea, every (method, step or tolerance) and every radiation fit order is
run and measured:

  error  max over the joint coordinates q_j of RMS(q_j - q_j,ref) / RMS(q_j,ref) over the
         record after the wave's ramp, on the output grid; q_ref is the converged reference:
         dopri5 on the full model at a step 8x below the finest one tried, whose own error is
         estimated against half that step and reported;
  cost   the wall time of the run (excitation synthesis and time-stepping, best of `repeats`,
         compilation excluded), and the real-time factor duration / wall.

Radiation orders are run on the full model's reference, so their error is a model error;
integration methods are run on the full model. `mbcontrol bench MODEL` writes the table (CSV
and netCDF) and the chart (PNG); see also mbcontrol.sim.stability for where each method fails.
"""
from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from ..console import progress_bar
from ..errors import InputError, SimulationError
from ..sim import METHODS

ERROR_MEASURE = ("max over joint coordinates of RMS(q - q_ref) / RMS(q_ref) after the wave "
                 "ramp; q_ref: dopri5 at 1/8 of the finest step")


def coordinate_error(ds, ref, after: float, n_q: int) -> float:
    """The error measure above between two runs on output grids where ref's contains ds's."""
    t, t_ref = ds["time"].values, ref["time"].values
    idx = np.rint(t / (t_ref[1] - t_ref[0])).astype(int)
    inside = idx < t_ref.size            # a coarse step may overshoot the record's end
    t, idx = t[inside], idx[inside]
    if np.max(np.abs(t_ref[idx] - t)) > 1e-9 * max(1.0, t[-1]):
        raise InputError("the reference's output grid must contain the run's")
    mask = (t >= after)
    X = ds["state"].values[:inside.sum()][mask, :n_q]
    X_ref = ref["state"].values[idx[mask], :n_q]
    scale = np.sqrt(np.mean(X_ref**2, axis=0))
    keep = scale > 1e-9 * max(scale.max(), 1e-300)       # coordinates the sea moves at all
    err = np.sqrt(np.mean((X - X_ref) ** 2, axis=0))[keep] / scale[keep]
    return float(err.max())


def default_steps(period: float, finest: int = 256, coarsest: int = 4) -> list[float]:
    """Steps period/coarsest ... period/finest, halving (so the reference grid holds them)."""
    k = np.arange(int(np.log2(coarsest)), int(np.log2(finest)) + 1)
    return [period / 2.0**j for j in k]


def work_precision(scene, wave, *, duration: float, methods=("rk3", "rk4", "dopri5",
                   "exp-rk4", "cvodes", "adams"), steps=None,
                   rtols=(1e-3, 1e-4, 1e-5, 1e-6, 1e-7), radiation_tols=(), radiation_method:
                   str = "exp-rk4", repeats: int = 3, progress: bool = False) -> xr.Dataset:
    """Run the grid and return a Dataset over `run` (see the module docstring).

    scene: a Scene, scene file or catalogue name. steps (s): fixed steps to try (default
    `default_steps(wave.period)`); rtols: for the adaptive methods (their output grid is the
    finest step). radiation_tols: fits to compare at the finest stable step of
    `radiation_method`. Unstable runs (SimulationError) are kept, marked stable = False.
    """
    from ..plant import build_plant
    from ..scene import load_scene
    from ..sim import simulate
    scene = load_scene(scene) if isinstance(scene, str) else scene
    plant = build_plant(scene)
    steps = sorted(steps or default_steps(wave.period), reverse=True)
    dt_ref = steps[-1] / 8
    after = wave.ramp_time

    def run(p, method, dt, rtol=1e-8):
        best = None
        for _ in range(repeats if METHODS[method].fixed_step else 1):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                ds = simulate(p, wave, duration=duration, dt=dt, method=method, rtol=rtol)
            if best is None or ds.attrs["wall_time_s"] < best.attrs["wall_time_s"]:
                best = ds
        return best

    ref = simulate(plant, wave, duration=duration, dt=dt_ref, method="dopri5")
    check = simulate(plant, wave, duration=duration, dt=dt_ref / 2, method="dopri5")
    ref_error = coordinate_error(ref, check, after, plant.n_q)

    jobs = [(m, dt, None) for m in methods if METHODS[m].fixed_step for dt in steps]
    jobs += [(m, steps[-1], rtol) for m in methods if not METHODS[m].fixed_step
             for rtol in rtols]
    bar = _bar(progress, len(jobs) + len(radiation_tols))
    rows = []
    for method, dt, rtol in jobs:
        rows.append(_measure(run, plant, method, dt, rtol, ref, after, duration, plant.n_q,
                             scene.hydro.radiation_tol))
        _tick(bar)
    # radiation orders: the finest stable step of radiation_method, a cruder model each
    stable_steps = [r["dt_s"] for r in rows if r["method"] == radiation_method and r["stable"]
                    and r["rms_error"] < 1e-4] or [steps[-1]]
    dt_rad = max(stable_steps)
    for tol in radiation_tols:
        p = build_plant(scene, radiation_tol=tol)
        row = _measure(run, p, radiation_method, dt_rad, None, ref, after, duration,
                       plant.n_q, tol)
        row["series"] = f"radiation order ({radiation_method}, dt={dt_rad:.3g} s)"
        rows.append(row)
        _tick(bar)
    if bar is not None:
        bar.close()
    return _dataset(rows, plant, wave, duration, dt_ref, ref_error)


def _measure(run, plant, method, dt, rtol, ref, after, duration, n_q, radiation_tol) -> dict:
    row = {"series": method, "method": method, "dt_s": dt,
           "rtol": np.nan if rtol is None else rtol, "radiation_tol": radiation_tol,
           "radiation_states": int(plant.hydro.radiation.order) if plant.hydro else 0,
           "states": plant.nx}
    try:
        ds = run(plant, method, dt, 1e-8 if rtol is None else rtol)
    except SimulationError:
        return {**row, "stable": False, "wall_s": np.nan, "rtf": np.nan, "rms_error": np.nan}
    wall = ds.attrs["wall_time_s"]
    return {**row, "stable": True, "wall_s": wall, "rtf": duration / wall,
            "rms_error": coordinate_error(ds, ref, after, n_q)}


def _dataset(rows, plant, wave, duration, dt_ref, ref_error) -> xr.Dataset:
    data = {key: ("run", [r[key] for r in rows]) for key in rows[0]}
    ds = xr.Dataset(data, coords={"run": np.arange(len(rows))})
    units = {"dt_s": "s", "wall_s": "s", "rtf": "1", "rms_error": "1"}
    for key, unit in units.items():
        ds[key].attrs["units"] = unit
    ds.attrs.update({"model": plant.name, "states": plant.nx, "duration_s": duration,
                     "wave": str(wave.describe()), "error_measure": ERROR_MEASURE,
                     "reference_dt_s": dt_ref, "reference_error": ref_error,
                     "wall_time": "excitation synthesis + time-stepping, best of repeats; "
                                  "compilation excluded; one core"})
    return ds


def table(ds: xr.Dataset) -> str:
    """The Dataset as a text table, cheapest first within each series."""
    lines = [f"{ds.attrs['model']} ({ds.attrs['states']} states), {ds.attrs['duration_s']:.0f} s "
             f"of {ds.attrs['wave']}",
             f"error: {ds.attrs['error_measure']} (reference's own error "
             f"{ds.attrs['reference_error']:.1e})",
             f"{'series':34s} {'setting':>12s} {'states':>6s} {'wall (s)':>10s} "
             f"{'x real time':>12s} {'rms error':>10s}"]
    for i in range(ds.sizes["run"]):
        r = {k: ds[k].values[i] for k in ds.data_vars}
        setting = (f"rtol={r['rtol']:.0e}" if np.isfinite(r["rtol"]) else
                   f"dt={r['dt_s']:.4g}")
        if not r["stable"]:
            lines.append(f"{r['series']:34s} {setting:>12s} {r['states']:6d} "
                         f"{'unstable':>10s}")
            continue
        lines.append(f"{r['series']:34s} {setting:>12s} {r['states']:6d} {r['wall_s']:10.4f} "
                     f"{r['rtf']:12,.0f} {r['rms_error']:10.2e}")
    return "\n".join(lines)


def cheapest(ds: xr.Dataset, tol: float, series=None) -> dict | None:
    """The stable run of least wall time whose error is <= tol (optionally within series)."""
    best = None
    for i in range(ds.sizes["run"]):
        r = {k: ds[k].values[i].item() for k in ds.data_vars}
        if not r["stable"] or r["rms_error"] > tol or (series and r["series"] not in series):
            continue
        if best is None or r["wall_s"] < best["wall_s"]:
            best = r
    return best


def plot(ds: xr.Dataset, path=None, tol: float | None = 0.01):
    """Error against wall time, one line per series; unstable steps marked on the top edge."""
    import matplotlib.pyplot as plt

    from ..plotting import save
    fig, ax = plt.subplots(figsize=(10.5, 5.0))
    series = list(dict.fromkeys(ds["series"].values.tolist()))
    stable = ds["stable"].values
    for name in series:
        sel = ds["series"].values == name
        ok, bad = sel & stable, sel & ~stable
        style = "s--" if name.startswith("radiation") else "o-"
        # an unstable step has no error to plot: the legend says from which step on
        label = name + (f" (unstable at dt >= {ds['dt_s'].values[bad].min():.3g} s)"
                        if bad.any() else "")
        if name.startswith("radiation"):
            label += "; numbers: radiation states"
        ax.loglog(ds["wall_s"].values[ok], ds["rms_error"].values[ok], style, label=label, ms=4)
        if name.startswith("radiation"):
            for j, (w, e, n) in enumerate(zip(ds["wall_s"].values[ok],
                                              ds["rms_error"].values[ok],
                                              ds["radiation_states"].values[ok])):
                ax.annotate(f"{n}", (w, e), fontsize=7, xytext=(3, 5 if j % 2 else -9),
                            textcoords="offset points")   # alternate sides: points crowd
    if tol:
        ax.axhline(tol, color="0.4", lw=0.8, ls=":")
        ax.annotate(f"{tol:.0%} RMS", xy=(1.0, tol), xycoords=("axes fraction", "data"),
                    ha="right", va="bottom", fontsize=7, color="0.3")
    ax.set_xlabel("wall time (s): excitation + time-stepping, one core")
    ax.set_ylabel("relative RMS error of the joint coordinates")
    ax.set_title(f"{ds.attrs['model']}: work-precision, {ds.attrs['duration_s']:.0f} s record",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()                    # the legend beside the axes: it hides no point
    if path is not None:
        save(fig, path)
    return fig


def _bar(progress: bool, total: int):
    if not progress:
        return None
    return progress_bar(total=total, desc="work-precision", leave=False)


def _tick(bar) -> None:
    if bar is not None:
        bar.update()
