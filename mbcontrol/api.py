"""The front door: what `import mbcontrol as mbc` gives beyond the stages' own functions.

`load` makes a plant from whatever names a model, `simulate` runs it (by model name, with a
controller by registry name) and returns one `mbcontrol.Result`, checked; `simulate_batch`
and `simulate_convolution` are its siblings returning the same type; `regular` and `jonswap`
make the waves. A driver of the whole flow, as the command line is: it may import every
stage, none imports it (tests/test_layout.py). Heavy stages are imported inside the
functions, so that `import mbcontrol` stays cheap.
"""
from __future__ import annotations

import inspect
import math
import time
import warnings
from pathlib import Path

import numpy as np

from .errors import InputError
from .waves import irregular

SEA_DURATION_S = 600.0      # a sea's repeat period by default: the CLI's and the sweeps' record
REGULAR_PERIODS = 30        # a regular wave's default run: 30 periods (the CLI's), 10 of them
STILL_WATER_S = 60.0        # for the statistics window after the ramp and the transient


def jonswap(hs: float, tp: float, gamma: float = 3.3, *, seed: int = 0,
            duration: float = SEA_DURATION_S, **options):
    """A JONSWAP sea of significant wave height hs (m) and peak period tp (s), peak
    enhancement gamma (1: Pierson-Moskowitz), random phases from `seed`.

    A sea is a sum of components on a uniform frequency grid d_omega = 2 pi / T_repeat, and
    the grid needs a length: T_repeat = max(duration, 20 tp) s, 600 s by default (so a run
    of up to `duration` never repeats; `mbcontrol.simulate` runs one repeat period unless
    told otherwise). Components span 0.3..4 times the peak frequency; `data_band` (rad/s)
    cuts them to a model's hydro data, as the command line does. options: those of
    `mbcontrol.waves.irregular` (band, direction (rad), ramp_time (s; 2 tp), amplitudes,
    spreading, data_band).
    """
    return irregular(hs, tp, gamma=gamma, seed=seed, duration=duration, kind="jonswap",
                     **options)


def load(model, parameters: dict | None = None, *, fidelity=None, hydro=None):
    """The process plant (`mbcontrol.plant.ProcessPlant`) of `model`: a catalogue name
    (`list_models()`), a scene file's path, a `Scene`, or a plant (returned as it is).

    parameters: values of the scene's [parameters] table (e.g. {"N": 8} for barge_chain);
    fidelity: a `mbcontrol.Fidelity` (simplified models); hydro: a HydroModel instead of the
    scene's hydro file. The Scene alone (no hydrodynamics) is `mbcontrol.load_scene`.
    """
    from .plant import ProcessPlant, build_plant
    from .scene import Scene, load_scene
    if isinstance(model, ProcessPlant):
        if parameters or fidelity is not None or hydro is not None:
            raise InputError(f"load: {model.name} is a plant already; parameters, fidelity and "
                             f"hydro apply to a scene or a model name")
        return model
    if isinstance(model, (str, Path)):
        model = load_scene(model, parameters)
    elif not isinstance(model, Scene):
        raise InputError(f"load: expected a catalogue name, a scene file's path, a Scene or a "
                         f"ProcessPlant, got {type(model).__name__}")
    elif parameters:
        raise InputError("load: a Scene's [parameters] are set when it is read: "
                         "load_scene(path, parameters)")
    return build_plant(model, hydro, fidelity=fidelity)


def default_duration(wave) -> float:
    """The run length `simulate` uses when none is given (s): still water 60 s, a regular
    wave 30 periods, a sea its repeat period (2 pi / d_omega), a record its own length."""
    if wave is None:
        return STILL_WATER_S
    if wave.kind == "regular":
        return REGULAR_PERIODS * float(wave.period)
    if wave.settings.get("duration_s"):
        return float(wave.settings["duration_s"])
    return 2 * math.pi / wave.d_omega if wave.d_omega else SEA_DURATION_S


def controller_for(controller, settings: dict | None, wave=None):
    """A Controller from a registry name and its settings (a predictive law that takes a
    `wave` is handed the simulated one, as the CLI does), or the instance given."""
    if controller is None or not isinstance(controller, str):
        if settings:
            raise InputError("simulate: settings go with a controller's registry name "
                             f"(e.g. controller='passive', settings={{'damping': 6e5}}); "
                             f"got settings with {type(controller).__name__}")
        return controller
    from .controllers import REGISTRY, make
    settings = dict(settings or {})
    cls = REGISTRY.get(controller)
    if wave is not None and cls is not None and "wave" in inspect.signature(cls).parameters:
        settings.setdefault("wave", wave)
    return make(controller, **settings)


def simulate(model, wave=None, controller=None, settings: dict | None = None, *,
             duration: float | None = None, dt: float | None = None, method: str | None = None,
             params: dict | None = None, x0=None, rtol: float | None = None,
             progress: bool = False):
    """Simulate `model` in `wave` with `controller`; a checked `mbcontrol.Result`.

    model: a catalogue name, a scene path, a Scene or a plant (`load`); wave: a
    `mbcontrol.waves.Wave` (`regular`, `jonswap`, ...) or None (still water); controller: a
    registry name (`mbcontrol.controllers.REGISTRY`) with `settings` its keyword settings, a
    Controller instance, or None (the scene's own PTO laws). duration (s): see
    `default_duration`; dt (s), method (a name in mbcontrol.sim.METHODS), rtol: the defaults
    "sim.dt", "sim.method", "sim.rtol" of `mbcontrol.defaults`; params: plant parameter
    overrides by name (SI); x0: the initial state (default: rest).

    The run is checked against physics (`mbcontrol.analysis.validity`): `result.valid`,
    `result.invalid_reasons`, and a RuntimeWarning when invalid. A record that ends before
    its statistics window starts (inside the wave's ramp) holds no statistics: InputError,
    naming the shortest duration that works. The bare integrator, a Dataset without checks,
    is `mbcontrol.sim.simulate`.
    """
    from .analysis import Result
    from .sim import simulate as integrate
    plant = load(model)
    duration = default_duration(wave) if duration is None else duration
    law = controller_for(controller, settings, wave)
    ds = integrate(plant, wave, duration=duration, dt=dt, controller=law, method=method,
                   params=params, x0=x0, rtol=rtol, progress=progress)
    return _checked(Result.from_run(ds, plant))     # analysis.validity: the checks


def _checked(result):
    """The result, with a RuntimeWarning naming its reasons when it failed its checks (as
    `mbcontrol.analysis.simulate_checked` warns)."""
    if not result.valid:
        warnings.warn(f"{result.summary['model']}: the result failed its physics checks: "
                      + "; ".join(result.invalid_reasons), RuntimeWarning, stacklevel=3)
    return result


def simulate_batch(model, waves=None, params=None, *, duration: float | None = None,
                   dt: float | None = None, method: str | None = None) -> list:
    """Many cases of `model` (open loop, the scene's PTO laws) stepped together in one
    compiled call (`mbcontrol.sim.simulate_batch`); one checked `Result` per case.

    waves: a list of Waves (None: still water) or one for all; params: a list of dicts of
    parameter overrides, or one dict or None for all; the longer list sets the number of
    cases. duration (s): `default_duration` of the first wave; dt, method: the defaults
    "sim.dt", "sim.method" (a fixed-step method).
    """
    from . import defaults
    from .analysis import Result
    from .sim import run_dataset
    from .sim import simulate_batch as batch
    plant = load(model)
    dt, method = defaults.resolve("sim.dt", dt), defaults.resolve("sim.method", method)
    cases_waves = waves if isinstance(waves, (list, tuple)) else [waves]
    cases_params = params if isinstance(params, (list, tuple)) else [params]
    if duration is None:
        duration = default_duration(cases_waves[0])
    ds = batch(plant, list(cases_waves), list(cases_params), duration=duration, dt=dt,
               method=method)
    t = ds["time"].values
    out = []
    for c in range(ds.sizes["case"]):
        wave = cases_waves[c if len(cases_waves) > 1 else 0]
        one = ds.isel(case=c)
        Y = np.column_stack([one[name].values for name in plant.outputs])
        W = plant.excitation(wave, t) if wave is not None \
            else np.zeros((t.size, len(plant.disturbances)))
        eta = wave.elevation(t) if wave is not None else np.zeros_like(t)
        record = run_dataset(plant, t, one["state"].values, np.zeros((t.size, len(plant.inputs))),
                             W, Y, eta, wave=wave, controller=None, method=method, dt=dt,
                             p=one["parameters"].values, wall=ds.attrs["wall_time_s"])
        out.append(_checked(Result.from_run(record, plant)))
    return out


def simulate_convolution(model, wave, *, duration: float | None = None,
                         dt: float | None = None, params: dict | None = None):
    """`model` in `wave` with radiation by direct Cummins convolution of the BEM data, no
    radiation state space (`mbcontrol.sim.simulate_convolution`: a reference, O(n^2), the
    scene's PTO laws); a checked `Result` whose states are not recorded (`state_names` is
    empty). duration (s): `default_duration`; dt (s): "sim.dt".
    """
    from . import defaults
    from .analysis import Result
    from .scene import Scene
    from .sim import run_dataset
    from .sim import simulate_convolution as convolution
    dt = defaults.resolve("sim.dt", dt)
    duration = default_duration(wave) if duration is None else duration
    scene = model if isinstance(model, Scene) else load(model).scene
    start = time.perf_counter()
    t, Y, plant = convolution(scene, wave, duration=duration, dt=dt, params=params)
    wall = time.perf_counter() - start
    W = plant.excitation(wave, t) if wave is not None \
        else np.zeros((t.size, len(plant.disturbances)))
    eta = wave.elevation(t) if wave is not None else np.zeros_like(t)
    p = plant.params(**params) if params else plant.p0
    record = run_dataset(plant, t, None, np.zeros((t.size, len(plant.inputs))), W, Y, eta,
                         wave=wave, controller=None, method="convolution", dt=dt, p=p,
                         wall=wall)
    return _checked(Result.from_run(record, plant, states=False))
