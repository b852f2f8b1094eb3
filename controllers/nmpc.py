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
its multipliers, shifted by one step. States are scaled by their size in the free response
to the wave (the sphere's radiation states reach 1e4 while heave is metres).

A failed solve (IPOPT not converged: iteration or time limit, restoration failure, an
evaluation error, a non-finite state) never stops a simulation: the controller applies the
previous plan's next command (clipped to the force and rate limits) and counts the failure.
Counters and solve times are in describe() and so in the results' attrs.
"""
from __future__ import annotations

import math
import time

import casadi as ca
import numpy as np

from mbcontrol.errors import ControllerError, UnknownName
from mbcontrol.sim import rk4_step

from .base import signal_indices
from .law import PredictiveLaw

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
    """
    name = "nmpc"     # the law protocol (controllers.law): a predictive law, not exported
    uses_state = True
    export_refusal = "NMPC's solver, IPOPT, generates no C"    # why not (mbcontrol.export)

    def __init__(self, wave, *, horizon_s: float = 10.0, dt_s: float = 0.25, substeps: int = 2,
                 force_max: float | None = None, stroke_max: float | None = None,
                 rate_max: float | None = None, force_penalty: float | None = None,
                 stroke_penalty: float = 10.0, pto: str | None = None, model=None,
                 params: dict | None = None, max_iter: int = 200, tol: float = 1e-6,
                 max_cpu_time: float | None = None, ipopt: dict | None = None):
        if wave is None:
            raise ControllerError("Nmpc needs the wave it forecasts (wave=...)")
        n = round(horizon_s / dt_s) if dt_s > 0 else 0
        if n < 1 or abs(n * dt_s - horizon_s) > 1e-9 * horizon_s:
            raise ControllerError(f"horizon_s ({horizon_s}) must be a whole number >= 1 of "
                                  f"dt_s ({dt_s})")
        if substeps < 1 or stroke_penalty <= 0 or (force_penalty is not None
                                                   and force_penalty < 0):
            raise ControllerError("expected substeps >= 1, stroke_penalty > 0, force_penalty >= 0")
        if rate_max is not None and rate_max <= 0:
            raise ControllerError(f"rate_max must be > 0 (N/s) or None, got {rate_max}")
        self.wave, self.horizon_s, self.dt_s, self.substeps = wave, horizon_s, dt_s, substeps
        self.force_max, self.stroke_max, self.rate_max = force_max, stroke_max, rate_max
        self.force_penalty, self.stroke_penalty = force_penalty, stroke_penalty
        self.pto, self.model, self.params = pto, model, dict(params or {})
        self.max_iter, self.tol, self.max_cpu_time = max_iter, tol, max_cpu_time
        self.ipopt = dict(ipopt or {})
        self.period = dt_s            # s, zero-order hold
        self._n = n
        self._solver = None
        self._reset_counters()

    # ------------------------------------------------------------------ building (once)
    def reset(self, plant) -> None:
        """Bind to `plant`: resolve limits and scales, build and compile the Opti problem."""
        model = self.model if self.model is not None else plant
        if tuple(model.states) != tuple(plant.states) or \
                tuple(model.inputs) != tuple(plant.inputs):
            raise ControllerError(f"nmpc: prediction model {model.name!r} must have the states and "
                                  f"inputs of the plant {plant.name!r}")
        ptos = {p.name: p for p in plant.scene.ptos}
        name = self.pto or plant.scene.ptos[0].name
        if name not in ptos:
            raise UnknownName(f"{plant.name}: no PTO {name!r}; PTOs are {', '.join(ptos)}")
        self._model, self._pto_name, self._nu = model, name, len(plant.inputs)
        self._i_u = plant.inputs.index(f"u__{name}")
        zero_law = {f"{p.name}__{k}": 0.0 for p in plant.scene.ptos
                    for k in ("damping", "stiffness")}
        p = model.params(**{**zero_law, **self.params})

        if self.force_max is None and ptos[name].limited_force() == "hull":
            raise ControllerError(f"nmpc: PTO {name!r} limits the force on the hull (force_max_on = "
                                  f"'hull'); the NMPC limits the machine's command only: give it "
                                  f"force_max (a machine limit) explicitly")
        fmax = ptos[name].force_max if self.force_max is None else self.force_max
        smax = ptos[name].stroke_max if self.stroke_max is None else self.stroke_max
        self._fmax, self._smax = float(fmax), float(smax)
        self._rate = math.inf if self.rate_max is None else float(self.rate_max)
        # scales that make the unknowns of order one; unlimited quantities fall back to the
        # wave's largest excitation force and 1 m (or rad)
        self._fs = self._fmax if math.isfinite(self._fmax) else self._excitation_scale(model)
        self._ss = self._smax if math.isfinite(self._smax) else 1.0
        self._R = float(self.force_penalty if self.force_penalty is not None
                        else 1e-3 * self._ss / (self._fs * self.horizon_s))

        N, m = self._n, self.substeps
        self._half = np.arange(2 * N * m + 1) * self.dt_s / m / 2    # forecast offsets, s
        # step k's excitation window: half-grid rows 2mk .. 2m(k+1)
        self._windows = 2 * m * np.arange(N)[:, None] + np.arange(2 * m + 1)[None, :]
        step, pos = self._step_functions(model, p, signal_indices(model, [f"{name}__position"])[0])
        args = step.mx_in()
        self._rollout = ca.Function("nmpc_step_x", args, [step(*args)[0]]).mapaccum(
            "nmpc_rollout", N)                         # N periods: cold starts, state scales
        self._xs = self._state_scale(model)
        self._build(model, step, pos)
        self._plan = None            # (X scaled, U scaled, S) of the last successful solve
        self._lam = None             # its constraint multipliers
        self._age = 0                # controller periods since that plan began
        self._u_last = 0.0           # command last applied, / force scale
        self.plan_force = None       # N or N m: the last successful plan's forces
        self._reset_counters()

    def _step_functions(self, model, p, i_pos):
        """(step, pos): one controller period of the model (m RK4 substeps, the force held)
        -> (x_next, PTO position after each substep); and the PTO position of a state."""
        m, nx, nw = self.substeps, model.nx, len(model.disturbances)
        rk4 = rk4_step(model)
        x, us = ca.SX.sym("x", nx), ca.SX.sym("u")             # us: force / force scale
        wseg = ca.SX.sym("w", nw, 2 * m + 1)
        u_full = ca.SX.zeros(self._nu)
        u_full[self._i_u] = us * self._fs
        pos = ca.Function("nmpc_pos", [x], [model.h(x, ca.DM.zeros(self._nu),
                                                    ca.DM.zeros(nw), p)[i_pos]])
        xn, xp_sub = x, []
        for j in range(m):
            xn = rk4(xn, u_full, wseg[:, 2 * j:2 * j + 3], p, self.dt_s / m)[0]
            xp_sub.append(pos(xn))
        # the stroke is checked at every substep: sampled at dt_s = 0.24 s alone, a 4 m
        # stroke at 0.65 rad/s can overshoot between samples by 4 (1/cos(0.65 dt_s/2) - 1) = 1.2 cm
        step = ca.Function("nmpc_step", [x, us, ca.vec(wseg)], [xn, ca.horzcat(*xp_sub)])
        return step, pos

    def _build(self, model, step, pos) -> None:
        N, m, nx, nw = self._n, self.substeps, model.nx, len(model.disturbances)
        fs, ss = self._fs, self._ss
        opti = ca.Opti()
        Xv = opti.variable(nx, N + 1)                  # states / xs
        xs = ca.DM(self._xs)
        X = ca.repmat(xs, 1, N + 1) * Xv
        U = opti.variable(1, N)                        # force / force scale
        S = opti.variable(1, N)                        # stroke slack, m or rad
        x0, W = opti.parameter(nx), opti.parameter(nw * (2 * m + 1), N)
        u_prev = opti.parameter()
        opti.subject_to(Xv[:, 0] == x0 / xs)
        X_next, xp_sub = step.map(N)(X[:, :N], U, W)   # (nx, N), (1, N m)
        opti.subject_to(Xv[:, 1:] == X_next / ca.repmat(xs, 1, N))
        xp = pos.map(N + 1)(X)
        energy = -ca.sum2(U * (xp[1:] - xp[:N])) * fs                 # J, absorbed
        loss = self._R * self.dt_s * fs ** 2 * ca.sumsqr(U)            # J
        slack = self.stroke_penalty * fs * ca.sum2(S + S ** 2 / ss)   # J
        opti.minimize((loss - energy + slack) / (fs * ss))            # order one
        if math.isfinite(self._fmax):
            opti.subject_to(opti.bounded(-self._fmax / fs, U, self._fmax / fs))
        if math.isfinite(self._rate):
            r = self._rate * self.dt_s / fs
            opti.subject_to(opti.bounded(-r, ca.diff(ca.horzcat(u_prev, U), 1, 1), r))
        opti.subject_to(S >= 0)
        if math.isfinite(self._smax):
            S_sub = ca.kron(S, ca.DM.ones(1, m))       # step k's slack on its substeps
            opti.subject_to(opti.bounded(-self._smax - S_sub, xp_sub, self._smax + S_sub))
        # warm start from the shifted plan and multipliers with a small barrier parameter:
        # 8.4 iterations a solve on the sphere (force and stroke limits) against 13.3 from
        # the primal guess alone
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self.max_iter, "tol": self.tol,
                 "warm_start_init_point": "yes", "mu_init": 1e-4,
                 **({"max_cpu_time": self.max_cpu_time} if self.max_cpu_time else {}),
                 **self.ipopt}
        opti.solver("ipopt", {"expand": True, "print_time": False}, ipopt)
        self._solver = opti.to_function("nmpc_ocp", [x0, W, u_prev, Xv, U, S, opti.lam_g],
                                        [Xv, U, S, opti.lam_g],
                                        ["x0", "W", "u_prev", "X", "U", "S", "lam_g"],
                                        ["X_opt", "U_opt", "S_opt", "lam_g_opt"])
        self._ng = opti.ng

    def _forecast(self, t: float) -> np.ndarray:
        """Excitation windows (n_w (2m+1), N) of the horizon starting at t (s)."""
        w = self._model.excitation(self.wave, t + self._half)          # (2Nm+1, n_w)
        N = self._n
        return w[self._windows].transpose(0, 2, 1).reshape(N, -1).T

    def _state_scale(self, model) -> np.ndarray:
        """Typical size of each state: its largest value in the model's free response (zero
        force) to the wave from rest, over the ramp plus 60 s; 1 for states left at rest."""
        N = self._n
        t0, x, peak = 0.0, np.zeros(model.nx), np.zeros(model.nx)
        while t0 < max(self.wave.ramp_time + 60.0, 4 * self.horizon_s):
            X = np.asarray(self._rollout(x, np.zeros((1, N)), self._forecast(t0)))
            peak = np.maximum(peak, np.abs(X).max(axis=1))
            x, t0 = X[:, -1], t0 + self.horizon_s
        if not np.all(np.isfinite(peak)) or peak.max() > 1e12:
            raise ControllerError(f"nmpc: the prediction model diverges with {self.substeps} RK4 "
                                  f"substep(s) of {self.dt_s / self.substeps:.4g} s; raise substeps")
        return np.where(peak > 1e-9 * max(peak.max(), 1e-300), peak, 1.0)

    def _excitation_scale(self, model) -> float:
        t = np.arange(0.0, max(4 * self.horizon_s, 2 * self.wave.ramp_time + 60.0), 0.1)
        scale = float(np.max(np.abs(model.excitation(self.wave, t)), initial=0.0))
        return scale if scale > 0 else 1.0

    def _reset_counters(self) -> None:
        self.solves, self.failures = 0, 0
        self.solve_times: list[float] = []      # s, wall time of each solve
        self.iterations: list[int] = []         # IPOPT iterations of each solve
        self.statuses: dict[str, int] = {}      # IPOPT return status -> count
        self.slack_max = 0.0                    # m or rad: largest first-step stroke slack

    # ------------------------------------------------------------------ each period
    def __call__(self, t: float, y, x) -> np.ndarray:
        """PTO force command(s) (N or N m, one per plant input) at time t (s) from state x."""
        if self._solver is None:
            raise RuntimeError("nmpc: call reset(plant) before using the controller")
        x = np.asarray(x, float).ravel()
        W = self._forecast(t)
        start = time.perf_counter()
        ok, status = False, "non-finite state or forecast"
        if np.all(np.isfinite(x)) and np.all(np.isfinite(W)):
            X0, U0, S0 = self._guess(x, W)
            lam0 = self._lam if self._lam is not None else np.zeros(self._ng)
            try:
                X, U, S, lam = self._solver(x, W, self._u_last, X0, U0, S0, lam0)
                stats = self._solver.stats()
                ok, status = bool(stats.get("success")), stats.get("return_status", "?")
                self.iterations.append(int(stats.get("iter_count", -1)))
            except RuntimeError as exc:         # an evaluation error inside the solver
                status = f"error: {str(exc).splitlines()[0][:80]}"
            if ok:
                U = np.asarray(U).ravel()
                ok = bool(np.all(np.isfinite(U)))
        self.solve_times.append(time.perf_counter() - start)
        self.solves += 1
        self.statuses[status] = self.statuses.get(status, 0) + 1
        if ok:
            self._plan, self._age = (np.asarray(X), U, np.asarray(S).ravel()), 0
            self._lam = np.asarray(lam).ravel()
            self.slack_max = max(self.slack_max, float(self._plan[2][0]))
            self.plan_force = U * self._fs
            u = self._clip(float(U[0]))
        else:
            self.failures += 1
            u = self._fallback()
        self._u_last = u
        out = np.zeros(self._nu)
        out[self._i_u] = u * self._fs
        return out

    def _fallback(self) -> float:
        """Command (/ force scale) after a failed solve: the last plan's next one (0 before
        any plan), clipped to the force and rate limits."""
        u = 0.0
        if self._plan is not None:
            self._age += 1
            U = self._plan[1]
            u = float(U[min(self._age, U.size - 1)])
        return self._clip(u)

    def _clip(self, u: float) -> float:
        """u (/ force scale) within the rate and force limits: IPOPT meets its bounds only to
        its tolerance (relaxed by 1e-8 relative), the applied force meets them exactly."""
        r = self._rate * self.dt_s / self._fs
        u = float(np.clip(u, self._u_last - r, self._u_last + r))
        lim = self._fmax / self._fs
        return float(np.clip(u, -lim, lim))

    def _guess(self, x, W):
        """Initial guess (scaled): the last plan shifted by the periods since it began, its
        tail repeated; before any plan, a rollout from x with zero force."""
        N = self._n
        if self._plan is None:
            U = np.zeros((1, N))
            X = np.hstack([x[:, None], np.asarray(self._rollout(x, U, W))])
            return X / self._xs[:, None], U, np.zeros((1, N))
        Xp, Up, Sp = self._plan
        shift = self._age + 1
        X = Xp[:, np.minimum(np.arange(N + 1) + shift, N)].copy()
        X[:, 0] = x / self._xs
        cols = np.minimum(np.arange(N) + shift, N - 1)
        return X, Up[cols][None, :], Sp[cols][None, :]

    # ------------------------------------------------------------------ protocol
    def casadi_law(self, plant):
        return None                  # an optimiser, not a static law of y

    def describe(self) -> dict:
        """Settings, the state note (full-state oracle) and the solver counters."""
        times = np.asarray(self.solve_times)
        finite = (lambda v: v if v is None or math.isfinite(v) else None)   # JSON: no inf
        out = {"name": self.name, "state": STATE_NOTE, "wave": self.wave.describe(),
               "forecast": "known", "oracle": True, "label": ORACLE_LABEL,
               "horizon_s": self.horizon_s, "dt_s": self.dt_s, "period_s": self.period,
               "substeps": self.substeps, "pto": getattr(self, "_pto_name", self.pto),
               "force_max": finite(getattr(self, "_fmax", self.force_max)),
               "stroke_max": finite(getattr(self, "_smax", self.stroke_max)),
               "rate_max": self.rate_max,
               "force_penalty_W_per_N2": getattr(self, "_R", self.force_penalty),
               "stroke_penalty": self.stroke_penalty,
               "model": None if self.model is None else self.model.name,
               "params": self.params, "max_iter": self.max_iter, "tol": self.tol,
               "max_cpu_time_s": self.max_cpu_time, "ipopt": self.ipopt,
               "solves": self.solves, "failures": self.failures, "statuses": self.statuses,
               "stroke_slack_max": self.slack_max}
        if times.size:
            out.update({"solve_time_median_s": float(np.median(times)),
                        "solve_time_p95_s": float(np.percentile(times, 95)),
                        "solve_time_max_s": float(times.max()),
                        "iterations_mean": float(np.mean(self.iterations))
                        if self.iterations else None})
        return out
