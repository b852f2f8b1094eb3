"""One case of a sweep: its plant (built once per sweep run: `PlantCache`), its wave, its controller (tuned for
its sea with --design), its run and its record. With ``--nonlinear invalid`` a sea whose linear
run leaves the linear range is run again on the nonlinear plant (the scene with
[hydro] hydrostatics = froude_krylov = "nonlinear"), with the same controller: the controller
designed on the linear model, checked on the model that covers large motions."""
from __future__ import annotations

import math
import time

# The plants a run keeps, most recent last: cases run a plant at a time (`groups`), so a few
# suffice, and a sweep over scene parameters (each value a plant with its compiled code) does
# not keep every one it has passed
PLANTS_KEPT = 4


class PlantCache:
    """The plants one sweep run has built, and its last light run: owned by the caller (the
    sweep makes one per run; a Dask worker holds one per run in `worker_plants.RunPlants`),
    never kept between runs, so a scene edited on disk between two sweeps is built afresh.

    plant(model, scene_params, nonlinear) builds a plant once while it is among the last
    `kept` used; keep(...) gives it one the caller has already built. hold(run) keeps a light
    run until the next one has its arrays: freed at once, a run's records (35 MB for rm3 over
    an hour) top glibc's heap and go back to the kernel, and the next case faults them in
    again page by page (rm3: 4,300 page faults, 12 ms of 70 a case)."""

    def __init__(self, kept: int = PLANTS_KEPT):
        self.kept = kept
        self._plants: dict = {}
        self._last_run = None

    @staticmethod
    def _key(model: str, scene_params: tuple, nonlinear: bool) -> tuple:
        return (model, scene_params) + (("nonlinear",) if nonlinear else ())

    def __len__(self) -> int:
        return len(self._plants)

    def plant(self, model: str, scene_params: tuple, nonlinear: bool = False):
        """The plant of a model and sorted scene-parameter items (with ``nonlinear``: the
        scene's hydro bodies under the nonlinear pressure,
        `mbcontrol.plant.with_nonlinear_pressure`)."""
        key = self._key(model, scene_params, nonlinear)
        if key in self._plants:
            self._plants[key] = self._plants.pop(key)          # most recent last
            return self._plants[key]
        from ...plant import build_plant, with_nonlinear_pressure
        from ...scene import load_scene
        scene = load_scene(model, dict(scene_params) or None)
        return self.keep(model, scene_params,
                         build_plant(with_nonlinear_pressure(scene) if nonlinear else scene),
                         nonlinear)

    def keep(self, model: str, scene_params: tuple, plant, nonlinear: bool = False):
        """Remember `plant` as the one of (model, sorted scene-parameter items[, nonlinear]);
        returns it."""
        key = self._key(model, scene_params, nonlinear)
        self._plants.pop(key, None)
        self._plants[key] = plant
        while len(self._plants) > self.kept:
            self._plants.pop(next(iter(self._plants)))
        return plant

    def hold(self, run) -> None:
        """Keep `run` (a light run's arrays) until the next one; the previous is let go now."""
        self._last_run = run


def run_case(case, plants: PlantCache | None = None) -> dict:
    """Simulate one case in closed loop and measure it: {"case": key, "metrics": {name:
    value} (per PTO `<pto>__<metric>` as `mbcontrol.analysis.metrics.pto_metrics`, and the
    totals mean_power_W, mean_electrical_power_W), "valid", "invalid_reasons",
    "wall_time_s"} (`case_record`); a case whose run raises gives a `failed_record` instead.
    A case without a controller on a fixed-step method runs
    through `mbcontrol.sim.light.simulate_arrays` (the arrays its metrics need, no Dataset),
    any other through `simulate`; both give the same record to rounding.

    case.nonlinear: "scene" runs the scene as it is; "always" the nonlinear plant; "invalid"
    the linear one, then, where that run leaves the linear range (an INVALID reason whose
    remedy is the nonlinear model), the nonlinear plant with the same controller: its record
    is the case's, with "model": "nonlinear" and the linear run's under "linear". A case of a
    measured record (case.record, --records) runs in that record's wave (`records.record_wave`).
    plants: the run's PlantCache (None: a new one, the plant built for this case alone)."""
    plants = PlantCache() if plants is None else plants
    params, scene_params, settings = case.resolved()
    scene_key = tuple(sorted(scene_params.items()))
    plant = plants.plant(case.model, scene_key, case.nonlinear == "always")
    direction = None if case.direction_deg is None else math.radians(case.direction_deg)
    if case.record:                       # a measured record (--records): its own wave
        from .records import record_wave
        wave = record_wave(plant, case)
    else:
        wave = sea_wave(plant, case.sea, case.duration, seed=case.seed, direction=direction,
                        amplitudes=case.amplitudes)
    designed, law = None, case.controller
    start = time.perf_counter()
    if case.design:      # tuned for this sea; settings given with --set take precedence
        from mbcontrol.studies.design import NoLawForSea, design_for_sea
        try:
            designed = design_for_sea(plant, wave, case.controller, dt=case.dt,
                                      robust=case.robust)
        except NoLawForSea as exc:      # the device cannot serve the sea: zero, with why
            return no_law_record(case, exc, start)
        except Exception as exc:   # noqa: BLE001 - a sea the tuner cannot serve is a result
            return failed_record(case, exc, start)
        law = designed["controller"]
        if law != case.controller:     # fell back to another law: only what it takes
            settings = {k: v for k, v in settings.items() if k in designed["settings"]}
        settings = {**designed["settings"], **settings}
    record = _run(case, (plant, plants), wave, settings, params, start, law)
    if case.nonlinear == "invalid":    # every record says which model made it
        record = _escalated(case, record, (scene_key, plants), wave, settings, params, law) \
            if _left_linear_range(record) else {**record, "model": "linear"}
    if designed is not None:
        record["design"] = designed
    return record


def _run(case, where: tuple, wave, settings: dict, params: dict, start: float,
         law: str | None = None) -> dict:
    """Run `case` on where = (plant, the run's PlantCache) with the controller `law` (default
    case.controller: --design may have fallen back to another) made from `settings`; its
    record (failed_record if it raises)."""
    import inspect

    from mbcontrol.controllers import REGISTRY, make

    from ...sim import can_run_light, simulate, simulate_arrays
    plant, plants = where
    controller, law = None, law or case.controller
    if law:
        cls = REGISTRY[law]
        if "wave" in inspect.signature(cls).parameters:
            settings = {"wave": wave, **settings}
        controller = make(law, **settings)
    try:
        if can_run_light(plant, controller, case.method):
            run = simulate_arrays(plant, wave, duration=case.duration, dt=case.dt,
                                  method=case.method, params=params or None)
            plants.hold(run)     # the previous run is let go only now (PlantCache.hold)
        else:
            run = simulate(plant, wave, duration=case.duration, dt=case.dt,
                           controller=controller, method=case.method, params=params or None)
        return case_record(case, plant, wave, run, start)
    except Exception as exc:       # noqa: BLE001 - a case that fails is a result (see below)
        return failed_record(case, exc, start)


def _left_linear_range(record: dict) -> bool:
    """Whether a record is INVALID because its motions left the linear range."""
    from ...analysis import left_linear_range
    return left_linear_range(record["invalid_reasons"])


def _escalated(case, linear: dict, key: tuple, wave, settings, params,
               law: str | None = None) -> dict:
    """The case run again on the nonlinear plant (key = (sorted scene-parameter items, the
    run's PlantCache)); the linear record under "linear". A nonlinear run that cannot be made
    keeps the linear record, with the reason added."""
    scene_key, plants = key
    summary = {k: linear[k] for k in ("metrics", "valid", "invalid_reasons", "wall_time_s")}
    start = time.perf_counter()
    try:
        plant = plants.plant(case.model, scene_key, True)
    except Exception as exc:       # noqa: BLE001 - reported in the record, as a failed run
        record = failed_record(case, exc, start)
    else:
        record = _run(case, (plant, plants), wave, settings, params, start, law)
    if record.get("failed"):
        return {**linear, "model": "linear", "invalid_reasons": linear["invalid_reasons"] + [
            f"the nonlinear plant could not run this sea ({record['failure']})"]}
    return {**record, "model": "nonlinear", "linear": summary}


def sea_wave(plant, sea, duration: float, *, seed: int = 0, direction: float | None = None,
             amplitudes: str = "deterministic"):
    """The wave a case of `sea` runs in: JONSWAP cut to the hydro data's band, seeded; its
    direction `direction` (rad, --vary direction), else the sea's own (a seas file's
    column), else the data's one heading, or 0. A sea with a spread is short-crested: its
    spreading about that direction (`directional.sea_spreading`), one direction per
    component."""
    from ... import waves
    from .directional import sea_spreading
    headings = plant.hydro.data["wave_direction"].values
    omega = plant.hydro.omega
    if direction is None and math.isfinite(sea.direction):
        direction = sea.direction
    if direction is None:
        direction = float(headings[0]) if len(headings) == 1 else 0.0
    return waves.irregular(sea.hs, sea.tp, gamma=sea.gamma, seed=seed, duration=duration,
                           data_band=(float(omega[0]), float(omega[-1])), direction=direction,
                           amplitudes=amplitudes, spreading=sea_spreading(plant, sea, direction))


def failed_record(case, exc: BaseException, start: float) -> dict:
    """The record of a case whose run raised (a divergence, a solver that gave up, ...): no
    metrics, not valid, `failed` with the error's type and message, so one bad sea neither
    stops the sweep nor loses the others, and is never averaged. It is stored like any
    record: the same case fails the same way again, so a resumed sweep does not rerun it."""
    reason = f"{type(exc).__name__}: {exc}"
    return {"case": case.key, "metrics": {}, "valid": False, "failed": True,
            "failure": reason, "invalid_reasons": [f"run failed ({reason})"],
            "wall_time_s": time.perf_counter() - start}


def no_law_record(case, exc: BaseException, start: float) -> dict:
    """The record of a --design case whose sea no law serves within the PTO's limits
    (studies.design.NoLawForSea: the device's survival mode): not run, no metrics, not valid
    and not failed, no_law true, the reason in invalid_reasons and under design (fell_back
    true, to null), so the sweep counts its energy as zero and says why."""
    from mbcontrol.studies.design import no_law_design
    reason = f"no law within the PTO's limits serves this sea (survival, counted as zero): {exc}"
    return {"case": case.key, "metrics": {}, "valid": False, "failed": False, "no_law": True,
            "invalid_reasons": [reason], "design": no_law_design(exc, case.controller),
            "wall_time_s": time.perf_counter() - start}


def mooring_metrics(run) -> dict:
    """A MoorDyn run's line loads over its statistics window (N): per line end
    "<mooring>__line<k>__<end>_{max,mpm_3h}_N", and the case's design loads, the largest over
    every fairlead: "mooring_max_N" (the record's) and "mooring_mpm_3h_N" (its 3-hour most
    probable maximum, mbcontrol.analysis.mooring_stats)."""
    from ...analysis import analysis_window, mooring_summary
    if not any(str(name).endswith("_tension") for name in getattr(run, "data_vars", ())):
        return {}
    out, fairleads = {}, []
    for mooring, lines in mooring_summary(run, analysis_window(run)).items():
        for line, ends in lines.items():
            for end, stats in ends.items():
                for key in ("max_N", "mpm_3h_N"):
                    if stats[key] is not None:
                        out[f"{mooring}__{line}__{end}_{key}"] = float(stats[key])
            fairleads.append(ends["fairlead"])
    out["mooring_max_N"] = max(s["max_N"] for s in fairleads)
    mpm = [s["mpm_3h_N"] for s in fairleads if s["mpm_3h_N"] is not None]
    if mpm:
        out["mooring_mpm_3h_N"] = max(mpm)
    return out


def case_record(case, plant, wave, run, start: float) -> dict:
    """A case's record from its run: `run` is a Dataset from `simulate` or a Run from
    `simulate_arrays` (both read as run[name].values and run.attrs), `start` the
    perf_counter at the start of its simulation. The one place a record is made: metrics
    (every numeric entry of `pto_metrics` per PTO, `<pto>__<key>`, and the totals), the
    validity verdict (`mbcontrol.analysis.validity.assess` on the run and its wave)."""
    from ...analysis import pto_metrics
    from ...analysis import assess
    from ...results import jsonable
    ptos = {pto.name: jsonable(pto_metrics(run, pto)) for pto in plant.scene.ptos}
    metrics = {}
    for pto, m in ptos.items():
        for k, v in m.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                metrics[f"{pto}__{k}"] = float(v)
    metrics["mean_power_W"] = sum(m["mean_power_W"] for m in ptos.values())
    metrics["mean_electrical_power_W"] = sum(m["mean_electrical_power_W"] for m in ptos.values())
    metrics.update(mooring_metrics(run))
    verdict = assess(run, plant, wave, mean_power_W=metrics["mean_power_W"])
    return {"case": case.key, "metrics": metrics, "valid": verdict["valid"],
            "invalid_reasons": verdict["invalid_reasons"],
            "wall_time_s": time.perf_counter() - start}


