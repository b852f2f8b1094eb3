"""Controller design in one call: tune by name, check the loop, bound it, simulate it, score it.

`design(plant, wave, name)` answers four questions about controller `name` in `wave`:

1. its parameters, under the names the controller takes (`make(name, **parameters)` rebuilds
   it, so `mbcontrol simulate MODEL --controller NAME --set k=v ...` re-runs it), tuned by the
   tuner of its module: passive `optimal_damping`, reactive `reactive_tuning`, latching
   `optimal_latch_time`, declutching `optimal_declutch`, mpc none (a horizon of one wave
   period in 40 steps, its causal AR forecast - the wave only sets its Kalman wave model and
   warm-up damper -, the PTO's limits, or its default soft stroke limit where the scene sets
   none);
2. what linear theory predicts it absorbs (W; passive and reactive only: the frequency-domain
   solution straight from the BEM data), and for the linear laws their stability margins on
   the linearised plant (controllers.margins);
3. what any controller could absorb (mbcontrol.analysis.bounds): the complex-conjugate bound and the
   pseudo-spectral bound under the PTO's force and stroke limits (in a regular wave with the
   force's harmonics inside the hydro data's band: a saturating or switching controller's
   force is not sinusoidal; in a sea on the sea's own frequency grid);
4. what the nonlinear plant does in closed loop (mbcontrol.sim.simulate), scored by
   mbcontrol.analysis.metrics over its analysis window (last 10 periods of a regular wave, after the
   ramp in a sea), and its share of the bounds.

Limits: with limits=True the scene PTO's finite force_max (N or N m) and stroke_max (m or
rad) go to the tuners that take them (constrained tuning: predicted peaks within the limits),
and the controller's own limits (the force saturation of passive and reactive, an MPC's force
and stroke limits) are set to the scene's, explicitly; limits=False tunes the unconstrained
linear optimum (e.g. complex-conjugate control) with no controller limits (inf), and the
scene's limits appear only in the metrics (violations) and the constrained bound. A PTO
efficiency below 1 goes to the tuners that take one (reactive: tuned for electrical power).

Simulation defaults, and why: a regular wave runs 30 periods (as `mbcontrol simulate`),
longer when the linear closed loop's slowest pole needs more than 12 time constants after the
ramp to settle before the 10-period window; a sea runs one repeat period (2 pi / d_omega, its
whole record, no repeats). dt = T / 1000 (T the period or peak period): the controller's
command is held over each step, and a held spring -k x lags dt / 2 on average, adding a
damping |k| dt / 2; for reactive control of the sphere that is 5.6 % of its damping at T / 1000
(power within 0.06 % of the bound) and 11 % at T / 500 (-0.16 %). A controller with its own
period gets the largest dt <= that which divides its period.
"""
from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, field

import numpy as np

from mbcontrol.errors import SimulationError
from mbcontrol.results import jsonable

from . import REGISTRY, make

# above this many wave components the pseudo-spectral QP is skipped unless bounds="full": its
# solve time grows like n^3 (bounds.pseudo_spectral_bound: 0.6 s at 75, 12-25 s at 278)
MAX_BOUND_COMPONENTS = 150
# the tuned parameters of each controller (the contract of make(name, **parameters))
CONTRACT = {"passive": ("damping",), "reactive": ("damping", "stiffness"),
            "latching": ("damping", "latch_time"), "declutching": ("damping", "declutch_time"),
            "mpc": ("horizon_s", "dt_s", "force_max", "stroke_max", "rate_max"),
            "nmpc": ("horizon_s", "dt_s", "force_max", "stroke_max", "rate_max")}
# MPC's default force-rate limit (with a force limit): a full reversal, -F_max to +F_max, takes
# a fifth of the wave period at the least; a real drive cannot switch within a few samples
RATE_REVERSALS_PER_PERIOD = 5
MAX_HARMONICS = 25            # the constrained bound's QP stays < 0.1 s (0.07 s at 15)
SETTLE_TIME_CONSTANTS = 12      # e^-12 = 6e-6: the start-up transient left in the window


@dataclass
class DesignResult:
    """What `design` found. Powers in W (absorbed > 0); see the module docstring.

    parameters: make(name, **parameters) rebuilds the controller (the contract names; with
    the controller's own force_max / stroke_max where it takes them, inf: none, null in
    JSON, `--set force_max=inf`); predicted_power_W: linear theory (None for
    switching and predictive control); bound: complex_conjugate_W, constrained_W (None with
    constrained_reason when skipped or infeasible), force_max, stroke_max; metrics:
    metrics.pto_metrics of the designed PTO in closed loop (None if not simulated);
    percent_of_bound: 100 x simulated power / each bound; margins: controllers.margins.Margins
    (passive and reactive); tuner: what tuned it and what it reported; simulation: duration_s,
    dt_s and the full `mbcontrol simulate --json` summary; warnings: what the reader should
    know (an unstable loop, a tuner without constrained tuning, ...).
    """
    name: str
    pto: str
    parameters: dict
    predicted_power_W: float | None
    bound: dict
    metrics: dict | None
    percent_of_bound: dict
    margins: object | None
    tuner: dict
    simulation: dict | None
    warnings: list = field(default_factory=list)
    dataset: object = field(default=None, repr=False)     # the closed-loop run (xarray)

    @property
    def valid(self) -> bool | None:
        """Did the closed-loop result pass its physics checks (None: not simulated)?"""
        return None if self.simulation is None else self.simulation["summary"]["valid"]

    @property
    def invalid_reasons(self) -> list:
        return [] if self.simulation is None else self.simulation["summary"]["invalid_reasons"]

    @property
    def stable(self) -> bool | None:
        """The linear closed loop's verdict (None where there is no linear loop)."""
        return None if self.margins is None else self.margins.stable

    def to_dict(self) -> dict:
        """JSON-ready (json.dumps(..., allow_nan=False) works): inf and nan become None."""
        out = {"controller": self.name, "pto": self.pto, "valid": self.valid,
               "invalid_reasons": self.invalid_reasons, "parameters": self.parameters,
               "predicted_power_W": self.predicted_power_W, "bound": self.bound,
               "metrics": self.metrics, "percent_of_bound": self.percent_of_bound,
               "margins": None if self.margins is None else self.margins.to_dict(),
               "tuner": self.tuner, "simulation": self.simulation, "warnings": self.warnings}
        return jsonable(out)


def design(plant, wave, name: str, *, pto: str | None = None, simulate_s: float | None = None,
           dt: float | None = None, bounds: bool | str = True, limits: bool = True,
           model_params: dict | None = None) -> DesignResult:
    """Tune controller `name` for `wave`, check, bound, simulate and score it.

    plant: a ProcessPlant; wave: mbcontrol.waves.Wave (regular or a sea); name: a REGISTRY
    name (passive, reactive, latching, declutching, mpc). pto: the PTO tuned and scored
    (default the first); the controller applies the same setting to every PTO, as --set does.
    simulate_s, dt: closed-loop simulation length and step (s; defaults in the module
    docstring). bounds: True (complex-conjugate, and pseudo-spectral unless the sea has more
    than MAX_BOUND_COMPONENTS components), "full" (always both), False (none). limits: tune to
    the PTO's force and stroke limits (see the module docstring). model_params: parameter
    overrides of the model the tuner sees, for model-error studies: the margins and the
    simulation use the plant as it is. An unstable linear loop is not simulated (it would
    diverge), and a simulation that fails (SimulationError) is reported, not raised: the
    result says so in margins and warnings, with metrics None.

    Raises ValueError naming the controller when it is unknown or its tuner cannot apply
    (no wave, latching in a sea, latching in waves shorter than the natural period, ...).
    """
    if name not in REGISTRY:
        raise ValueError(f"design: unknown controller {name!r}; expected one of "
                         f"{', '.join(REGISTRY)}")
    if wave is None:
        raise ValueError(f"design {name!r}: needs a wave to tune for")
    pto_obj = _pto(plant, pto)
    limit_values = {"force_max": float(pto_obj.force_max), "stroke_max": float(pto_obj.stroke_max)}
    period = float(wave.period)
    default_dt = dt is None
    dt = period / 1000 if default_dt else float(dt)
    notes: list[str] = []

    try:
        parameters, predicted, tuner, extra = _tune(plant, wave, name, pto_obj, limits,
                                                    model_params, notes)
    except ValueError as exc:
        raise ValueError(f"design {name!r}: {exc}") from None
    controller = make(name, **parameters, **extra)

    margins = None
    if name in ("passive", "reactive"):
        from .margins import loop_margins
        gains = {k: parameters[k] for k in CONTRACT[name]}
        # the controller applies these gains to every PTO: close the other loops as well
        others = {f"{p.name}__{k}": v for p in plant.scene.ptos if p.name != pto_obj.name
                  for k, v in gains.items()}
        margins = loop_margins(plant, gains, pto=pto_obj.name, params=others or None)
        if not margins.stable:
            notes.append(f"{name}: the closed loop is unstable on the plant, so it was not "
                         f"simulated. {margins.message}")

    bound = _bounds(plant, wave, pto_obj.name, limit_values, bounds)

    metrics = simulation = ds = None
    percent = {"complex_conjugate": None, "constrained": None}
    if margins is None or margins.stable:
        from mbcontrol.analysis import pto_metrics, summary
        from mbcontrol.sim import simulate
        duration = simulate_s if simulate_s is not None else _duration(wave, margins)
        if default_dt and getattr(controller, "period", None):
            dt = controller.period / math.ceil(controller.period / dt - 1e-9)
        if wave.omega.size == 1 and duration < wave.ramp_time + 10 * period:
            notes.append(f"{duration:.4g} s is shorter than the ramp ({wave.ramp_time:.4g} s) "
                         f"plus the 10-period metrics window: the metrics include the start-up")
        try:
            ds = simulate(plant, wave, duration=duration, dt=dt, controller=controller)
        except SimulationError as exc:     # e.g. a loop stable only when linearised
            notes.append(f"{name}: the closed-loop simulation failed: {exc}")
        else:
            metrics = pto_metrics(ds, pto_obj)
            simulation = {"duration_s": float(duration), "dt_s": float(dt),
                          "summary": summary(ds, plant)}
            if not simulation["summary"]["valid"]:
                notes.append("the closed-loop result is INVALID: "
                             + "; ".join(simulation["summary"]["invalid_reasons"]))
            power = metrics["mean_power_W"]
            for key, ref in (("complex_conjugate", bound.get("complex_conjugate_W")),
                             ("constrained", bound.get("constrained_W"))):
                percent[key] = 100 * power / ref if ref else None
    return DesignResult(name, pto_obj.name, parameters, predicted, bound, metrics, percent,
                        margins, tuner, simulation, notes, ds)


def _pto(plant, pto):
    ptos = {p.name: p for p in plant.scene.ptos}
    if not ptos:
        raise ValueError(f"design: {plant.name} has no PTO to control")
    if pto is None:
        return plant.scene.ptos[0]
    if pto not in ptos:
        raise ValueError(f"design: {plant.name} has no PTO {pto!r}; PTOs are "
                         f"{', '.join(ptos)}")
    return ptos[pto]


def _accepts(func, keyword: str) -> bool:
    try:
        return keyword in inspect.signature(func).parameters
    except (TypeError, ValueError):
        return False


def _limit_kwargs(func, finite: dict, what: str, notes: list) -> dict:
    """The finite limits `func` takes; a note for each one it does not."""
    taken = {k: v for k, v in finite.items() if _accepts(func, k)}
    missing = sorted(set(finite) - set(taken))
    if missing:
        notes.append(f"{what} does not take {', '.join(missing)}: tuned without "
                     f"{'that limit' if len(missing) == 1 else 'those limits'}")
    return taken


def _tune(plant, wave, name, pto_obj, limits, model_params, notes):
    """(parameters, predicted W or None, tuner info, extra controller settings)."""
    cls = REGISTRY[name]
    pto = pto_obj.name
    scene = {"force_max": float(pto_obj.force_max), "stroke_max": float(pto_obj.stroke_max)}
    finite = {k: v for k, v in scene.items() if limits and math.isfinite(v)}
    # the controller's own limits, explicit (its default, None, would mean the scene's): the
    # scene's with limits, none without, so make(name, **parameters) is the very controller
    own = {k: (v if limits else math.inf) for k, v in scene.items() if _accepts(cls, k)}
    if name == "mpc" and limits:     # no scene limit: the MPC's own default (a soft stroke
        own = {k: v for k, v in own.items() if math.isfinite(v)}   # limit in its linear range)
    # the wave is a setting beyond the parameters: a predictive controller's preview
    extra = {"wave": wave} if _accepts(cls, "wave") else {}
    if name in ("passive", "reactive"):
        from .passive import optimal_damping
        from .reactive import reactive_tuning
        tuner = optimal_damping if name == "passive" else reactive_tuning
        kw = _limit_kwargs(tuner, finite, tuner.__name__, notes)
        if pto_obj.efficiency != 1 and _accepts(tuner, "efficiency"):
            kw["efficiency"] = float(pto_obj.efficiency)    # tune for electrical power
        if name == "passive":
            damping, predicted = tuner(plant, wave, pto=pto, params=model_params, **kw)
            tuned = {"damping": damping}
        else:
            damping, stiffness, predicted = tuner(plant, wave, pto, params=model_params, **kw)
            tuned = {"damping": damping, "stiffness": stiffness}
        return ({**tuned, **own}, predicted, {"function": tuner.__name__, "settings": kw},
                extra)
    if name in ("latching", "declutching"):
        from .latching import optimal_declutch, optimal_latch_time
        if model_params:
            raise ValueError("model_params: latching and declutching tune by simulating the "
                             "plant itself")
        tuner, key = ((optimal_latch_time, "latch_time") if name == "latching"
                      else (optimal_declutch, "declutch_time"))
        kw = _limit_kwargs(tuner, finite, tuner.__name__, notes)
        hold, damping, simulated = tuner(plant, wave, pto=pto, **kw)
        return ({"damping": damping, key: hold, **own}, None,
                {"function": tuner.__name__, "settings": kw, "simulated_power_W": simulated,
                 "dt_s": wave.period / 500}, extra)
    # mpc (or another registered controller): no tuner; its defaults and the PTO's limits
    if model_params:
        raise ValueError("model_params: this controller is not tuned, so there is no model "
                         "to get wrong")
    if name in ("mpc", "nmpc"):
        # one wave period ahead in 40 steps: the horizon that reaches the constrained bound
        # on the sphere (tests/test_mpc.py) and a QP of real-time size
        own.setdefault("horizon_s", float(wave.period))
        own.setdefault("dt_s", float(wave.period) / 40)
        if "force_max" in finite:      # a drive's slew: a full reversal in a fifth of a period
            own.setdefault("rate_max", RATE_REVERSALS_PER_PERIOD * 2 * finite["force_max"]
                           / float(wave.period))
    controller = make(name, **own, **extra)
    parameters = {}
    for key in CONTRACT.get(name, ()):
        value = own.get(key, getattr(controller, key, None))
        if isinstance(value, (int, float)):
            parameters[key] = float(value)
    return parameters, None, {"function": None, "settings": "defaults"}, extra


def _duration(wave, margins) -> float:
    """Default simulated time (s): see the module docstring."""
    if wave.omega.size > 1:
        return 2 * np.pi / wave.d_omega if wave.d_omega else 600.0
    T = float(wave.period)
    periods = 30
    if margins is not None and margins.pole_margin > 0:
        need = wave.ramp_time + SETTLE_TIME_CONSTANTS / margins.pole_margin + 10 * T
        periods = max(periods, math.ceil(need / T))
    return periods * T


def _harmonics(plant, wave) -> int:
    """Harmonics of a regular wave the constrained bound's force may hold: all inside the
    hydro data's band, at most MAX_HARMONICS. With the wave frequency alone it is no bound on
    a saturating or switching controller: on the sphere (H 2.5 m, T 9.67 s, 2 MN, 4 m) it is
    696.7 kW, while an MPC absorbs 755 kW; with 15 harmonics the bound is 756.5 kW."""
    if wave.omega.size != 1 or plant.hydro is None:
        return 1
    k = int(np.floor(float(plant.hydro.omega[-1]) / float(wave.omega[0]) * (1 - 1e-9)))
    return max(1, min(k, MAX_HARMONICS))


def _bounds(plant, wave, pto, limit_values, mode) -> dict:
    """Complex-conjugate and constrained (pseudo-spectral) bounds, W, with reasons."""
    out = {"complex_conjugate_W": None, "constrained_W": None, "constrained_reason": None,
           **limit_values}
    if not mode:
        out["constrained_reason"] = "bounds not requested"
        return out
    from mbcontrol.analysis import complex_conjugate_bound, pseudo_spectral_bound
    try:
        cc = complex_conjugate_bound(plant, wave, pto)
    except ValueError as exc:          # NotPassiveError, a wave outside the data, ...
        out["constrained_reason"] = f"no bound: {exc}"
        return out
    out["complex_conjugate_W"] = cc.power
    force_max, stroke_max = limit_values["force_max"], limit_values["stroke_max"]
    n = int(wave.omega.size)
    if not (math.isfinite(force_max) or math.isfinite(stroke_max)):
        out["constrained_W"] = cc.power
        out["constrained_reason"] = "the PTO has no force or stroke limit: the complex-conjugate bound"
    elif n > MAX_BOUND_COMPONENTS and mode != "full":
        out["constrained_reason"] = (
            f"skipped: the sea has {n} components (> {MAX_BOUND_COMPONENTS}); the QP's time "
            f"grows like n^3 (12-25 s at 278); ask for it with bounds='full' (--bounds full)")
    else:
        harmonics = _harmonics(plant, wave)
        out["constrained_harmonics"] = harmonics
        try:
            ps = pseudo_spectral_bound(plant, wave, pto=pto, force_max=force_max,
                                       stroke_max=stroke_max, harmonics=harmonics)
        except Exception as exc:        # a solver failure is reported, not raised: # noqa: BLE001
            out["constrained_reason"] = f"pseudo-spectral solve failed: {exc}"
            return out
        out["constrained_solve_time_s"] = ps.solve_time
        if math.isfinite(ps.mean_power):
            out["constrained_W"] = ps.mean_power
        else:
            out["constrained_reason"] = f"no optimum under the limits (solver status {ps.status})"
    return out
