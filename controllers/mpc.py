"""Linear model-predictive control of the PTO force: maximise absorbed energy over a horizon.

Every `dt_s` seconds the controller estimates the control-plant state and the excitation,
forecasts the excitation over `horizon_s`, solves a convex QP for the force sequence and
applies its first move (held, zero-order). The QP, with U the forces over the horizon (held
over each step) and P the PTO positions at the ends of the steps:

    minimise   sum_k u_k . (p_k+1 - p_k)          (minus the absorbed energy, J)
             + r |U|^2 + w1 |s|_1 + w2 |s|^2      (force penalty, stroke slack)
    subject to |u_k| <= force_max, |u_k - u_k-1| <= rate_max dt, |p_k| <= stroke_max + s_k

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
state (an oracle for studies, `uses_state`). Forecast (`forecast`): "known" (from `wave`, as
with an up-wave measurement), "ar" (auto-regressive on the Kalman estimates), "model" (the
Kalman wave model's free motion), "none" (zero).
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from mbcontrol.results import jsonable

from .base import per_pto
from .control_plant import build_control_plant
from .estimation import ArPredictor, ExcitationKalman, wave_frequencies
from .mpc_qp import CondensedQp


class Mpc:
    """Linear MPC of the PTO force(s). Settings (the contract names first):

    horizon_s, dt_s: prediction horizon and control period, s (dt_s a multiple of the
    simulation step); force_max (N or N m), stroke_max (m or rad), rate_max (N/s): limits,
    None = the scene PTO's (rate: unlimited); wave: the sea (for forecast "known" and the
    Kalman wave model); forecast: "known", "ar", "model", "none"; estimator: "kalman" or
    "state"; solver: "qpoases" or "cvxpy"; order: reduce the control plant to this many
    states (balanced truncation), None = full; force_penalty: r relative to the energy
    Hessian's largest eigenvalue; stroke_penalty: slack weights (w1 = w2 in scaled units);
    soft_stroke; measured: output names the Kalman filter reads (default: every joint
    coordinate and rate); ar_order; measurement_noise (Kalman, relative).
    """
    name = "mpc"

    def __init__(self, horizon_s: float = 10.0, dt_s: float = 0.2, force_max=None,
                 stroke_max=None, rate_max=None, *, wave=None, forecast: str | None = None,
                 estimator: str = "kalman", solver: str = "qpoases", order: int | None = None,
                 force_penalty: float = 1e-3, stroke_penalty: float = 100.0,
                 soft_stroke: bool = True, measured=None, ar_order: int = 8,
                 measurement_noise: float = 1e-3, efficiency=None):
        forecast = forecast or ("known" if wave is not None else "ar")
        _choice("forecast", forecast, ("known", "ar", "model", "none"))
        _choice("estimator", estimator, ("kalman", "state"))
        _choice("solver", solver, ("qpoases", "cvxpy"))
        if forecast == "known" and wave is None:
            raise ValueError("mpc: forecast 'known' needs the wave (wave=...)")
        if horizon_s < dt_s or dt_s <= 0:
            raise ValueError(f"mpc: expected 0 < dt_s <= horizon_s, got dt_s={dt_s}, "
                             f"horizon_s={horizon_s}")
        self.horizon_s, self.dt_s = float(horizon_s), float(dt_s)
        self.force_max, self.stroke_max, self.rate_max = force_max, stroke_max, rate_max
        self.wave, self.forecast, self.estimator, self.solver = wave, forecast, estimator, solver
        self.order, self.force_penalty, self.stroke_penalty = order, force_penalty, stroke_penalty
        self.soft_stroke, self.measured, self.ar_order = soft_stroke, measured, ar_order
        self.measurement_noise = measurement_noise
        self.efficiency = efficiency
        self.period = self.dt_s
        self.uses_state = estimator == "state"

    # -- set-up --------------------------------------------------------------------------
    def reset(self, plant) -> None:
        self.plant = plant
        self.cp = cp = build_control_plant(plant, self.dt_s, measured=self.measured,
                                           order=self.order)
        ptos = [p for p in plant.scene.ptos if p.name in cp.ptos]
        self.limits = {
            "force": _limits(plant, self.force_max, [p.force_max for p in ptos], "force_max"),
            "stroke": _limits(plant, self.stroke_max, [p.stroke_max for p in ptos], "stroke_max"),
            "rate": _limits(plant, self.rate_max, [math.inf] * len(ptos), "rate_max"),
        }
        self.N = int(round(self.horizon_s / self.dt_s))
        efficiency = _limits(plant, self.efficiency, [p.efficiency for p in ptos], "efficiency")
        omega = wave_frequencies(self.wave, _natural_frequency(cp))
        self.qp = CondensedQp(cp, self.N, self.limits, efficiency=efficiency,
                              loss_damping=_impedance(cp, float(np.median(omega))),
                              force_penalty=self.force_penalty,
                              stroke_penalty=self.stroke_penalty, soft_stroke=self.soft_stroke,
                              solver=self.solver)
        if self.estimator == "kalman":
            fallback = _natural_frequency(cp)
            self.kalman = ExcitationKalman(cp, wave_frequencies(self.wave, fallback),
                                           measurement_noise=self.measurement_noise)
        else:
            self.kalman = None
            if self.forecast != "known":
                raise ValueError("mpc: estimator 'state' knows no excitation; use forecast 'known'")
        self.ar = ArPredictor(cp.nd, self.dt_s, order=self.ar_order) if self.forecast == "ar" \
            else None
        self._excitation_cache = (None, None)
        self.u_prev = np.zeros(len(cp.ptos))
        self._plan = None
        self.stats = {"solves": 0, "failures": 0, "infeasible": 0, "solve_s": []}
        self.history = []                 # (t, d estimate) per call, for checks and plots
        self._warned = False

    # -- the control law -----------------------------------------------------------------
    def __call__(self, t: float, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        cp = self.cp
        known = self._known_forecast(t) if self.forecast == "known" else None
        if self.estimator == "state":
            z = cp.T @ np.asarray(x, float)
        else:
            ym = np.asarray(y, float)[cp.y_index] - cp.y_rest
            self.kalman.update(ym, self.u_prev)
            z = self.kalman.z
        D = self._forecast(known)
        if self.kalman is not None:
            self.history.append((t, self.kalman.d.copy()))
        start = time.perf_counter()
        U, status = self.qp.solve(z, D, self.u_prev, self._plan)
        self.stats["solve_s"].append(time.perf_counter() - start)
        self.stats["solves"] += 1
        if U is None:
            self._failed(t, status)
            U = self._shifted_plan()
        self._plan = U
        self.u_prev = np.clip(U[0], -self.limits["force"], self.limits["force"])
        return self.u_prev.copy()

    def _forecast(self, known) -> np.ndarray:
        n, nd = self.N, self.cp.nd
        if known is not None:
            return known
        if self.forecast == "none" or nd == 0:
            return np.zeros((n, nd))
        if self.ar is not None:
            self.ar.append(self.kalman.d)
            predicted = self.ar.forecast(n)
            if predicted is not None:
                return predicted
        return self.kalman.model_forecast(n)

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

    def describe(self) -> dict:
        times = np.asarray(self.__dict__.get("stats", {}).get("solve_s", [])) * 1e3
        stats = dict(self.__dict__.get("stats", {}))
        stats.pop("solve_s", None)
        if "qp" in self.__dict__:
            stats["soft_solves"] = self.qp.soft_solves
        if times.size:
            stats.update(solve_ms_median=float(np.median(times)),
                         solve_ms_p95=float(np.percentile(times, 95)))
        return {"name": self.name, "horizon_s": self.horizon_s, "dt_s": self.dt_s,
                "force_max": jsonable(self.force_max), "stroke_max": jsonable(self.stroke_max),
                "rate_max": jsonable(self.rate_max), "forecast": self.forecast,
                "estimator": self.estimator + (" (full-state oracle)" if self.uses_state else ""),
                "solver": self.solver, "order": self.order, "soft_stroke": self.soft_stroke,
                "period_s": self.period, "stats": stats}


def _limits(plant, value, scene_values, what) -> np.ndarray:
    """Per-PTO limits: the setting (number or dict by PTO name) or the scene's; > 0."""
    if value is None:
        out = np.asarray(scene_values, float)
    else:
        out = per_pto(plant, value, f"mpc {what}")[:len(scene_values)]
    if np.any(out <= 0):
        raise ValueError(f"mpc: {what} must be > 0, got {out}")
    return out


def _impedance(cp, omega: float) -> np.ndarray:
    """|Z_i| per PTO at omega (rad/s): 1 / |force -> velocity| of the control plant (N s/m)."""
    Y = cp.Cv @ np.linalg.solve(1j * omega * np.eye(cp.nz) - cp.A, cp.Bu_c)
    return 1.0 / np.abs(np.diag(Y))


def _natural_frequency(cp) -> float:
    """The lightly damped mode the PTO sees: the pole of A nearest the imaginary axis among
    those with a visible imaginary part (rad/s), for the Kalman wave model without a wave."""
    poles = np.linalg.eigvals(cp.A)
    osc = poles[np.abs(poles.imag) > 1e-6]
    if osc.size == 0:
        return 1.0
    return float(np.abs(osc[np.argmin(np.abs(osc.real) / np.abs(osc))]))


def _choice(what, value, allowed):
    if value not in allowed:
        raise ValueError(f"mpc: {what} must be one of {', '.join(allowed)}, got {value!r}")
