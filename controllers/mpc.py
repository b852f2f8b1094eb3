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


class CondensedQp:
    """The MPC's QP in the forces alone (states eliminated), scaled to O(1) and built once.

    Variables (scaled): U / F_s (N nu, step-major) and, with a finite stroke limit and
    soft_stroke, slacks s / L_s (N nu). F_s: the force limit (or L_s / lambda_max(G) if
    unlimited); L_s: the stroke limit (or 1 m). solve(z0, D, u_prev, warm) -> (U (N, nu) or
    None, status).
    """

    def __init__(self, cp, N: int, limits: dict, *, efficiency, loss_damping,
                 force_penalty: float, stroke_penalty: float, soft_stroke: bool, solver: str):
        nu, nz = len(cp.ptos), cp.nz
        self.N, self.nu, self.solver = N, nu, solver
        # prediction of the positions at the ends of steps 1..N
        powers = [np.eye(nz)]
        for _ in range(N):
            powers.append(cp.Ad @ powers[-1])
        Phi = np.vstack([cp.Cp @ powers[k] for k in range(1, N + 1)])          # (N nu, nz)
        Psi = np.zeros((N * nu, N * nu))
        Om = np.zeros((N * nu, N * cp.nd))
        for k in range(1, N + 1):
            for j in range(k):
                Psi[(k - 1) * nu:k * nu, j * nu:(j + 1) * nu] = cp.Cp @ powers[k - 1 - j] @ cp.Bu
                Om[(k - 1) * nu:k * nu, j * cp.nd:(j + 1) * cp.nd] = cp.Cp @ powers[k - 1 - j] @ cp.Bd
        L = np.eye(N * nu) - np.eye(N * nu, k=-nu)       # P -> increments
        E = np.zeros((N * nu, nu))
        E[:nu] = np.eye(nu)
        G = L @ Psi
        Gs = 0.5 * (G + G.T)
        lam = float(np.max(np.linalg.eigvalsh(Gs)))
        if lam <= 0:
            raise ValueError("mpc: the control plant absorbs no energy from the PTO (energy "
                             "Hessian not positive); check the PTO and the model")
        self.passivity_defect = float(max(-np.min(np.linalg.eigvalsh(Gs)) / lam, 0.0))
        force, stroke, rate = limits["force"], limits["stroke"], limits["rate"]
        Ls = float(np.max(stroke)) if np.all(np.isfinite(stroke)) else 1.0
        Fs = float(np.max(force)) if np.all(np.isfinite(force)) else Ls / lam
        r = force_penalty * lam
        # electrical power with efficiency eta: P_e = a P - (1/eta - eta)/2 |P|, a = (eta +
        # 1/eta)/2, and |P| <= (F^2/c + c v^2)/2 for any c > 0 (equal at |F| = c |v|): a
        # concave minorant, with c the device's impedance |Z_i| (the passive optimum) and
        # v = increment / dt. With increments G U + q the minimised cost (J) is
        #   U'(aG)U + a q'U + b dt/c |U|^2 + b c/dt |G U + q|^2,   b = (1/eta - eta)/4
        eta = np.tile(np.asarray(efficiency, float), N)
        a, b = 0.5 * (eta + 1 / eta), 0.25 * (1 / eta - eta)
        c = np.tile(np.asarray(loss_damping, float), N)
        loss_u, loss_v = b * cp.dt / c, b * c / cp.dt
        quad = 0.5 * (a[:, None] * G + (a[:, None] * G).T) + np.diag(loss_u) \
            + G.T @ (loss_v[:, None] * G) + r * np.eye(N * nu)
        # scaled (objective / (F_s L_s)), clipped to PSD against round-off
        w, V = np.linalg.eigh(2 * Fs / Ls * quad)
        self.H_u = (V * np.clip(w, 2 * r * Fs / Ls * 1e-3, None)) @ V.T
        W = np.diag(a) + 2 * G.T * loss_v[None, :]          # linear term W q
        self.Qz = W @ (L @ Phi - E @ cp.Cp) / Ls             # q = Qz z0 + Qd D (scaled)
        self.Qd = W @ (L @ Om) / Ls
        self.Phi, self.Om, self.Psi = Phi, Om, Psi
        self.Fs, self.Ls, self.stroke_penalty = Fs, Ls, stroke_penalty
        self.has_stroke = bool(np.all(np.isfinite(stroke)))
        self.stroke = np.tile(stroke, N) / Ls
        self.force = np.tile(force, N) / Fs
        self.has_rate = bool(np.all(np.isfinite(rate)))
        self.rate = np.tile(rate * cp.dt, N) / Fs
        backend = _QpoasesBackend if solver == "qpoases" else _CvxpyBackend
        # the exact L1 penalty makes the soft QP's solution the hard one's whenever the hard
        # QP is feasible: solve the hard QP (half the variables) and the soft one only when
        # it is infeasible
        self.forms = [_QpForm(self, soft=False, backend=backend)]
        if soft_stroke and self.has_stroke:
            self.forms.append(_QpForm(self, soft=True, backend=backend))
        self._last, self.soft_solves = 0, 0

    def solve(self, z0, D, u_prev, warm=None):
        """(U (N, nu) N or N m, status), or (None, status) when no form could be solved."""
        z0, D, u_prev = np.asarray(z0, float), np.asarray(D, float), np.asarray(u_prev, float)
        free = (self.Phi @ z0 + self.Om @ D.reshape(-1)) / self.Ls   # positions with U = 0
        q = self.Qz @ z0 + self.Qd @ D.reshape(-1)
        status = "not solved"
        # start with the form that solved last time: the hard QP is infeasible for stretches
        # (a wave group), and an active-set solver takes long to prove infeasibility
        order = self.forms if self._last == 0 else self.forms[::-1]
        for form in order:
            sol, status, slack = form.solve(q, free, u_prev, warm)
            if sol is not None:
                # back to the hard form once the slack is no longer used
                self._last = int(form.soft and slack > 1e-6)
                self.soft_solves += int(form.soft)
                return (sol * self.Fs).reshape(self.N, self.nu), status
        return None, status


class _QpForm:
    """One layout of the condensed QP: hard stroke limits (variables U) or soft (U, slack).
    Rows: stroke (Psi U, or Psi U -/+ s), then force rate (differences of U)."""

    def __init__(self, qp, *, soft: bool, backend):
        N, nu = qp.N, qp.nu
        self.qp, self.soft, self.n_u = qp, soft, N * nu
        n_s = N * nu if soft else 0
        self.n_var = N * nu + n_s
        rows = []
        if qp.has_stroke:
            S = qp.Fs / qp.Ls * qp.Psi
            rows += [np.hstack([S, -np.eye(n_s)]), np.hstack([S, np.eye(n_s)])] if soft else [S]
        if qp.has_rate:
            Dr = np.eye(N * nu) - np.eye(N * nu, k=-nu)
            rows += [np.hstack([Dr, np.zeros((N * nu, n_s))])]
        self.A = np.vstack(rows) if rows else np.zeros((0, self.n_var))
        self.H = np.zeros((self.n_var, self.n_var))
        self.H[:N * nu, :N * nu] = qp.H_u
        self.g_slack = np.zeros(self.n_var)
        if soft:
            self.H[N * nu:, N * nu:] = 2 * qp.stroke_penalty * np.eye(n_s)
            self.g_slack[N * nu:] = qp.stroke_penalty
        self.lbx = np.concatenate([-qp.force, np.zeros(n_s)])
        self.ubx = np.concatenate([qp.force, np.full(n_s, np.inf)])
        self.backend = backend(self)

    def bounds(self, q, free, u_prev):
        """(g, lba, uba) for the linear cost term q, the free positions and the last force."""
        qp, n = self.qp, self.n_u
        g = self.g_slack.copy()
        g[:n] += q
        lba, uba = [], []
        if qp.has_stroke:
            if self.soft:
                lba += [np.full(n, -np.inf), -qp.stroke - free]
                uba += [qp.stroke - free, np.full(n, np.inf)]
            else:
                lba += [-qp.stroke - free]
                uba += [qp.stroke - free]
        if qp.has_rate:
            first = np.zeros(n)
            first[:qp.nu] = u_prev / qp.Fs
            lba += [first - qp.rate]
            uba += [first + qp.rate]
        join = (lambda parts: np.concatenate(parts) if parts else np.zeros(0))
        return g, join(lba), join(uba)

    def solve(self, q, free, u_prev, warm):
        g, lba, uba = self.bounds(q, free, u_prev)
        x0 = np.zeros(self.n_var)
        if warm is not None:
            x0[:self.n_u] = np.vstack([warm[1:], warm[-1:]]).ravel() / self.qp.Fs
        sol, status = self.backend.solve(g, self.lbx, self.ubx, lba, uba, x0)
        if sol is None:
            return None, status, 0.0
        return sol[:self.n_u], status, float(np.max(sol[self.n_u:], initial=0.0))


class _QpoasesBackend:
    """Dense qpOASES through CasADi's conic interface; H and A fixed, built once."""

    def __init__(self, form):
        import casadi as ca
        self.H, self.A = form.H, form.A
        self.called = False
        opts = {"printLevel": "none", "sparse": False, "error_on_fail": False,
                "hessian_type": "posdef"}
        self.solver = _quiet(lambda: ca.conic(
            "mpc_qp", "qpoases", {"h": ca.DM(form.H).sparsity(), "a": ca.DM(form.A).sparsity()},
            opts))

    def solve(self, g, lbx, ubx, lba, uba, x0):
        call = (lambda: self.solver(h=self.H, a=self.A, g=g, lbx=lbx, ubx=ubx, lba=lba,
                                    uba=uba, x0=x0))
        if not self.called:                 # qpOASES prints its banner on the first solve
            self.called = True
            out = _quiet(call)
        else:
            out = call()
        stats = self.solver.stats()
        if not stats.get("success", False):
            return None, str(stats.get("return_status", "failed"))
        return np.asarray(out["x"]).ravel(), "solved"


class _CvxpyBackend:
    """cvxpy with Parameters (built once, DPP), solved by Clarabel."""

    def __init__(self, form):
        import cvxpy as cp
        n = form.n_var
        self.x = cp.Variable(n)
        self.g = cp.Parameter(n)
        w, V = np.linalg.eigh(form.H)
        factor = V * np.sqrt(np.clip(w, 0, None))[None, :]
        lo, hi = np.isfinite(form.lbx), np.isfinite(form.ubx)
        cons = [self.x[np.flatnonzero(lo)] >= form.lbx[lo]] if lo.any() else []
        if hi.any():
            cons.append(self.x[np.flatnonzero(hi)] <= form.ubx[hi])
        # which rows have finite bounds is fixed by the layout: probe it once
        _, lba, uba = form.bounds(np.zeros(form.n_u), np.zeros(form.n_u), np.zeros(form.qp.nu))
        self.lo_rows, self.hi_rows = np.flatnonzero(np.isfinite(lba)), np.flatnonzero(np.isfinite(uba))
        self.lba, self.uba = cp.Parameter(self.lo_rows.size), cp.Parameter(self.hi_rows.size)
        if self.lo_rows.size:
            cons.append(form.A[self.lo_rows] @ self.x >= self.lba)
        if self.hi_rows.size:
            cons.append(form.A[self.hi_rows] @ self.x <= self.uba)
        objective = 0.5 * cp.sum_squares(factor.T @ self.x) + self.g @ self.x
        self.problem = cp.Problem(cp.Minimize(objective), cons)

    def solve(self, g, lbx, ubx, lba, uba, x0):
        import cvxpy as cp
        self.g.value = g
        self.lba.value, self.uba.value = lba[self.lo_rows], uba[self.hi_rows]
        try:
            self.problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError as exc:
            return None, f"solver error: {exc}"
        if self.problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return None, self.problem.status
        return np.asarray(self.x.value).ravel(), "solved"


def _quiet(call):
    """Run with output silenced: qpOASES prints a banner, through CasADi's stream (which
    CasADi hands to Python's sys.stdout) or straight to the process's stdout."""
    import contextlib
    import io
    import os
    import sys
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null, contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            return call()
    finally:
        _flush_c_stdio()                # a pipe's C buffer would print after the restore
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)


def _flush_c_stdio() -> None:
    import ctypes
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):
        pass


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
