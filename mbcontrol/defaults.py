"""Every default of the toolbox in one place, documented, and overridable.

Like python-control's ``config.defaults``: a function whose argument is left out (``None``)
takes its value from here, so one setting changes every call that does not say otherwise.
The value of a key is, first match wins:

1. set in this process: ``defaults.set("sim.dt", 0.005)`` or ``with defaults.override(...)``;
2. the environment: ``MBCONTROL_SIM_DT=0.005`` (the key upper-cased, dots as underscores;
   the cache folder keeps its historical name ``MBCONTROL_CACHE``);
3. the built-in value below.

An explicit argument (or a CLI flag) always wins over all three. ``mbcontrol defaults``
lists every key with its value and where the value came from.
"""
from __future__ import annotations

import math
import os
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from .errors import InputError, UnknownName


@dataclass(frozen=True)
class Default:
    value: object
    unit: str           # "" when dimensionless or not a quantity
    doc: str
    kind: type = float  # how an environment value is read
    env: str = ""       # the environment variable, when not the key's own

    def variable(self, key: str) -> str:
        return self.env or "MBCONTROL_" + key.upper().replace(".", "_")


_REGISTRY: dict[str, Default] = {
    "cache.folder": Default(str(Path.home() / ".cache" / "mbcontrol"), "",
                            "BEM results, radiation fits and compiled code", str,
                            env="MBCONTROL_CACHE"),
    "log.quiet": Default(False, "", "hide status lines and progress bars (the CLI's -q)", bool,
                         env="MBCONTROL_QUIET"),
    "sim.dt": Default(0.01, "s", "time step of simulate() and simulate --dt"),
    "sim.method": Default("rk4", "", "integration method of simulate() (mbcontrol.sim.METHODS)",
                          str),
    "sim.rtol": Default(1e-8, "", "relative tolerance of the adaptive methods (cvodes, adams)"),
    "stats.min_periods": Default(10, "", "wave periods (a sea's peak periods) a result's "
                                         "statistics window must hold after the ramp and any "
                                         "warm-up, or the result is INVALID", int),
    "sweep.duration": Default(600.0, "s", "simulated time of each sweep case"),
    "sweep.dt": Default(0.05, "s", "time step of sweep cases"),
    "sweep.method": Default("rk4", "", "fixed-step method of sweep cases", str),
    "sweep.workers": Default(-1, "", "local Dask workers of a sweep: -1 one per core, "
                                     "0 serial in this process", int),
    "sweep.cluster": Default("auto", "", "a sweep's local Dask cluster: auto (only when it "
                                         "pays, timed) or always", str),
    "sweep.start": Default("forkserver", "", "how a sweep's local Dask workers start: "
                                             "forkserver (forks of one fresh interpreter that "
                                             "imported the code once), spawn (fresh "
                                             "interpreters) or fork (fastest; may hang a "
                                             "threaded process)", str),
    "compile.cc": Default("", "", "C compiler of the compiled simulation code (empty: gcc, "
                                  "else cc)", str, env="CC"),
    "dask.host": Default("127.0.0.1", "", "address local Dask clusters (sweeps, co-design) "
                                          "and their web server listen on", str),
    "identify.dt": Default(0.01, "s", "simulation step of identification runs"),
    "identify.method": Default("gauss-newton", "", "optimiser: gauss-newton or nelder-mead",
                               str),
    "identify.settle": Default(60.0, "s", "time each identification run is simulated from rest "
                                          "before its measured window"),
    "hydro.radiation_tol": Default(0.01, "", "radiation fit error of a scene that sets none "
                                             "([hydro] radiation_tol)"),
    "fidelity.tol": Default(0.01, "", "error a simplified model may add (fidelity auto)"),
    "design.gain_margin_min": Default(2.0, "", "least gain margin (factor on the gains) of a "
                                               "linear law design and export tune and ship "
                                               "(--aggressive: none)"),
    "design.phase_margin_min_deg": Default(30.0, "deg", "least phase margin of a linear law "
                                                        "design and export tune and ship "
                                                        "(--aggressive: none)"),
    # Result-shaping thresholds (issue 59): each was a module constant; same built-in values
    "validity.power_allowance": Default(0.10, "", "share above the power bound a result's mean "
                                                  "power may reach before it is INVALID"),
    "validity.energy_tolerance": Default(0.05, "", "energy balance error a valid result may "
                                                   "have, as a share of the excitation's "
                                                   "absolute work over the record"),
    "linearize.equilibrium_share": Default(1e-6, "", "residual acceleration linearize() accepts "
                                                     "at its point, as a share of g"),
    "mooring.mpm_hours": Default(3.0, "h", "sea-state length of a line tension's most probable "
                                           "maximum (mpm_3h_N)"),
    "mooring.slack_fraction": Default(0.02, "", "a line is slack below this share of its mean "
                                                "tension"),
    "sim.energy_margin": Default(2.0, "", "factor on the energy put in that a run's energy may "
                                          "not exceed (energy audit)"),
    "plant.imbalance_tol": Default(0.10, "", "weight against buoyancy at rest a scene may be "
                                             "off by (share of the weight) before it is "
                                             "refused"),
    "plant.equilibrium_warn": Default(1e-6, "", "load left at rest, as a share of the largest "
                                                "body weight, above which a warning is given"),
    "hydro.bem_asymmetry_tol": Default(1e-2, "", "reciprocity error of BEM data (scaled) "
                                                 "symmetrised with a warning; larger is refused"),
    "identify.alpha": Default(0.05, "", "miscoverage of calibrated identification intervals "
                                        "(0.05: 95 %)"),
    "identify.kappa": Default(0.3, "", "weight of the frequency slope in the calibration "
                                       "score's scale"),
    "identify.correlation_limit": Default(0.95, "", "parameter correlation above which an "
                                                    "identification warns"),
    "identify.condition_limit": Default(1e6, "", "condition number of the fit's information "
                                                 "matrix above which it warns"),
    "identify.structure_tie": Default(0.01, "", "cross-validation scores within this share of "
                                                "the best tie: the smaller structure wins"),
    "design.bound_tolerance": Default(0.01, "", "share by which a simulated power may exceed "
                                                "its bound before it is noted"),
    "design.max_harmonics": Default(25, "", "harmonics of the constrained power bound's QP",
                                    int),
    "design.settle_time_constants": Default(12, "", "slowest time constants a design's check "
                                                    "run settles before its window", int),
    "design.coulomb_share": Default(0.98, "", "share of the Coulomb limit a clipped damper "
                                              "fallback is taken to at most"),
    "fidelity.steps_per_period": Default(200, "", "fidelity auto's default step: the peak "
                                                  "period over this", int),
    "fidelity.signal_floor": Default(1e-3, "", "signals below this share of their unit "
                                               "class's largest RMS are not compared "
                                               "(fidelity auto)"),
    "fidelity.freeze_threshold": Default(1e-3, "", "excitation and response share below which "
                                                   "freeze = \"auto\" freezes a DOF"),
    "waves.breaking_steepness": Default(1 / 7, "", "wave steepness H/L refused as breaking"),
    "sweep.direction_step": Default(math.radians(1.0), "rad", "direction bins of a spread "
                                                              "sea's expected power"),
    "resource.min_hours_year": Default(24 * 120, "h", "valid hours a year needs to enter a "
                                                      "resource's per-year weights", int),
    "resource.min_hours_month": Default(24 * 7, "h", "valid hours a month needs to enter a "
                                                     "resource's per-month weights", int),
    "validity.angle_max": Default(math.radians(30.0), "rad", "roll and pitch (significant) "
                                                             "beyond which linear "
                                                             "hydrodynamics do not describe "
                                                             "a body"),
    "validity.draft_factor": Default(1.0, "", "relative heave limit in mean drafts (V / A_wp)"),
    "envelope.share": Default(0.9, "", "share of the validity limits a tuned setting's "
                                       "predicted significant motion is kept within; a "
                                       "predictive controller bounds every sample at half "
                                       "of it"),
    "design.rate_reversals_per_period": Default(5, "", "force reversals per peak period a "
                                                       "tuned law's rate limit allows "
                                                       "(rate_max = this x 2 force_max / Tp)",
                                                int),
}

_set: dict[str, object] = {}


def keys() -> list[str]:
    return sorted(_REGISTRY)


def _entry(key: str) -> Default:
    try:
        return _REGISTRY[key]
    except KeyError:
        raise UnknownName(f"unknown default {key!r}; expected one of {', '.join(keys())}") from None


def _read(key: str, entry: Default, text: str):
    name = entry.variable(key)
    try:
        if entry.kind is bool:
            lowered = text.strip().lower()
            if lowered in ("", "0", "false", "no", "off"):
                return False
            if lowered in ("1", "true", "yes", "on"):
                return True
            raise ValueError
        return entry.kind(text)
    except ValueError:
        raise InputError(f"environment variable {name}={text!r}: expected "
                         f"{'true or false' if entry.kind is bool else 'a ' + entry.kind.__name__}"
                         f" ({entry.doc})") from None


def get(key: str):
    """The value of default `key` (see the module's docstring for the order)."""
    entry = _entry(key)
    if key in _set:
        return _set[key]
    text = os.environ.get(entry.variable(key))
    if text is not None:
        return _read(key, entry, text)
    return entry.value


def resolve(key: str, value):
    """`value` unless it is None, else the default `key`: for arguments left out."""
    return get(key) if value is None else value


def source(key: str) -> str:
    """Where get(key) comes from: "set", the environment variable's name, or "built-in"."""
    entry = _entry(key)
    if key in _set:
        return "set"
    if entry.variable(key) in os.environ:
        return entry.variable(key)
    return "built-in"


def set(key: str, value) -> None:  # noqa: A001 (the registry's verb, as in control.config)
    """Set default `key` for this process (reset(key) undoes it)."""
    entry = _entry(key)
    if entry.kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if not isinstance(value, entry.kind):
        raise TypeError(f"default {key!r}: expected a {entry.kind.__name__}, got {value!r}")
    _set[key] = value


def reset(key: str | None = None) -> None:
    """Forget what set() changed: one key, or all."""
    if key is None:
        _set.clear()
    else:
        _entry(key)
        _set.pop(key, None)


@contextmanager
def override(**values):
    """Set defaults for a block: ``with override(sim_dt=0.005):`` (dots as underscores)."""
    previous = dict(_set)
    try:
        for name, value in values.items():
            key = name.replace("_", ".", 1)
            set(key, value)
        yield
    finally:
        _set.clear()
        _set.update(previous)


def table() -> list[dict]:
    """Every default: key, value, unit, source, environment variable and description."""
    return [{"key": k, "value": get(k), "unit": _REGISTRY[k].unit, "source": source(k),
             "env": _REGISTRY[k].variable(k), "doc": _REGISTRY[k].doc} for k in keys()]
