"""From a scene and measured files to an `Identification`: which parameters to fit (the scene's
[identify] table or NAME[=LO:HI] specs), which plant output each measured channel is, and the
flume runs loaded; what `mbcontrol identify`, the notebook and the benchmark share."""
from __future__ import annotations

import math

from ...errors import InputError
from . import extrapolation
from .problem import FitParameter, Identification


def fit_parameters(scene, plant_parameters: dict, specs=()) -> list[FitParameter]:
    """FitParameters from specs "NAME" or "NAME=LO:HI" (bounds from the scene's [identify]
    table when not given), or the whole table when specs is empty. The start is the plant's
    nominal value when inside the bounds, else their geometric (log) or plain middle."""
    chosen = {}
    if not specs:
        if not scene.identify:
            raise InputError(f"{scene.path}: no parameters to fit given and no [identify] "
                             f"table in the scene")
        chosen = dict(scene.identify)
    for spec in specs:
        name, _, bounds = spec.partition("=")
        _known(scene, plant_parameters, name)
        if bounds:
            try:
                lo, hi = (float(v) for v in bounds.split(":"))
            except ValueError:
                raise InputError(f"--fit {spec}: expected NAME=LO:HI with two numbers") from None
        elif name in scene.identify:
            lo, hi = scene.identify[name]
        else:
            raise InputError(f"--fit {name}: no bounds given and none in {scene.path}'s "
                             f"[identify] table; write --fit {name}=LO:HI")
        chosen[name] = (lo, hi)
    out = []
    for name, (lo, hi) in chosen.items():
        _known(scene, plant_parameters, name)
        if not lo < hi:
            raise InputError(f"--fit {name}: bounds {lo:g}:{hi:g}; expected LO < HI")
        log = lo > 0
        nominal = plant_parameters[name]
        initial = nominal if lo <= nominal <= hi and (nominal > 0 or not log) else (
            math.sqrt(lo * hi) if log else 0.5 * (lo + hi))
        out.append(FitParameter(name, float(initial), float(lo), float(hi), log=log))
    return out


def _known(scene, plant_parameters, name) -> None:
    if name not in plant_parameters:
        raise InputError(f"--fit {name}: not a parameter of {scene.name}; it has "
                         f"{', '.join(sorted(plant_parameters))}")


def channel_outputs(plant, runs) -> dict:
    """Measured channel -> the plant output of the same name, case aside (Roll -> roll)."""
    lower = {o.lower(): o for o in plant.outputs}
    out = {}
    for channel in sorted({c for r in runs for c in r.channels}):
        if channel.lower() not in lower:
            raise InputError(f"channel {channel!r} has no plant output of that name in "
                             f"{plant.name}; expected a joint named like it")
        out[channel] = lower[channel.lower()]
    return out


def flume_identification(model, files, *, calibration=None, fit=(), drop_bad: bool = False,
                         runs=None, drop_absent: bool | None = None,
                         **options) -> Identification:
    """An Identification of `model` (catalogue name or scene path) on flume files (naming
    SPPH[_R], see `flume`), or on `runs` already loaded. fit: NAME[=LO:HI] specs (default:
    the scene's [identify] table, with parameters the runs cannot see dropped with a warning;
    drop_absent=True drops them from given specs too, as calibration folds need);
    options: Identification's (cost, phase, params, dt, settle, ...)."""
    from ...plant import build_plant
    from ...scene import load_scene
    from .flume import load_runs
    scene = load_scene(model)
    if runs is None:
        runs = load_runs(files, calibration, drop_bad=drop_bad)
    full = build_plant(scene, hydro_corrections=True)
    parameters = fit_parameters(scene, dict(zip(full.parameters, full.p0)), list(fit))
    problem = Identification(scene.path, runs, parameters, outputs=channel_outputs(full, runs),
                             drop_absent=not fit if drop_absent is None else drop_absent,
                             **options)
    extrapolation.warn(problem, "fit")
    return problem


def prediction(problem: Identification, runs) -> Identification:
    """The same model and options on other runs, nothing to fit: evaluate it with
    `report.amplitude_rows(prediction, fitted_values)` to validate on runs the fit did not see
    (values of parameters its plants lack, e.g. of a blocked DOF, are ignored). Runs outside
    the fitted runs' frequency band, or above the radiation fit, warn (ExtrapolationWarning)
    and are flagged in the rows."""
    from ...plant import build_plant
    from ...scene import load_scene
    full = build_plant(load_scene(problem.scene), hydro_corrections=True)
    predicted = Identification(problem.scene, runs, [], outputs=channel_outputs(full, runs),
                               **problem.options)
    omegas = [r.omega for r in problem.runs]
    predicted.fitted_band = (min(omegas), max(omegas))   # what the identified values have seen
    extrapolation.warn(predicted, "validation")
    return predicted
