"""The NMPC's setup and run data (controllers.nmpc): what it builds from a plant and its
settings, fixed once built, and what one run keeps between calls.

`build_setup(settings, plant)` resolves the limits and scales, builds the multiple-shooting
problem in CasADi Opti and compiles it into one Function (`opti.to_function`) solved by IPOPT;
`NmpcSetup.new_run()` starts the run data (`NmpcRun`: the last plan and its multipliers, the
command held, the solver's counters). As the linear MPC's parts (controllers.mpc_setup).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from mbcontrol.errors import ControllerError, UnknownName
from mbcontrol.sim import rk4_step

from .base import signal_indices
from .nmpc_settings import NmpcSettings


@dataclass(frozen=True)
class NmpcSetup:
    """What an NMPC builds from a plant and its settings; fixed once built.

    model: the prediction plant; pto_name, nu (plant inputs), i_u (the PTO's input index);
    fmax (N or N m), smax (m or rad), rate (N/s; inf: unlimited): the resolved limits; fs, ss:
    the force and stroke scales; R (W/N^2): the force penalty; half (s): the forecast's
    offsets on the half-substep grid; windows: each step's rows of it; rollout: N periods of
    the model (cold starts, state scales); xs: the states' scales; solver: the compiled
    IPOPT problem; ng: its constraint count."""
    settings: NmpcSettings
    model: object
    pto_name: str
    nu: int
    i_u: int
    fmax: float
    smax: float
    rate: float
    fs: float
    ss: float
    R: float
    half: np.ndarray
    windows: np.ndarray
    rollout: object
    xs: np.ndarray
    solver: object
    ng: int

    def forecast(self, t: float) -> np.ndarray:
        """Excitation windows (n_w (2m+1), N) of the horizon starting at t (s)."""
        return _forecast(self.model, self.settings, self.half, self.windows, t)

    def new_run(self) -> NmpcRun:
        return NmpcRun()


@dataclass
class NmpcRun:
    """One run of an NMPC: plan ((X scaled, U scaled, S) of the last successful solve), lam
    (its constraint multipliers), age (controller periods since that plan began), u_last
    (the command last applied, / force scale), plan_force (N or N m: the last successful
    plan's forces), and the counters: solves, failures, solve_times (s, wall time of each
    solve), iterations (IPOPT's, each solve), statuses (IPOPT return status -> count),
    slack_max (m or rad: the largest first-step stroke slack)."""
    plan: tuple | None = None
    lam: np.ndarray | None = None
    age: int = 0
    u_last: float = 0.0
    plan_force: np.ndarray | None = None
    solves: int = 0
    failures: int = 0
    solve_times: list = field(default_factory=list)
    iterations: list = field(default_factory=list)
    statuses: dict = field(default_factory=dict)
    slack_max: float = 0.0


def build_setup(settings: NmpcSettings, plant) -> NmpcSetup:
    """Bind to `plant`: resolve limits and scales, build and compile the Opti problem."""
    st = settings
    model = st.model if st.model is not None else plant
    if tuple(model.states) != tuple(plant.states) or \
            tuple(model.inputs) != tuple(plant.inputs):
        raise ControllerError(f"nmpc: prediction model {model.name!r} must have the states and "
                              f"inputs of the plant {plant.name!r}")
    ptos = {p.name: p for p in plant.scene.ptos}
    name = st.pto or plant.scene.ptos[0].name
    if name not in ptos:
        raise UnknownName(f"{plant.name}: no PTO {name!r}; PTOs are {', '.join(ptos)}")
    nu = len(plant.inputs)
    i_u = plant.inputs.index(f"u__{name}")
    zero_law = {f"{p.name}__{k}": 0.0 for p in plant.scene.ptos
                for k in ("damping", "stiffness")}
    p = model.params(**{**zero_law, **st.params})

    if st.force_max is None and ptos[name].limited_force() == "hull":
        raise ControllerError(f"nmpc: PTO {name!r} limits the force on the hull (force_max_on = "
                              f"'hull'); the NMPC limits the machine's command only: give it "
                              f"force_max (a machine limit) explicitly")
    fmax = ptos[name].force_max if st.force_max is None else st.force_max
    smax = ptos[name].stroke_max if st.stroke_max is None else st.stroke_max
    fmax, smax = float(fmax), float(smax)
    rate = math.inf if st.rate_max is None else float(st.rate_max)
    # scales that make the unknowns of order one; unlimited quantities fall back to the
    # wave's largest excitation force and 1 m (or rad)
    fs = fmax if math.isfinite(fmax) else _excitation_scale(st, model)
    ss = smax if math.isfinite(smax) else 1.0
    R = float(st.force_penalty if st.force_penalty is not None
              else 1e-3 * ss / (fs * st.horizon_s))

    N, m = st.n, st.substeps
    half = np.arange(2 * N * m + 1) * st.dt_s / m / 2    # forecast offsets, s
    # step k's excitation window: half-grid rows 2mk .. 2m(k+1)
    windows = 2 * m * np.arange(N)[:, None] + np.arange(2 * m + 1)[None, :]
    step, pos = _step_functions(st, model, p, signal_indices(model, [f"{name}__position"])[0],
                                nu, i_u, fs)
    args = step.mx_in()
    rollout = ca.Function("nmpc_step_x", args, [step(*args)[0]]).mapaccum(
        "nmpc_rollout", N)                         # N periods: cold starts, state scales
    xs = _state_scale(st, model, rollout, half, windows)
    solver, ng = _build(st, model, step, pos, xs=xs, fs=fs, ss=ss, R=R, fmax=fmax, smax=smax,
                        rate=rate)
    return NmpcSetup(st, model, name, nu, i_u, fmax, smax, rate, fs, ss, R, half, windows,
                     rollout, xs, solver, ng)


def _step_functions(st: NmpcSettings, model, p, i_pos, nu: int, i_u: int, fs: float):
    """(step, pos): one controller period of the model (m RK4 substeps, the force held)
    -> (x_next, PTO position after each substep); and the PTO position of a state."""
    m, nx, nw = st.substeps, model.nx, len(model.disturbances)
    rk4 = rk4_step(model)
    x, us = ca.SX.sym("x", nx), ca.SX.sym("u")             # us: force / force scale
    wseg = ca.SX.sym("w", nw, 2 * m + 1)
    u_full = ca.SX.zeros(nu)
    u_full[i_u] = us * fs
    pos = ca.Function("nmpc_pos", [x], [model.h(x, ca.DM.zeros(nu),
                                                ca.DM.zeros(nw), p)[i_pos]])
    xn, xp_sub = x, []
    for j in range(m):
        xn = rk4(xn, u_full, wseg[:, 2 * j:2 * j + 3], p, st.dt_s / m)[0]
        xp_sub.append(pos(xn))
    # the stroke is checked at every substep: sampled at dt_s = 0.24 s alone, a 4 m
    # stroke at 0.65 rad/s can overshoot between samples by 4 (1/cos(0.65 dt_s/2) - 1) = 1.2 cm
    step = ca.Function("nmpc_step", [x, us, ca.vec(wseg)], [xn, ca.horzcat(*xp_sub)])
    return step, pos


def _build(st: NmpcSettings, model, step, pos, *, xs, fs, ss, R, fmax, smax, rate):
    """(the compiled IPOPT problem, its constraint count)."""
    N, m, nx, nw = st.n, st.substeps, model.nx, len(model.disturbances)
    opti = ca.Opti()
    Xv = opti.variable(nx, N + 1)                  # states / xs
    xs = ca.DM(xs)
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
    loss = R * st.dt_s * fs ** 2 * ca.sumsqr(U)                    # J
    slack = st.stroke_penalty * fs * ca.sum2(S + S ** 2 / ss)     # J
    opti.minimize((loss - energy + slack) / (fs * ss))            # order one
    if math.isfinite(fmax):
        opti.subject_to(opti.bounded(-fmax / fs, U, fmax / fs))
    if math.isfinite(rate):
        r = rate * st.dt_s / fs
        opti.subject_to(opti.bounded(-r, ca.diff(ca.horzcat(u_prev, U), 1, 1), r))
    opti.subject_to(S >= 0)
    if math.isfinite(smax):
        S_sub = ca.kron(S, ca.DM.ones(1, m))       # step k's slack on its substeps
        opti.subject_to(opti.bounded(-smax - S_sub, xp_sub, smax + S_sub))
    # warm start from the shifted plan and multipliers with a small barrier parameter:
    # 8.4 iterations a solve on the sphere (force and stroke limits) against 13.3 from
    # the primal guess alone
    ipopt = {"print_level": 0, "sb": "yes", "max_iter": st.max_iter, "tol": st.tol,
             "warm_start_init_point": "yes", "mu_init": 1e-4,
             **({"max_cpu_time": st.max_cpu_time} if st.max_cpu_time else {}),
             **st.ipopt}
    opti.solver("ipopt", {"expand": True, "print_time": False}, ipopt)
    solver = opti.to_function("nmpc_ocp", [x0, W, u_prev, Xv, U, S, opti.lam_g],
                              [Xv, U, S, opti.lam_g],
                              ["x0", "W", "u_prev", "X", "U", "S", "lam_g"],
                              ["X_opt", "U_opt", "S_opt", "lam_g_opt"])
    return solver, opti.ng


def _forecast(model, st: NmpcSettings, half, windows, t: float) -> np.ndarray:
    """Excitation windows (n_w (2m+1), N) of the horizon starting at t (s)."""
    w = model.excitation(st.wave, t + half)                       # (2Nm+1, n_w)
    N = st.n
    return w[windows].transpose(0, 2, 1).reshape(N, -1).T


def _state_scale(st: NmpcSettings, model, rollout, half, windows) -> np.ndarray:
    """Typical size of each state: its largest value in the model's free response (zero
    force) to the wave from rest, over the ramp plus 60 s; 1 for states left at rest."""
    N = st.n
    t0, x, peak = 0.0, np.zeros(model.nx), np.zeros(model.nx)
    while t0 < max(st.wave.ramp_time + 60.0, 4 * st.horizon_s):
        X = np.asarray(rollout(x, np.zeros((1, N)), _forecast(model, st, half, windows, t0)))
        peak = np.maximum(peak, np.abs(X).max(axis=1))
        x, t0 = X[:, -1], t0 + st.horizon_s
    if not np.all(np.isfinite(peak)) or peak.max() > 1e12:
        raise ControllerError(f"nmpc: the prediction model diverges with {st.substeps} RK4 "
                              f"substep(s) of {st.dt_s / st.substeps:.4g} s; raise substeps")
    return np.where(peak > 1e-9 * max(peak.max(), 1e-300), peak, 1.0)


def _excitation_scale(st: NmpcSettings, model) -> float:
    t = np.arange(0.0, max(4 * st.horizon_s, 2 * st.wave.ramp_time + 60.0), 0.1)
    scale = float(np.max(np.abs(model.excitation(st.wave, t)), initial=0.0))
    return scale if scale > 0 else 1.0
