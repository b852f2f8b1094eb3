"""Linear model-predictive control of the PTO force: maximise absorbed energy over a horizon.

Every `dt_s` seconds the controller estimates the control-plant state and the excitation,
forecasts the excitation over `horizon_s`, solves a convex QP for the force sequence and
applies its first move (held, zero-order). The QP, with U the forces over the horizon (held
over each step) and P the PTO positions at the ends of the steps:

    minimise   sum_k u_k . (p_k+1 - p_k)          (minus the absorbed energy, J)
             + r |U|^2 + w1 |s|_1 + w2 |s|^2      (force penalty, stroke slack)
    subject to |u_k| <= force_max, |u_k - u_k-1| <= rate_max dt, |p_k| <= stroke_max + s_k
               (force_max_on = "hull": the hull's force at each step's ends, mpc_qp)

The energy of a held force is exactly u_k (p_k+1 - p_k). Condensed (P affine in U), the
energy term is U^T G U + q^T U with G + G^T positive semidefinite whenever the plant is
passive from force to velocity (the energy a PTO puts into a passive body at rest is never
negative), so the QP is convex; r adds a small margin (force_penalty times the largest
eigenvalue) that makes it strictly convex and keeps the force from chattering. The stroke
limit is soft (slack s >= 0 with an exact L1 penalty) so the QP is always feasible; with
soft_stroke=False it is hard, and a state from which it cannot be met is reported (counted,
warned once, the previous plan's next move applied), not a crash.

Two solver paths on the same scaled QP: "qpoases" (the real-time path: the dense condensed
QP through CasADi's qpOASES interface, matrices built once) and "cvxpy" (the prototyping
path: a cvxpy Problem with Parameters, built once, solved by Clarabel).

State and excitation (`estimator`): "kalman" (default) estimates both from the joint
encoders (controllers.estimation.ExcitationKalman); "state" hands the controller the plant's
state (an oracle for studies, `uses_state`). Forecast (`forecast`): "ar" (the default:
auto-regressive on the Kalman estimates, causal), "model" (the Kalman wave model's free
motion), "none" (zero), "known" (the true future excitation from `wave`: a non-causal
oracle, only when asked; describe() then labels the run an upper bound). A `wave` given with
a causal forecast only sets the Kalman wave model's frequencies and the warm-up damper.

Start-up (warm-up). Until the AR predictor has its first fit the controller applies the
tuned passive damper instead, then blends over to the MPC in one peak period (per PTO,
computed once in reset(): `optimal_damping` for the
sea by linear theory, or |Z_i| at the wave model's frequency without a wave), clipped to the
force limit. The first fit waits for WARM_UP_PERIODS peak periods of estimates (at least
4 x ar_order samples): an AR(8) fitted to the first 32 samples (6.4 s, during the wave's
ramp) learnt the ramp's growth (companion spectral radius 1.14 on rm3) and its forecast,
500 times the excitation 10 s ahead, drove rm3 to 237 m strokes. describe()["warm_up_s"] is
the time the MPC took over; mbcontrol.analysis.metrics starts its statistics after it. A
fitted AR model that is unstable (a root of its characteristic polynomial outside the unit
circle) is stabilised by reflecting those roots into it (estimation.ArPredictor; counted in
describe()["stats"]["ar_unstable_fits"]). With no force limit (rm3's and the OSWEC's
scenes have none) the QP is regularised by force_penalty alone. A PTO whose scene sets no
stroke limit gets a soft one at LINEAR_RANGE_SHARE of the range where the linear model
holds (see LINEAR_RANGE_SHARE; reported in describe()["stroke_max_default"]).

Envelope (envelope=True, the default): the quantities the physics checks measure, each
body's heave relative to the surface (a probe measures the surface at the body; needs the
wave) and its roll and pitch, are soft constraints at every step of the horizon, each within
PEAK_SHARE of the check's limit (controllers.mpc_envelope; describe()["envelope"]). Without
it the MPC rode PacWave's seas outside the linear model's range: sphere 28, rm3 17, OSWEC 10
of 32 seas INVALID (200 s each); with it none.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from mbcontrol.analysis import winding_coefficient
from mbcontrol.errors import ControllerError
from mbcontrol.results import jsonable

from .base import signal_indices
from .control_plant import build_control_plant, device_frequency, hydro_band, pto_impedance
from .estimation import ArPredictor, ExcitationKalman, excitation_error, wave_frequencies
from .limits import (LINEAR_RANGE_SHARE, command_limit, hull_limits, linear_range,
                     per_pto_values)
from .sampled import held_dampers
from .mpc_envelope import MpcEnvelope
from .mpc_qp import CondensedQp

# warm-up before the first AR fit, in peak periods of the sea (or of the wave model without
# a wave): 5 periods give the least-squares fit 5 T / dt_s samples (225 for rm3 at Tp 9 s,
# dt_s 0.2 s: 28 per AR(8) coefficient), 3 periods past the simulation's ramp (2 Tp). The
# root reflection alone already prevents the blow-up; the warm-up is for the fit's quality.
# Measured on rm3 (Hs 2 m, Tp 9 s, seeds 0-2, 400 s, power over t >= 80 s): 278.5-279.3,
# 254.1-255.9 and 247.9-248.8 kW for warm-ups of 0-5 periods (within 0.7 %), stabilised
# fits 10 -> 3, 12 -> 6, 7 -> 1 from 0 to 5 periods; 8 periods gave +0.6 % to +4.4 % power
# but costs another 27 s of every record's statistics
WARM_UP_PERIODS = 5.0
ORACLE_LABEL = "non-causal upper bound (true future wave)"


class Mpc:
    """Linear MPC of the PTO force(s). Settings (the contract names first):

    horizon_s, dt_s: prediction horizon and control period, s (dt_s a multiple of the
    simulation step); force_max (N or N m), stroke_max (m or rad), rate_max (N/s): limits,
    None = the scene PTO's (rate: unlimited); wave: the sea (the Kalman wave model's
    frequencies and the warm-up damper; the forecast only with forecast "known"); forecast:
    "ar" (default, causal), "model", "none", or "known" (the oracle, labelled a bound);
    warm_up_s: passive damping until this time, s (None: WARM_UP_PERIODS peak periods with
    the AR forecast, 0 otherwise; with "ar", until its first fit); estimator: "kalman" or
    "state"; solver: "qpoases" or "cvxpy"; order: reduce the control plant to this many
    states (balanced truncation), None = full; force_penalty: r relative to the energy
    Hessian's largest eigenvalue; stroke_penalty: slack weights (w1 = w2 in scaled units);
    soft_stroke; measured: output names the Kalman filter reads (default: every joint
    coordinate and rate); ar_order; measurement_noise (Kalman, relative); objective: "auto"
    (electrical power for PTOs with a drivetrain: each step's winding loss R F^2 dt /
    (gear kt')^2 enters the QP), "electrical" or "mechanical"; envelope: keep the linear
    model's range (see the module docstring).
    """
    name = "mpc"

    def __init__(self, horizon_s: float = 10.0, dt_s: float = 0.2, force_max=None,
                 stroke_max=None, rate_max=None, *, wave=None, forecast: str | None = None,
                 estimator: str = "kalman", solver: str = "qpoases", order: int | None = None,
                 force_penalty: float = 1e-3, stroke_penalty: float = 100.0,
                 soft_stroke: bool = True, measured=None, ar_order: int = 8,
                 measurement_noise: float = 1e-3, efficiency=None,
                 warm_up_s: float | None = None, objective: str = "auto",
                 envelope: bool = True):
        forecast = forecast or "ar"        # causal by default; the oracle only when asked
        _choice("forecast", forecast, ("known", "ar", "model", "none"))
        _choice("estimator", estimator, ("kalman", "state"))
        _choice("solver", solver, ("qpoases", "cvxpy"))
        _choice("objective", objective, ("auto", "electrical", "mechanical"))
        if forecast == "known" and wave is None:
            raise ControllerError("mpc: forecast 'known' needs the wave (wave=...)")
        if warm_up_s is not None and not warm_up_s >= 0:
            raise ControllerError(f"mpc: warm_up_s must be >= 0 s, got {warm_up_s}")
        if horizon_s < dt_s or dt_s <= 0:
            raise ControllerError(f"mpc: expected 0 < dt_s <= horizon_s, got dt_s={dt_s}, "
                                  f"horizon_s={horizon_s}")
        self.horizon_s, self.dt_s = float(horizon_s), float(dt_s)
        self.force_max, self.stroke_max, self.rate_max = force_max, stroke_max, rate_max
        self.wave, self.forecast, self.estimator, self.solver = wave, forecast, estimator, solver
        self.order, self.force_penalty, self.stroke_penalty = order, force_penalty, stroke_penalty
        self.soft_stroke, self.measured, self.ar_order = soft_stroke, measured, ar_order
        self.measurement_noise = measurement_noise
        self.efficiency, self.objective = efficiency, objective
        self.envelope = bool(envelope)
        self.warm_up_setting = warm_up_s
        self.period = self.dt_s
        self.uses_state = estimator == "state"

    # -- set-up --------------------------------------------------------------------------
    def reset(self, plant) -> None:
        self.plant = plant
        self.env = MpcEnvelope(plant, self.wave, on=self.envelope, forecast=self.forecast,
                               dt=self.dt_s)
        self.cp = cp = build_control_plant(plant, self.dt_s, measured=self.measured,
                                           order=self.order, extra_outputs=self.env.outputs)
        ptos = [p for p in plant.scene.ptos if p.name in cp.ptos]
        strokes = [p.stroke_max if math.isfinite(p.stroke_max) else linear_range(plant, p.name)
                   for p in ptos]
        self.stroke_default = None if self.stroke_max is not None else {
            p.name: s for p, s in zip(ptos, strokes) if not math.isfinite(p.stroke_max)}
        hull = hull_limits(ptos, list(cp.ptos), self.force_max)   # force_max_on = "hull"
        self.limits = {
            "force": per_pto_values(plant, self.force_max, [command_limit(p) for p in ptos],
                                    "force_max"),
            "stroke": per_pto_values(plant, self.stroke_max, strokes, "stroke_max"),
            "rate": per_pto_values(plant, self.rate_max, [math.inf] * len(ptos), "rate_max"),
        }
        self.N = int(round(self.horizon_s / self.dt_s))
        efficiency = per_pto_values(plant, self.efficiency, [p.efficiency for p in ptos], "efficiency")
        self.device_omega = device_frequency(cp, hydro_band(plant))
        if self.wave is None:
            warnings.warn(f"mpc: no sea state given (wave=...): the Kalman wave model is centred "
                          f"on the device's resonance seen from its PTO ({self.device_omega:.3g} "
                          f"rad/s, period {2 * np.pi / self.device_omega:.3g} s), a guess; the "
                          f"sea's own spectrum estimates the excitation better", RuntimeWarning,
                          stacklevel=3)
        omega = wave_frequencies(self.wave, self.device_omega)
        winding = [0.0 if self.objective == "mechanical" else winding_coefficient(plant, p.name)
                   or 0.0 for p in ptos]            # a drivetrain's R / (gear kt')^2, W/N^2
        self.qp = CondensedQp(cp, self.N, self.limits, efficiency=efficiency, winding=winding,
                              loss_damping=pto_impedance(cp, float(np.median(omega))),
                              force_penalty=self.force_penalty,
                              stroke_penalty=self.stroke_penalty, soft_stroke=self.soft_stroke,
                              solver=self.solver, envelope=self.env.rows(cp), hull=hull)
        if self.estimator == "kalman":
            self.kalman = ExcitationKalman(cp, omega, measurement_noise=self.measurement_noise)
        else:
            self.kalman = None
            if self.forecast != "known":
                raise ControllerError("mpc: estimator 'state' knows no excitation; use forecast 'known'")
        self.warm_up_planned = self._warm_up_time(cp)
        self.ar = (ArPredictor(cp.nd, self.dt_s, order=self.ar_order,
                               min_samples=int(math.ceil(self.warm_up_planned / self.dt_s - 1e-9))
                               + 1)
                   if self.forecast == "ar" else None)
        self.env.forecast_like(self.ar)
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in cp.ptos])
        self.warm_up_damping = self._warm_up_damping(plant, cp, omega)
        self.warm_up_end = None           # s: when the MPC took over
        self._last_t = None
        self._excitation_cache = (None, None)
        self.u_prev = np.zeros(len(cp.ptos))
        self._plan = None
        self.stats = {"solves": 0, "failures": 0, "infeasible": 0, "solve_s": []}
        self.history = []                 # (t, d estimate) per call, for checks and plots
        self._warned = False

    # -- the control law -----------------------------------------------------------------
    def __call__(self, t: float, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        cp = self.cp
        if self._last_t is not None and t < self._last_t + self.dt_s * (1 - 1e-6):
            # called again within a period (simulate's closing sample, off the controller's
            # grid): hold the command. Updating the filter here would step its discrete model
            # by a whole period for a fraction of one (measured on rm3: a 228 MN command).
            return self.u_prev.copy()
        self._last_t = float(t)
        if self.estimator == "state":
            z = cp.T @ np.asarray(x, float)
        else:
            ym = np.asarray(y, float)[cp.y_index] - cp.y_rest
            self.kalman.update(ym, self.u_prev)
            z = self.kalman.z
        if self.kalman is not None:
            self.history.append((t, self.kalman.d.copy()))
            if self.ar is not None:
                self.ar.append(self.kalman.d)
        self.env.measure(t)              # the surface probes: a measurement, now
        if self._warming_up(t):          # the tuned damper until the predictor has a fit
            u = -self.warm_up_damping * np.asarray(y, float)[self._velocity]
            self.u_prev = np.clip(u, -self.limits["force"], self.limits["force"])
            return self.u_prev.copy()
        known = self._known_forecast(t) if self.forecast == "known" else None
        D = self._forecast(known)
        start = time.perf_counter()
        U, status = self.qp.solve(z, D, self.u_prev, self._plan, self.env.offset(t, self.N))
        self.stats["solve_s"].append(time.perf_counter() - start)
        self.stats["solves"] += 1
        if U is None:
            self._failed(t, status)
            U = self._shifted_plan()
        self._plan = U
        u = U[0]
        if self.warm_up_end is not None and t < self.warm_up_end + self.blend_s:
            # bumpless take-over: from the damper to the MPC over one peak period (its first
            # plan alone kicked rm3's PTO with 12 MN, 4x its later peaks)
            share = (t - self.warm_up_end) / self.blend_s
            u = share * u - (1 - share) * self.warm_up_damping * np.asarray(y, float)[
                self._velocity]
        self.u_prev = np.clip(u, -self.limits["force"], self.limits["force"])
        return self.u_prev.copy()

    def _forecast(self, known) -> np.ndarray:
        n, nd = self.N, self.cp.nd
        if known is not None:
            return known
        if self.forecast == "none" or nd == 0:
            return np.zeros((n, nd))
        if self.ar is not None:
            predicted = self.ar.forecast(n)
            if predicted is not None:
                return predicted
        return self.kalman.model_forecast(n)

    def _warming_up(self, t: float) -> bool:
        if self.warm_up_end is not None:
            return False
        ready = (self.ar.coefficients is not None if self.ar is not None
                 else t >= self.warm_up_planned - 1e-9)
        if ready:
            self.warm_up_end = float(t)
        return not ready

    def _warm_up_time(self, cp) -> float:
        """Planned warm-up, s: the setting, or WARM_UP_PERIODS peak periods (AR forecast)."""
        if self.wave is not None:
            period = float(self.wave.period)
        else:
            period = 2 * np.pi / self.device_omega
        if self.warm_up_setting is not None:
            planned = float(self.warm_up_setting)
        elif self.forecast != "ar":
            planned = 0.0
        else:
            planned = max(WARM_UP_PERIODS * period, (4 * self.ar_order - 1) * self.dt_s)
        self.blend_s = period if planned > 0 else 0.0      # the take-over's length, s
        return planned

    def _warm_up_damping(self, plant, cp, omega) -> np.ndarray:
        """The warm-up damper per PTO, N s/m: optimal_damping for the sea (linear theory, the
        other PTOs free), or |Z_i| at the wave model's median frequency (the regular-wave
        optimum) without a wave or when the sea lies outside the hydro data. A limit on the
        hull is not held during the warm-up (the command clip holds a machine limit)."""
        out = pto_impedance(cp, float(np.median(omega)))
        if self.wave is not None:
            from .passive import optimal_damping
            for i, name in enumerate(cp.ptos):
                try:
                    out[i] = optimal_damping(plant, self.wave, pto=name)[0]
                except ValueError:
                    pass
        # held over dt_s, as it is applied: a damper tuned in continuous time can destabilise
        # the sampled loop (rm3, Tp >= 11.3 s, dt_s 0.2 s: the cause of its divergences)
        held, self.warm_up_factor = held_dampers(plant, dict(zip(cp.ptos, out)), self.dt_s)
        return np.array([held[name] for name in cp.ptos])

    def _known_forecast(self, t: float) -> np.ndarray:
        """d at the midpoints of the next N periods from the wave (cached in blocks)."""
        k0 = int(round(t / self.dt_s))
        start, block = self._excitation_cache
        if start is None or k0 < start or k0 + self.N > start + len(block):
            times = (k0 + np.arange(self.N + 2000) + 0.5) * self.dt_s
            block = self.plant.excitation(self.wave, times) @ self.cp.S.T
            self._excitation_cache = (k0, block)
            start = k0
        return block[k0 - start:k0 - start + self.N]

    def _failed(self, t: float, status: str) -> None:
        self.stats["failures"] += 1
        if "infeasible" in status.lower():
            self.stats["infeasible"] += 1
        if not self._warned:
            self._warned = True
            hint = (" The hard stroke limit cannot be met from this state; use soft_stroke=True "
                    "(the default)." if not self.soft_stroke else "")
            warnings.warn(f"mpc: QP not solved at t = {t:.4g} s ({status}); applying the previous "
                          f"plan's next move.{hint} Counts are in describe()['stats'].",
                          RuntimeWarning, stacklevel=3)

    def _shifted_plan(self) -> np.ndarray:
        if self._plan is None:
            return np.zeros((self.N, len(self.cp.ptos)))
        return np.vstack([self._plan[1:], self._plan[-1:]])

    def casadi_law(self, plant):
        return None                      # dynamic (estimator, horizon): runs in Python

    def estimation_report(self, t, W) -> dict | None:
        """The Kalman excitation estimate's accuracy against the simulation's true excitation
        W (on times t, s), after the warm-up (estimation.excitation_error); simulate calls it."""
        if not self.history:
            return None
        start = self.warm_up_end if self.warm_up_end is not None else self.warm_up_planned
        times, estimates = zip(*self.history)
        return excitation_error(times, np.array(estimates), t, W, self.cp.S, start)

    def describe(self) -> dict:
        times = np.asarray(self.__dict__.get("stats", {}).get("solve_s", [])) * 1e3
        stats = dict(self.__dict__.get("stats", {}))
        stats.pop("solve_s", None)
        if "qp" in self.__dict__:
            stats["soft_solves"] = self.qp.soft_solves
        if self.__dict__.get("ar") is not None:
            stats["ar_fits"] = self.ar.fits
            stats["ar_unstable_fits"] = self.ar.unstable_fits
        if times.size:
            stats.update(solve_ms_median=float(np.median(times)),
                         solve_ms_p95=float(np.percentile(times, 95)))
        out = {"name": self.name, "horizon_s": self.horizon_s, "dt_s": self.dt_s,
               "force_max": jsonable(self.force_max), "stroke_max": jsonable(self.stroke_max),
               "rate_max": jsonable(self.rate_max), "forecast": self.forecast,
               "oracle": self.forecast == "known" or self.uses_state,
               "label": self.label(),
               "estimator": self.estimator + (" (full-state oracle)" if self.uses_state else ""),
               "solver": self.solver, "order": self.order, "soft_stroke": self.soft_stroke,
               "envelope_on": self.envelope,
               "period_s": self.period, "stats": stats}
        out.update(self._warm_up_report())
        if "env" in self.__dict__ and self.envelope:
            out["envelope"] = self.env.report()
        if self.__dict__.get("stroke_default"):
            out["stroke_max_default"] = {
                "values": {k: float(v) for k, v in self.stroke_default.items()},
                "why": f"the scene sets no stroke limit: a soft one at {LINEAR_RANGE_SHARE:g} of "
                       f"the linear-hydrodynamics range (30 deg; the shallowest mean draft), "
                       f"where the MPC's linear model holds"}
        return out

    def label(self) -> str:
        """How causal the run is, for JSON, Datasets and figure legends."""
        if self.forecast == "known":
            return ORACLE_LABEL
        causal = {"ar": "causal (AR forecast of the Kalman excitation estimate)",
                  "model": "causal (Kalman wave-model forecast)",
                  "none": "causal (no forecast)"}[self.forecast]
        return causal + ("; full-state oracle" if self.uses_state else "")

    def _warm_up_report(self) -> dict:
        """warm_up_s: when the MPC took over (the plan before a run, or when it never did)."""
        if "warm_up_planned" not in self.__dict__:
            return {"warm_up_s": self.warm_up_setting}
        end = self.warm_up_end if self.warm_up_end is not None else self.warm_up_planned
        return {"warm_up_s": float(end),
                "warm_up": {"law": "passive damper u = -c v until the first AR fit"
                            if self.ar is not None else "passive damper u = -c v",
                            "damping": [float(c) for c in self.warm_up_damping],
                            # < 1: the sea's damper scaled down to keep its loop held over
                            # dt_s stable (controllers.sampled.held_dampers)
                            "held_factor": float(self.warm_up_factor),
                            "planned_s": float(self.warm_up_planned),
                            "take_over_s": float(self.blend_s),
                            "completed": self.warm_up_end is not None}}


def _choice(what, value, allowed):
    if value not in allowed:
        raise ControllerError(f"mpc: {what} must be one of {', '.join(allowed)}, got {value!r}")
