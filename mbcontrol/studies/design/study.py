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
ramp to settle before the 10-period window; a sea runs two repeat periods (T_r = 2 pi /
d_omega) and is scored over the second: a whole-period mean, as its bounds, with the ramp and
any warm-up behind it (a window after the ramp may hold more energetic waves than the period:
on the sphere in Hs 3.5 m, Tp 9.67 s, a 300 s sea, the complex-conjugate optimum's mean over
t >= ramp is 112 % of its period mean, so scored there an MPC "beat" the bound).

dt = T / 1000 (T the period or peak period): the controller's command is held over each step,
and a held spring -k x lags dt / 2 on average, -k x(t - dt / 2) ~ -k x + k (dt / 2) v: a
damping of -k dt / 2. A positive stiffness removes
damping k dt / 2 (at a long enough hold the loop goes unstable; controllers.sampled checks
it), a negative one adds |k| dt / 2: for reactive control of the sphere (k < 0) that is 5.6 %
of its damping at T / 1000 (power within 0.06 % of the bound) and 11 % at T / 500 (-0.16 %).
A controller with its own period gets the largest dt <= that which divides its period.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mbcontrol.errors import ControllerError, SimulationError
from mbcontrol.results import jsonable

from ... import defaults
from ...controllers import REGISTRY, make
from ...sim import period_of
from .fallback import NoLawForSea, tune_with_fallback
from .envelope_gain import lifted_envelope

# MAX_HARMONICS, the default "design.max_harmonics": the constrained bound's QP stays < 0.1 s (0.07 s at 15)
# SETTLE_TIME_CONSTANTS, the default "design.settle_time_constants": e^-12 = 6e-6: the start-up transient left in the window
# simulated power above a bound by more than this share is noted: the nonlinear plant, its
# radiation fit and the held command move a run's power by well under 1 % of linear theory
# BOUND_TOLERANCE: the default "design.bound_tolerance" (mbcontrol.defaults)


@dataclass
class DesignResult:
    """What `design` found. Powers in W (absorbed > 0); see the module docstring.

    parameters: make(name, **parameters) rebuilds the controller (the contract names; with
    the controller's own force_max / stroke_max where it takes them, inf: none, null in
    JSON, `--set force_max=inf`); predicted_power_W: linear theory (None for
    switching and predictive control); bound: complex_conjugate_W, constrained_W (None with
    constrained_reason when skipped or infeasible), force_max, stroke_max, and electrical_W
    for a PTO with a drivetrain (in a regular wave within the PTO's force and stroke limits,
    analysis.electrical.electrical_bound; in a sea impedance.electrical_optimum, with no limit,
    which bounds the limited runs too: electrical_within_limits says which;
    percent_of_bound["electrical"] sets the simulated electrical power against it); metrics:
    metrics.pto_metrics of the designed PTO in closed loop (None if not simulated);
    percent_of_bound: 100 x simulated power / each bound; margins: controllers.margins.Margins
    (passive and reactive); tuner: what tuned it and what it reported; simulation: duration_s,
    dt_s and the full `mbcontrol simulate --json` summary; warnings: what the reader should
    know (an unstable loop, a tuner without constrained tuning, ...); envelope_lifted: on a
    plant with nonlinear pressure, the same law tuned without the linear model's envelope and
    simulated there (studies.design.envelope_gain.lifted_envelope), else None.
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
    envelope_lifted: dict | None = None   # nonlinear pressure: envelope_gain.lifted_envelope

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
               "tuner": self.tuner, "simulation": self.simulation, "warnings": self.warnings,
               "envelope_lifted": self.envelope_lifted}
        return jsonable(out)


def design(plant, wave, name: str, *, pto: str | None = None, simulate_s: float | None = None,
           dt: float | None = None, bounds: bool | str = True, limits: bool = True,
           model_params: dict | None = None, robust: bool = True) -> DesignResult:
    """Tune controller `name` for `wave`, check, bound, simulate and score it.

    plant: a ProcessPlant; wave: mbcontrol.waves.Wave (regular or a sea); name: a REGISTRY
    name (passive, reactive, latching, declutching, mpc, nmpc, or a registered law). pto:
    the PTO tuned and scored (default the first).
    simulate_s, dt: closed-loop simulation length and step (s; defaults in the module
    docstring). bounds: True (complex-conjugate, and pseudo-spectral with a sea's force band cut
    to analysis.constrained.MAX_FORCE_COMPONENTS frequencies, then a reference, not a bound),
    "full" (the whole band), False (none). A multi-PTO device's passive and reactive laws are
    tuned jointly (controllers.joint); its total is bounded by the multiport optimum.
    limits: tune to the PTO's force and stroke limits (see the module docstring).
    model_params: parameter overrides of the model the tuner sees, for model-error studies:
    the margins and the simulation use the plant as it is. An unstable linear loop is not
    simulated (it would diverge), and a simulation that fails (SimulationError) is reported,
    not raised: the result says so in margins and warnings, with metrics None. robust (the
    default): a reactive law within the robustness floors (controllers.robustness, the
    defaults design.gain_margin_min and design.phase_margin_min_deg); False: the
    unconstrained optimum (`design --aggressive`). Linear laws are checked against the floors
    and flagged either way (tuner["robustness"]).

    Raises ValueError naming the controller when it is unknown or its tuner cannot apply
    (no wave, latching in a sea, latching in waves shorter than the natural period, ...).
    """
    if name not in REGISTRY:
        raise ControllerError(f"design: unknown controller {name!r}; expected one of "
                              f"{', '.join(REGISTRY)}")
    if wave is None:
        raise ControllerError(f"design {name!r}: needs a wave to tune for")
    pto_obj = _pto(plant, pto)
    limit_values = {"force_max": float(pto_obj.force_max), "stroke_max": float(pto_obj.stroke_max),
                    "force_max_on": pto_obj.limited_force()}   # the machine's force or the hull's
    period = float(wave.period)
    default_dt = dt is None
    dt = period / 1000 if default_dt else float(dt)
    notes: list[str] = []

    try:      # the tuned law, or in a sea it cannot serve a detuned or saturated damper
        law = tune_with_fallback(plant, wave, name, pto_obj, notes, robust=robust,
                                 model_params=model_params, limits=limits)
    except NoLawForSea:
        raise
    except ValueError as exc:
        raise ControllerError(f"design {name!r}: {exc}") from None
    name, parameters, predicted, extra = (law["controller"], law["parameters"],
                                          law["predicted"], law["extra"])
    tuner = {**law["tuner"], "fallback": law["fallback"]}
    controller = make(name, **parameters, **extra)
    if isinstance(predicted, dict):                  # jointly tuned: one figure per PTO
        predicted = predicted[pto_obj.name]
    many = len(plant.scene.ptos) > 1
    linear = REGISTRY[name].kind == "linear"     # a loop transfer and linear theory
    # the other PTOs as the controller closes them: the same plant for margins and bounds
    others = None
    if linear and many:
        from ...controllers import other_laws
        others = other_laws(plant, parameters, pto_obj.name)
        tuner["other_ptos"] = (f"{len(plant.scene.ptos)} PTOs tuned jointly for their total "
                               f"power; the prediction, bound, margins and simulation of "
                               f"{pto_obj.name!r} close the others with their tuned laws")
    elif many:
        tuner["other_ptos"] = (f"{name} acts on every PTO; one PTO's power has no bound of its "
                               f"own (the others can feed it): the total is bounded")

    margins = _loop_checks(plant, wave, name, parameters, pto_obj.name, predicted, others,
                           tuner, notes) if linear else None
    duration = simulate_s if simulate_s is not None else _duration(wave, margins)
    # a sea on a uniform grid repeats every T_r: scored over its last whole repeat period,
    # the metrics are the period means the bounds are (a window after the ramp is not)
    repeat = 2 * math.pi / wave.d_omega if wave.omega.size > 1 and wave.d_omega else None
    whole = repeat is not None and duration >= 2 * repeat * (1 - 1e-9)
    bound = _bounds(plant, wave, pto_obj.name, limit_values, bounds, others, whole)
    if many and not linear:      # the others under a switching or predictive law
        bound.update(complex_conjugate_W=None, constrained_W=None,
                     constrained_reason=tuner["other_ptos"])
    if many and bounds:
        from mbcontrol.analysis import multiport_bound
        bound["total_complex_conjugate_W"] = multiport_bound(plant, wave).power

    metrics = simulation = ds = None
    percent = {"complex_conjugate": None, "constrained": None}
    if margins is None or margins.stable:
        if default_dt and period_of(controller):
            dt = controller.period / math.ceil(controller.period / dt - 1e-9)
        if wave.omega.size == 1 and duration < wave.ramp_time + 10 * period:
            notes.append(f"{duration:.4g} s is shorter than the ramp ({wave.ramp_time:.4g} s) "
                         f"plus the 10-period metrics window: the metrics include the start-up")
        metrics, simulation, ds = _closed_loop(
            plant, wave, controller, pto_obj, name=name, duration=duration, dt=dt,
            repeat=repeat if whole else None, bound=bound, percent=percent, notes=notes)
    for key, value in percent.items():     # a bound beaten: linear theory failed this run
        kind = bound.get("constrained_kind", "bound") if key == "constrained" else "bound"
        if value is not None and kind == "bound" and value > 100 * (1 + defaults.get("design.bound_tolerance")):
            notes.append(f"the simulated power is {value:.1f} % of the {key.replace('_', '-')} "
                         f"bound: the linear theory behind the bound does not hold for this run")
    lifted = None if not limits or metrics is None else lifted_envelope(
        plant, wave, name, pto_obj, _as_designed(parameters, metrics, simulation),
        duration=duration, dt=dt, score_from_s=duration - repeat if whole else None,
        model_params=model_params, robust=robust)
    return DesignResult(name, pto_obj.name, parameters, predicted, bound, metrics, percent,
                        margins, tuner, simulation, notes, ds, lifted)


def _as_designed(parameters, metrics, simulation) -> dict:
    """The design inside the envelope, as `envelope_gain.lifted_envelope` compares with it."""
    verdict = simulation["summary"]
    return {"parameters": parameters, "mean_power_W": metrics["mean_power_W"],
            "valid": verdict["valid"], "invalid_reasons": verdict["invalid_reasons"],
            "excursions": verdict["validity"].get("excursions", {})}


def _loop_checks(plant, wave, name, parameters, pto, predicted, others, tuner, notes):
    """A linear law's margins on the plant, its robustness (into `tuner`) and, for one PTO,
    the share of the prediction linear theory explains; what the reader should know into
    `notes`."""
    from ...controllers import loop_margins, loop_robustness, share_explained
    gains = {k: parameters[k] for k in REGISTRY[name].tuned}
    margins = loop_margins(plant, gains, pto=pto, params=others)
    if not margins.stable:
        notes.append(f"{name}: the closed loop is unstable on the plant, so it was not "
                     f"simulated. {margins.message}")
    tuner["robustness"] = loop_robustness(margins)
    if margins.stable and not tuner["robustness"]["meets"]:
        notes.append(f"{name}: below the robustness floors: {tuner['robustness']['why']}")
    if len(plant.scene.ptos) == 1 and plant.hydro is not None:
        tuner["share"] = share_explained(plant, wave, pto, predicted, name,
                                         robust=_floors_cost(tuner))
    return margins


def _closed_loop(plant, wave, controller, pto_obj, *, name, duration, dt, repeat, bound,
                 percent, notes):
    """Simulate the designed loop and score it: (metrics, simulation, dataset), with each
    bound's percentage into `percent`; all None when the simulation fails (said in `notes`).
    repeat: a sea's repeat period (s) when the run is scored over its last whole one."""
    from mbcontrol.analysis import pto_metrics, summary
    from mbcontrol.sim import simulate
    try:
        ds = simulate(plant, wave, duration=duration, dt=dt, controller=controller)
    except SimulationError as exc:     # e.g. a loop stable only when linearised
        notes.append(f"{name}: the closed-loop simulation failed: {exc}")
        return None, None, None
    if repeat is not None:
        ds.attrs["statistics_from_s"] = duration - repeat
        ds.attrs["statistics_note"] = (f"the last whole repeat period of the sea "
                                       f"({repeat:.4g} s), as its bounds")
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
    if bound.get("electrical_W"):
        percent["electrical"] = 100 * metrics["mean_electrical_power_W"] / bound["electrical_W"]
    if bound.get("total_complex_conjugate_W"):
        total = sum(pto_metrics(ds, p)["mean_power_W"] for p in plant.scene.ptos)
        metrics["total_mean_power_W"] = total
        percent["total_complex_conjugate"] = 100 * total / bound["total_complex_conjugate_W"]
    return metrics, simulation, ds


def _pto(plant, pto):
    ptos = {p.name: p for p in plant.scene.ptos}
    if not ptos:
        raise ControllerError(f"design: {plant.name} has no PTO to control")
    if pto is None:
        return plant.scene.ptos[0]
    if pto not in ptos:
        raise ControllerError(f"design: {plant.name} has no PTO {pto!r}; PTOs are "
                              f"{', '.join(ptos)}")
    return ptos[pto]


def _duration(wave, margins) -> float:
    """Default simulated time (s): see the module docstring."""
    if wave.omega.size > 1:           # two repeat periods, scored over the second
        return 4 * np.pi / wave.d_omega if wave.d_omega else 600.0
    T = float(wave.period)
    periods = 30
    if margins is not None and margins.pole_margin > 0:
        need = wave.ramp_time + defaults.get("design.settle_time_constants") / margins.pole_margin + 10 * T
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
    return max(1, min(k, defaults.get("design.max_harmonics")))


def _bounds(plant, wave, pto, limit_values, mode, params=None, whole=False) -> dict:
    """Complex-conjugate and constrained (pseudo-spectral) bounds, W, with reasons; params:
    the other PTOs' laws (None: their scene laws); whole: the metrics are a sea's mean over a
    whole repeat period (else over a window after the ramp, which a period mean does not
    bound: the figure is then a reference)."""
    out = {"complex_conjugate_W": None, "constrained_W": None, "constrained_reason": None,
           **limit_values}
    if not mode:
        out["constrained_reason"] = "bounds not requested"
        return out
    from mbcontrol.analysis import complex_conjugate_bound
    from ...analysis import constrained_figure, window_share
    try:
        cc = complex_conjugate_bound(plant, wave, pto, params)
    except ValueError as exc:          # NotPassiveError, a wave outside the data, ...
        out["constrained_reason"] = f"no bound: {exc}"
        return out
    out["complex_conjugate_W"] = cc.power
    force_max, stroke_max = limit_values["force_max"], limit_values["stroke_max"]
    if next(p for p in plant.scene.ptos if p.name == pto).drivetrain is not None:
        from ...controllers import electrical_optimum     # limits only lower it: still a bound
        out["electrical_W"] = electrical_optimum(plant, wave, pto=pto, params=params)["power_W"]
        out["electrical_within_limits"] = False
        if wave.omega.size == 1 and (math.isfinite(force_max) or math.isfinite(stroke_max)):
            from mbcontrol.analysis import electrical_bound   # within the limits
            out["electrical_W"] = electrical_bound(
                plant, wave, pto=pto, force_max=force_max, stroke_max=stroke_max, params=params,
                omega_max=float(plant.hydro.omega[-1])).electrical_W
            out["electrical_within_limits"] = True
    if not (math.isfinite(force_max) or math.isfinite(stroke_max)):
        out["constrained_W"] = cc.power
        out["constrained_reason"] = ("the PTO has no force or stroke limit: the "
                                     "complex-conjugate bound")
        out["constrained_kind"], out["constrained_kind_reason"] = "bound", "linear theory"
        if wave.omega.size > 1 and wave.d_omega and not whole:    # see constrained_figure
            start, end = float(wave.ramp_time or 0.0), 2 * math.pi / wave.d_omega
            out.update(window_s=[start, end], window_share=window_share(cc, start, end),
                       constrained_kind="reference",
                       constrained_kind_reason="a mean over the whole repeat period, the "
                                               "metrics over a window after the ramp")
    else:
        # a sea's force may hold every multiple of 2 pi / T in the data's band, not only the
        # sea's frequencies (analysis.constrained: else a saturating MPC beats the figure);
        # constrained_kind says whether it bounds what the metrics measure
        harmonics = _harmonics(plant, wave)
        out["constrained_harmonics"] = harmonics
        out.update(constrained_figure(plant, wave, pto, force_max, stroke_max, params=params,
                                      harmonics=harmonics, full=mode == "full",
                                      conjugate=cc, whole_period=whole))
    return out


def _floors_cost(tuner: dict) -> bool:
    """Did the robustness floors give up power (more than 1e-4 of the unconstrained optimum's
    prediction)? Then the share's explanation names them."""
    cost = (tuner.get("margins_cost") or {}).get("share") or 0.0
    return bool(tuner.get("robust")) and cost > 1e-4
