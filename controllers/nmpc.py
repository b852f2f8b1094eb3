"""Nonlinear model predictive control (NMPC) on the process plant: CasADi Opti + IPOPT.

Every `dt_s` seconds the controller solves, from the plant's measured full state x (an
oracle: `uses_state = True`, see controllers.base), the optimal-control problem

    maximise   sum_k  -u_k (x_p(k+1) - x_p(k))  -  R dt_s u_k^2  -  slack cost
    subject to x(k+1) = RK4(f, x(k), u_k, w)           (multiple shooting, N = horizon / dt_s)
               |u_k| <= force_max,  |u_k - u_k-1| <= rate_max dt_s       (hard)
               |x_p| <= stroke_max + s_k,  s_k >= 0   at every RK4 substep (soft)

and applies u_0 (zero-order hold). x_p is the PTO position (plant.h): the first sum is the
work the PTO absorbs with its force held over each step, exact for a zero-order hold (as
mbcontrol.analysis.metrics counts it). R (`force_penalty`, W/N^2) charges a loss R u^2, e.g. a
generator's copper loss; a small default keeps the optimum unique. The stroke limit is soft
(slack with an L1 + quadratic cost) so that the problem is always feasible; the L1 weight
makes it an exact penalty: no planned overshoot whenever one can be avoided.

The prediction model is the nonlinear process plant f itself (or `model`, a plant with the
same states, e.g. its linear-hydrostatics twin for comparisons), RK4 with `substeps` steps
per dt_s and the excitation at half steps from the wave (a perfect forecast:
plant.excitation(wave, t), what simulate applies). The Opti problem is built once, in
reset(), with parameters for x0, the forecast and the previous command, and turned into one
CasADi Function (`opti.to_function`); each call warm-starts it from the previous plan and
its multipliers, shifted by one step. As the linear MPC, the NMPC is three parts: its
settings (`NmpcSettings`, frozen: controllers.nmpc_settings), the setup built from a plant
(`NmpcSetup`: limits, scales, the compiled problem; controllers.nmpc_setup) and the data
of one run (`NmpcRun`: the plan, the command held, the counters). States are scaled by their size in the free response
to the wave (the sphere's radiation states reach 1e4 while heave is metres).

A failed solve (IPOPT not converged: iteration or time limit, restoration failure, an
evaluation error, a non-finite state) never stops a simulation: the controller applies the
previous plan's next command (clipped to the force and rate limits) and counts the failure.
Counters and solve times are in describe() and so in the results' attrs.
"""
from __future__ import annotations

import math
import time

import numpy as np

from mbcontrol.errors import ControllerError

from .law import PredictiveLaw
from .nmpc_settings import SETTING_NAMES, NmpcSettings
from .nmpc_setup import NmpcRun, NmpcSetup, build_setup

STATE_NOTE = ("full-state feedback: an oracle that reads the plant's whole state x, "
              "radiation states included (no real device measures them)")
# the NMPC forecasts with the true future excitation and reads the true state: its power is
# a non-causal upper bound, and its results say so (as an MPC asked for forecast "known")
ORACLE_LABEL = "non-causal upper bound (true future wave, full state)"


class Nmpc(PredictiveLaw):
    """Nonlinear MPC of one PTO's force, maximising absorbed energy over a receding horizon.

    wave: the sea the controller forecasts (excitation known exactly; required): a
    non-causal oracle, labelled as an upper bound in describe() ("oracle", "label").
    horizon_s (s), dt_s (s): prediction horizon and controller period; dt_s must divide
    horizon_s, and simulate's dt must divide dt_s. substeps: RK4 steps per dt_s in the model
    (RK4 is stable for |lambda| h <= 2.78: the sphere's fastest radiation pole, -16.7 1/s,
    needs h <= 0.166 s, so 2 substeps at dt_s = 0.24 s).
    force_max (N or N m), stroke_max (m or rad): None takes the scene PTO's limits, inf lifts
    them. rate_max (N/s or N m/s): None, unlimited.
    force_penalty R (W/N^2): the loss R u^2 subtracted from the absorbed power; None: the
    small regulariser 1e-3 stroke_scale / (force_scale horizon_s) (2e-10 W/N^2 on the
    sphere: 800 W at 2 MN, 0.1 % of its power).
    stroke_penalty: weight w of the stroke slack s_k (m or rad; one per step, covering its
    substep points), cost w force_scale (s_k + s_k^2 / stroke_scale) J: with w >= 1 an
    overshoot costs more than the work a force within force_max gains through it (10 by
    default; measured on the sphere: largest applied slack 5e-8 m).
    pto: the PTO it drives (default the first); other PTOs get zero command (free).
    model: the plant used for prediction (default: the controlled plant; same states and
    inputs). params: parameter overrides for the prediction model (every PTO's damping and
    stiffness are zero, as simulate sets them in closed loop).
    max_iter, tol, max_cpu_time (s, per solve), ipopt (dict): IPOPT settings.

    settings: NmpcSettings (its settings read as attributes too: nmpc.horizon_s); setup:
    NmpcSetup of the last reset(plant) (None before); run: NmpcRun of this run (its counters
    and last plan read as attributes too: nmpc.failures, nmpc.plan_force).
    """
    name = "nmpc"     # the law protocol (controllers.law): a predictive law, not exported
    uses_state = True
    export_refusal = "NMPC's solver, IPOPT, generates no C"    # why not (mbcontrol.export)
    RUN_FIELDS = ("plan_force", "solves", "failures", "solve_times", "iterations", "statuses",
                  "slack_max")

    def __init__(self, wave, *, horizon_s: float = 10.0, dt_s: float = 0.25, substeps: int = 2,
                 force_max: float | None = None, stroke_max: float | None = None,
                 rate_max: float | None = None, force_penalty: float | None = None,
                 stroke_penalty: float = 10.0, pto: str | None = None, model=None,
                 params: dict | None = None, max_iter: int = 200, tol: float = 1e-6,
                 max_cpu_time: float | None = None, ipopt: dict | None = None):
        self.settings = NmpcSettings(
            wave, horizon_s=horizon_s, dt_s=dt_s, substeps=substeps, force_max=force_max,
            stroke_max=stroke_max, rate_max=rate_max, force_penalty=force_penalty,
            stroke_penalty=stroke_penalty, pto=pto, model=model, params=params,
            max_iter=max_iter, tol=tol, max_cpu_time=max_cpu_time, ipopt=ipopt)
        self.setup: NmpcSetup | None = None
        self.run: NmpcRun = NmpcRun()

    def __getattr__(self, name):
        """A setting (nmpc.horizon_s) or a run's counter or plan (nmpc.failures), read-only."""
        if name in SETTING_NAMES:
            return getattr(self.__dict__["settings"], name)
        if name in Nmpc.RUN_FIELDS:
            return getattr(self.__dict__["run"], name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def period(self) -> float:
        """s: the control period (zero-order hold), dt_s."""
        return self.settings.dt_s

    # ------------------------------------------------------------------ building (once)
    def reset(self, plant) -> None:
        """Bind to `plant`: resolve limits and scales, build and compile the Opti problem
        (the setup), start a fresh run."""
        self.setup = build_setup(self.settings, plant)
        self.run = self.setup.new_run()

    # ------------------------------------------------------------------ each period
    def __call__(self, t: float, y, x) -> np.ndarray:
        """PTO force command(s) (N or N m, one per plant input) at time t (s) from state x."""
        s, r = self.setup, self.run
        if s is None:
            raise RuntimeError("nmpc: call reset(plant) before using the controller")
        x = np.asarray(x, float).ravel()
        W = s.forecast(t)
        start = time.perf_counter()
        ok, status = False, "non-finite state or forecast"
        if np.all(np.isfinite(x)) and np.all(np.isfinite(W)):
            X0, U0, S0 = self._guess(x, W)
            lam0 = r.lam if r.lam is not None else np.zeros(s.ng)
            try:
                X, U, S, lam = s.solver(x, W, r.u_last, X0, U0, S0, lam0)
                stats = s.solver.stats()
                ok, status = bool(stats.get("success")), stats.get("return_status", "?")
                r.iterations.append(int(stats.get("iter_count", -1)))
            except RuntimeError as exc:         # an evaluation error inside the solver
                status = f"error: {str(exc).splitlines()[0][:80]}"
            if ok:
                U = np.asarray(U).ravel()
                ok = bool(np.all(np.isfinite(U)))
        r.solve_times.append(time.perf_counter() - start)
        r.solves += 1
        r.statuses[status] = r.statuses.get(status, 0) + 1
        if ok:
            r.plan, r.age = (np.asarray(X), U, np.asarray(S).ravel()), 0
            r.lam = np.asarray(lam).ravel()
            r.slack_max = max(r.slack_max, float(r.plan[2][0]))
            r.plan_force = U * s.fs
            u = self._clip(float(U[0]))
        else:
            r.failures += 1
            u = self._fallback()
        r.u_last = u
        out = np.zeros(s.nu)
        out[s.i_u] = u * s.fs
        return out

    def _fallback(self) -> float:
        """Command (/ force scale) after a failed solve: the last plan's next one (0 before
        any plan), clipped to the force and rate limits."""
        r = self.run
        u = 0.0
        if r.plan is not None:
            r.age += 1
            U = r.plan[1]
            u = float(U[min(r.age, U.size - 1)])
        return self._clip(u)

    def _clip(self, u: float) -> float:
        """u (/ force scale) within the rate and force limits: IPOPT meets its bounds only to
        its tolerance (relaxed by 1e-8 relative), the applied force meets them exactly."""
        s, u_last = self.setup, self.run.u_last
        r = s.rate * self.settings.dt_s / s.fs
        u = float(np.clip(u, u_last - r, u_last + r))
        lim = s.fmax / s.fs
        return float(np.clip(u, -lim, lim))

    def _guess(self, x, W):
        """Initial guess (scaled): the last plan shifted by the periods since it began, its
        tail repeated; before any plan, a rollout from x with zero force."""
        s, r = self.setup, self.run
        N = self.settings.n
        if r.plan is None:
            U = np.zeros((1, N))
            X = np.hstack([x[:, None], np.asarray(s.rollout(x, U, W))])
            return X / s.xs[:, None], U, np.zeros((1, N))
        Xp, Up, Sp = r.plan
        shift = r.age + 1
        X = Xp[:, np.minimum(np.arange(N + 1) + shift, N)].copy()
        X[:, 0] = x / s.xs
        cols = np.minimum(np.arange(N) + shift, N - 1)
        return X, Up[cols][None, :], Sp[cols][None, :]

    # ------------------------------------------------------------------ protocol
    def casadi_law(self, plant):
        return None                  # an optimiser, not a static law of y

    def describe(self) -> dict:
        """Settings, the state note (full-state oracle) and the solver counters."""
        st, s, r = self.settings, self.setup, self.run
        times = np.asarray(r.solve_times)
        finite = (lambda v: v if v is None or math.isfinite(v) else None)   # JSON: no inf
        out = {"name": self.name, "state": STATE_NOTE, "wave": st.wave.describe(),
               "forecast": "known", "oracle": True, "label": ORACLE_LABEL,
               "horizon_s": st.horizon_s, "dt_s": st.dt_s, "period_s": self.period,
               "substeps": st.substeps, "pto": st.pto if s is None else s.pto_name,
               "force_max": finite(st.force_max if s is None else s.fmax),
               "stroke_max": finite(st.stroke_max if s is None else s.smax),
               "rate_max": st.rate_max,
               "force_penalty_W_per_N2": st.force_penalty if s is None else s.R,
               "stroke_penalty": st.stroke_penalty,
               "model": None if st.model is None else st.model.name,
               "params": dict(st.params), "max_iter": st.max_iter, "tol": st.tol,
               "max_cpu_time_s": st.max_cpu_time, "ipopt": dict(st.ipopt),
               "solves": r.solves, "failures": r.failures, "statuses": r.statuses,
               "stroke_slack_max": r.slack_max}
        if times.size:
            out.update({"solve_time_median_s": float(np.median(times)),
                        "solve_time_p95_s": float(np.percentile(times, 95)),
                        "solve_time_max_s": float(times.max()),
                        "iterations_mean": float(np.mean(r.iterations))
                        if r.iterations else None})
        return out
