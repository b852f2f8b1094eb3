"""A whole sweep: cases from seas, seeds and varied quantities, run (serially or on Dask)
into a store, assembled into one Dataset, with the power figures per sea state: wave energy
flux J, capture width P / J and its ratio to a characteristic width, and for weighted seas the
weighted mean power and the mean annual energy."""
from __future__ import annotations

import datetime
import math
import time
from pathlib import Path

import numpy as np
import xarray as xr

from ... import defaults
from ...errors import InputError
from ...plant import provenance
from .cases import build_cases, roles_for
from .made_by import sweep_provenance
from .records import label_summary, measured_seas, with_records
from ...waves import annual_energy_MWh, site_energy_flux
from .runner import PlantCache, execute
from .store import CaseStore, assemble
from .zero import fell_back_summary, zero_note, zero_seas


NONLINEAR_MODES = ("scene", "invalid", "always")


def sweep(model: str, seas, *, seeds: int = 1, vary: dict | None = None, params=None,
          scene_params=None, controller: str | None = None, settings=None,
          duration: float | None = None, dt: float | None = None, method: str | None = None,
          store=None, workers: int | None = 0, scheduler: str | None = None,
          width: float | None = None, progress: bool = True, design: bool = False,
          robust: bool = True, amplitudes: str = "deterministic", identified=None,
          years: dict | None = None, nonlinear: str = "scene", records=None):
    """Run a sweep and return (Dataset, summary).

    seas: SeaStates (`waves.grid`, `waves.read_seas`); vary: name -> values (scene
    parameter, plant parameter or controller setting); workers: 0 serial, None one Dask
    worker per core, N workers; scheduler: a Dask scheduler address; store: a folder (resume:
    finished cases are not run again; `<store>/sweep.nc` holds the Dataset); width: the
    characteristic width (m) for the capture width ratio. design: the controller is tuned for
    each sea (studies.design.sea; per sea "settings", "bound_W", "percent_of_bound" in the
    summary); robust (the default; False: --aggressive): a reactive law tuned within the
    robustness floors, as `design` tunes it; amplitudes:
    "deterministic" (the expected power) or "random" (Rayleigh: a record's statistics;
    waves.irregular). With several seeds each sea gets its standard error and 95 % interval
    (seed_statistics). identified: an identification's summary (path): its parameter values
    are run (params given explicitly win) and its covariance and model error enter the annual
    energy's budget (`uncertainty`); years: label -> per-year weights of the seas
    (`waves.read_year_weights`), the budget's resource term. duration, dt (s) and method left out
    take the defaults "sweep.duration" (600 s), "sweep.dt" (0.05 s) and "sweep.method"
    (mbcontrol.defaults). nonlinear: "scene" (the scene's own hydrostatics), "always" (every
    sea on the nonlinear plant: [hydro] hydrostatics = froude_krylov = "nonlinear") or
    "invalid" (the linear plant, and the nonlinear one only for seas whose linear run leaves
    the linear range, with the same controller; those cases are marked nonlinear_model and
    keep the linear run's power as mean_power_W__linear). records: a folder of measured
    elevation records, one sea each, instead of `seas` (None): every file checked before any
    case runs, duration left out each record's own length (`records`; no annual energy)."""
    from mbcontrol.controllers import REGISTRY

    from ...scene import load_scene
    start, given_duration = time.perf_counter(), duration
    duration = defaults.resolve("sweep.duration", duration)
    dt, method = defaults.resolve("sweep.dt", dt), defaults.resolve("sweep.method", method)
    vary = {k: list(v) for k, v in (vary or {}).items()}
    scene = load_scene(model, scene_params or None)
    robust = _check_controller(controller, design, robust)
    plants, plant = _run_plants(model, scene, tuple(sorted((scene_params or {}).items())),
                                nonlinear)
    roles = roles_for(vary, scene, plant.parameters, REGISTRY.get(controller))
    if identified is not None:
        from .uncertainty import read_identified
        identified = read_identified(identified, scene.name, plant.parameters)
        params = {**identified["values"], **dict(params or {})}
    unknown = [p for p in (params or {}) if p not in plant.parameters]
    if unknown:
        raise InputError(f"--param {unknown[0]}: not a parameter of {scene.name}; it has "
                         f"{', '.join(plant.parameters)}")
    inputs = {"model": scene.name, **provenance(plant)}
    measured = measured_seas(records, plant, given_duration, seeds=seeds,
                             amplitudes=amplitudes, seas=seas)
    seas = seas if measured is None else [r.sea for r in measured]
    cases = build_cases(model, seas, seeds=seeds, vary=vary, roles=roles, params=params,
                        scene_params=scene_params, controller=controller, settings=settings,
                        duration=duration, dt=dt, method=method, inputs=inputs,
                        design=design, robust=robust, amplitudes=amplitudes,
                        nonlinear=nonlinear)
    if measured is not None:
        cases = with_records(cases, measured)
    case_store = CaseStore(store, inputs)
    run = execute(cases, case_store, workers=workers, scheduler=scheduler, progress=progress,
                  plants=plants, meanwhile=_import_statistics)
    depth, rho, g = scene.water.depth, scene.water.rho, scene.water.g
    made_by = sweep_provenance(inputs, controller, settings, vary, roles, amplitudes=amplitudes,
                               nonlinear=nonlinear, identified=identified, design=design,
                               robust=robust, measured=measured)
    if measured is not None:
        duration = given_duration             # None: each record's own (per sea in the rows)
    attrs = {"model": scene.name, "controller": controller, "settings": dict(settings or {}),
             "provenance": made_by,
             "params": dict(params or {}), "scene_params": dict(scene_params or {}),
             "duration_s": duration, "dt_s": dt, "method": method,
             "created": datetime.datetime.now().isoformat(timespec="seconds"),
             "metrics": "mbcontrol.analysis.metrics.pto_metrics over the record after the ramp"}
    rated = sum(p.rated_power for p in scene.ptos)
    if scene.ptos and math.isfinite(rated):
        attrs["rated_power_W"] = float(rated)
    ds = assemble(cases, case_store, seas, vary, seeds, attrs)
    if measured is not None:                  # its file name per sea
        ds = ds.assign_coords(record=("sea", [r.name for r in measured]))
    J = [s.j if measured is not None else site_energy_flux(s, depth, rho, g)  # a record's own,
         for s in seas]                                                       # a site's own
    ds["energy_flux_W_per_m"] = ("sea", np.array(J, float))
    ds["capture_width_m"] = ds["mean_power_W"] / ds["energy_flux_W_per_m"]
    if width:
        ds["capture_width_ratio"] = ds["capture_width_m"] / width
        ds.attrs["characteristic_width_m"] = width
    if store is not None:
        from ...results import write_dataset
        write_dataset(ds, Path(store) / "sweep.nc")
    summary = _summary(ds, seas, run, time.perf_counter() - start, len(cases))
    from mbcontrol.controllers import absorbs_nothing
    why = None if design else absorbs_nothing(controller, settings, vary)
    if why:
        summary["notes"].insert(0, why)
    from .uncertainty import add_uncertainty
    if measured is not None:                  # no JONSWAP sea to take linear theory over
        label_summary(summary, measured)
    else:
        add_uncertainty(summary, ds, seas, plant, controller=controller, settings=settings,
                        params=params, duration=duration, amplitudes=amplitudes,
                        identified=identified, years=years)
    summary["provenance"] = made_by
    if "rated_power_W" in ds.attrs:
        summary["rated_power_W"] = float(ds.attrs["rated_power_W"])
    return ds, summary


def _check_controller(controller, design: bool, robust: bool) -> bool:
    """InputError for a controller no sweep can run; robust as a case's key records it (only
    where the law is tuned: --design)."""
    from mbcontrol.controllers import REGISTRY
    if controller is not None and controller not in REGISTRY:
        raise InputError(f"--controller {controller}: expected one of {', '.join(REGISTRY)}")
    if design:
        from mbcontrol.studies.design import DESIGNABLE
        if controller not in DESIGNABLE:
            raise InputError(f"--design tunes a controller for each sea: give --controller, one "
                             f"of {', '.join(DESIGNABLE)} (got {controller})")
    return bool(robust and design)


def _run_plants(model: str, scene, scene_key: tuple, nonlinear: str) -> tuple:
    """(this run's PlantCache, the scene's plant): the plant built and kept for the cases run
    here; with --nonlinear invalid|always the nonlinear plant too, built now (a scene that
    cannot have it fails before any case runs). Nothing outlives the run."""
    if nonlinear not in NONLINEAR_MODES:
        raise InputError(f"--nonlinear {nonlinear}: expected one of {', '.join(NONLINEAR_MODES)}")
    from ...plant import build_plant, with_nonlinear_pressure
    plants = PlantCache()
    plant = plants.keep(model, scene_key, build_plant(scene))
    if nonlinear != "scene":
        plants.keep(model, scene_key, build_plant(with_nonlinear_pressure(scene)), True)
    return plants, plant


def _summary(ds, seas, run, wall, n_cases) -> dict:
    """The JSON contract of `mbcontrol sweep --json` (per sea: means over seeds; when other
    quantities are varied, per sea the values over them as lists in the sweep's order)."""
    power = ds["mean_power_W"].mean("seed")          # over the valid seeds (invalid: NaN)
    cw = ds["capture_width_m"].mean("seed")
    failed = ds["failed"] if "failed" in ds else xr.zeros_like(ds["valid"])
    invalid = ~ds["valid"] & ~failed             # ran, and failed its physics checks
    rows = []
    for k, s in enumerate(seas):
        p, c = power.isel(sea=k).values, cw.isel(sea=k).values
        row = {"hs": s.hs, "tp": s.tp, "weight": None if math.isnan(s.weight) else s.weight,
               "mean_power_W": _plain(p), "capture_width_m": _plain(c),
               "energy_flux_W_per_m": float(ds["energy_flux_W_per_m"].values[k]),
               "invalid_cases": int(invalid.isel(sea=k).sum()),
               "failed_cases": int(failed.isel(sea=k).sum())}
        if not math.isnan(s.te):
            row["te"] = s.te
        if not math.isnan(s.direction):     # a seas file's or the CLI's direction and spread
            row["direction_deg"] = math.degrees(s.direction)
        if not math.isnan(s.spread):
            row.update(spread_deg=math.degrees(s.spread), spreading=s.spreading)
        if ds.sizes["seed"] > 1 and np.ndim(p) == 0:
            row.update(seed_statistics(ds["mean_power_W"].isel(sea=k).values))
        if "bound_W" in ds:                 # --design: the sea's settings and its bound
            row.update(_designed_row(ds, k))
        if "nonlinear_model" in ds:         # --nonlinear invalid: seas that left the range
            row.update(_nonlinear_row(ds.isel(sea=k)))
        if "capture_width_ratio" in ds:
            row["capture_width_ratio"] = _plain(ds["capture_width_ratio"].mean("seed")
                                                .isel(sea=k).values)
        row.update(_mooring_loads(ds, k))
        rows.append(row)
    weights = np.array([s.weight for s in seas])
    weighted = aep = unchecked = None
    coverage = 1.0
    notes = []
    if not np.any(np.isnan(weights)) and power.ndim == 1:
        # a sea with no valid case counts as producing nothing (a device in survival mode):
        # the annual figure is then a lower bound, said so with the share of the year it
        # covers and the figure the failed cases would have given
        missing = np.isnan(power.values) & (weights > 0)
        valid_power = np.where(missing, 0.0, power.values)
        rated = ds.attrs.get("rated_power_W")
        if rated is not None:        # the power matrix capped at the PTOs' rated power
            capped = valid_power > rated
            uncapped_aep = annual_energy_MWh(valid_power, weights)
            valid_power = np.minimum(valid_power, rated)
            if capped.any():
                notes.append(f"{int(capped.sum())} seas are capped at the rated power "
                             f"{rated / 1e3:.4g} kW: annual energy "
                             f"{annual_energy_MWh(valid_power, weights):.4g} MWh, "
                             f"{uncapped_aep:.4g} MWh uncapped")
        weighted = float(np.nansum(weights * valid_power))
        aep = annual_energy_MWh(valid_power, weights)
        coverage = float(1.0 - weights[missing].sum())
        raw = ds.get("mean_power_W__unchecked", ds["mean_power_W"]).mean("seed")
        # a case that failed to run has no number at all: it counts as nothing here too
        unchecked = annual_energy_MWh(np.nan_to_num(raw.values, nan=0.0), weights)
        zero = zero_seas(ds, seas, missing)
        if zero:
            notes.append(zero_note(zero, aep, coverage, unchecked))
    if "bound_W" in ds:
        notes += _design_notes(ds, rows)
    extra = {"zero_seas": zero if aep is not None else [], **fell_back_summary(ds, rows)}
    listed, crashed = _cases_where(ds, invalid), _cases_where(ds, failed)
    if listed:
        notes.append(f"{len(listed)} of {n_cases} cases failed their physics checks and are "
                     f"left out of every mean, matrix and annual figure (listed with their "
                     f"sea, seed and reasons)")
    if crashed:
        notes.append(f"{len(crashed)} of {n_cases} cases failed to run (diverged or raised) "
                     f"and are left out of every mean, matrix and annual figure (listed with "
                     f"their sea, seed and reason)")
    return {"model": ds.attrs["model"], "cases": n_cases, "computed": run["computed"],
            "reused": run["reused"], "wall_time_s": wall,
            "valid_cases": n_cases - len(listed) - len(crashed),
            "invalid_cases": len(listed), "invalid": listed,
            "failed_cases": len(crashed), "failed": crashed, "notes": notes, "seas": rows,
            "weighted_mean_power_W": weighted, "annual_energy_MWh": aep,
            "annual_energy_coverage": coverage if aep is not None else None,
            "annual_energy_unchecked_MWh": unchecked, **extra}


def seed_statistics(powers) -> dict:
    """A sea's mean power over its valid seeds (W) as an estimate: its standard error s / sqrt(n)
    and the 95 % interval mean +- t(0.975, n - 1) s / sqrt(n) (Student), from n >= 2 valid
    seeds; valid_seeds: n; and IEC TS 62600-100 Annex D's per-bin statistics of the records
    (power_std_W, power_min_W, power_max_W; the count is valid_seeds). Each seed is an independent record (with random amplitudes, a
    record's statistics; with deterministic ones the spread is what the phases leave over the
    record)."""
    from scipy.stats import t as student
    x = np.asarray(powers, float)
    x = x[np.isfinite(x)]
    out = {"valid_seeds": int(x.size)}
    if x.size < 2:
        return {**out, "mean_power_stderr_W": None, "mean_power_ci95_W": None}
    std = float(np.std(x, ddof=1))
    stderr = std / math.sqrt(x.size)
    half = float(student.ppf(0.975, x.size - 1)) * stderr
    mean = float(np.mean(x))
    return {**out, "mean_power_stderr_W": stderr,
            "mean_power_ci95_W": [mean - half, mean + half],
            "power_std_W": std, "power_min_W": float(x.min()), "power_max_W": float(x.max())}


def _designed_row(ds, k: int) -> dict:
    """A sea's --design entries: the settings tuned for it (its first seed's: every seed of a
    sea has the same spectrum, so the same tuning), linear theory's power, its bound inside
    the envelope and the simulated power's share of it."""
    import json
    sea = ds.isel(sea=k)
    first = np.ravel(sea["design_settings"].values)[0]
    bound = float(np.nanmean(sea["bound_W"].values)) if np.isfinite(sea["bound_W"].values).any() \
        else None
    power = np.nanmean(sea["mean_power_W"].values) if np.isfinite(sea["mean_power_W"].values).any() \
        else None
    return {"settings": json.loads(first) if first else None,
            "predicted_power_W": _plain(np.nanmean(sea["predicted_power_W"].values))
            if np.isfinite(sea["predicted_power_W"].values).any() else None,
            "bound_W": bound,
            "percent_of_bound": None if bound is None or power is None else float(
                100 * power / bound),
            "inside_envelope": bool(sea["inside_envelope"].values.all()),
            "fell_back": bool(sea["fell_back"].values.any()) if "fell_back" in sea else False,
            "fallback": next((str(f) for f in np.ravel(sea["fallback"].values) if str(f)), None)
            if "fallback" in sea else None,
            "meets_robustness_floors": bool(sea["meets_robustness_floors"].values.all())}


def _design_notes(ds, rows) -> list[str]:
    """What a reader of a --design sweep must know: seas where no setting stays inside the
    envelope, laws below the robustness floors, simulations far off linear theory, and any
    sea whose power beats its bound by more than 1 %."""
    notes = []
    fell = [r for r in rows if r["fell_back"]]
    if fell:
        notes.append(f"{len(fell)} seas' tuned laws could not hold the PTO's limits or the "
                     f"envelope and fell back (fell_back true; their energy is counted): "
                     + ", ".join(f"Hs {r['hs']:.3g} m Tp {r['tp']:.3g} s to {r['fallback']}"
                                 for r in fell))
    outside = [r for r in rows if not r["inside_envelope"]]
    if outside:
        notes.append(f"{len(outside)} seas have no setting inside the linear model's envelope "
                     f"(the closest was used; inside_envelope false): "
                     + ", ".join(f"Hs {r['hs']:.3g} m Tp {r['tp']:.3g} s" for r in outside))
    fragile = [r for r in rows if not r["meets_robustness_floors"]]
    if fragile:
        notes.append(f"{len(fragile)} seas' tuned laws are below the robustness floors (gain "
                     f"margin 2, phase margin 30 deg; meets_robustness_floors false): deploy "
                     f"them knowing a few % of model error can destabilise them (without "
                     f"--aggressive, design tunes within the floors)")
    # a loop that rings (a phase margin near 0: linear theory's steady state is never
    # reached in the record): Humboldt Bay's Hs 1.25 m, Tp 20.4 s, reactive, 22 kW predicted,
    # 1 kW simulated, phase margin 0.8 deg
    astray = [r for r in rows if r["predicted_power_W"] and isinstance(r["mean_power_W"], float)
              and not 0.5 <= r["mean_power_W"] / r["predicted_power_W"] <= 2.0]
    if astray:
        notes.append(f"{len(astray)} seas' simulated power is off linear theory's prediction by "
                     f"more than a factor of 2 (a loop that rings, or a law linear theory does "
                     f"not describe): " + ", ".join(
                         f"Hs {r['hs']:.3g} m Tp {r['tp']:.3g} s {r['mean_power_W'] / 1e3:.3g} "
                         f"kW against {r['predicted_power_W'] / 1e3:.3g} kW" for r in astray))
    beaten = [r for r in rows if r["percent_of_bound"] is not None
              and r["percent_of_bound"] > 101.0]
    if beaten:
        notes.append(f"{len(beaten)} seas absorb more than 101 % of their bound (linear theory "
                     f"does not hold there): " + ", ".join(
                         f"Hs {r['hs']:.3g} m Tp {r['tp']:.3g} s {r['percent_of_bound']:.1f} %"
                         for r in beaten))
    return notes


def _cases_where(ds, mask) -> list[dict]:
    """{hs, tp, seed, varied values..., reasons} of each case where `mask` holds."""
    out = []
    for index in zip(*np.nonzero(mask.values)):
        out.append({"hs": float(ds["hs"].values[index[0]]),
                    "tp": float(ds["tp"].values[index[0]]), "seed": int(index[1]),
                    **{d: float(ds[d].values[i]) for d, i in zip(ds["valid"].dims[2:], index[2:])},
                    "reasons": str(ds["invalid_reasons"].values[index])})
    return out


def _nonlinear_row(sea) -> dict:
    """--nonlinear invalid, one sea: its cases run on the nonlinear plant and, where any,
    their linear runs' mean power (W; INVALID, for comparison)."""
    escalated = int(sea["nonlinear_model"].sum())
    return {"nonlinear_cases": escalated,
            "linear_mean_power_W": _plain(sea["mean_power_W__linear"].mean("seed").values)
            if escalated else None}


def _mooring_loads(ds, k: int) -> dict:
    """MoorDyn moorings: sea k's design loads (N), the largest over fairleads and seeds."""
    return {load: _plain(ds[load].max("seed").isel(sea=k).values)
            for load in ("mooring_max_N", "mooring_mpm_3h_N") if load in ds}


def _plain(values):
    values = np.asarray(values, float)
    return float(values) if values.ndim == 0 else values.tolist()


def _import_statistics() -> None:
    """Import what the summary and the budget need (scipy.stats: 1-2 s) while workers run the
    cases, not after them."""
    import scipy.stats  # noqa: F401
