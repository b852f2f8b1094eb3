"""The hand-written baseline of the speed bench: Cummins' equation by direct convolution.

What a user without this toolbox would write, on the same equations of motion:

  * the radiation-free plant (``build_plant(scene, radiation=False)``): its CasADi ``f`` called
    from Python, with w = excitation - mu the whole wave load on the hydro DOFs;
  * the radiation memory force mu(t) = int_0^t K(t - tau) nu(tau) dtau, K(t) = (2/pi) int
    B(omega) cos(omega t) domega over the BEM data's band (``mbcontrol.hydro.impulse_response``
    with tail=None, as WEC-Sim computes its IRF), by the trapezoid rule over the stored velocity
    history on a fixed grid of step `delta`; the kernel is truncated where it has decayed (the
    memory length: where the kernel with the high-frequency tail stays below 1e-4 of its
    peak, at most 30 s), tapered over its last quarter so that the truncation is the same
    equation at every delta (see :func:`kernel`);
  * ``scipy.integrate.solve_ivp`` (RK45) advancing the rigid-body state [q, s] from one grid
    point to the next, with mu extrapolated linearly over the interval from its last two grid
    values (second order in delta); the excitation is the exact sum of the wave components at
    every right-hand-side call. Each interval is one ``solve_ivp`` call started with
    ``first_step = delta``, so that a loose rtol takes one RK45 step per interval.

Its settings are the grid step `delta` (s) and solve_ivp's rtol (atol = 1e-3 rtol).

``converged_reference`` solves the same convolution equations (same kernel, same truncation)
to a tight accuracy, to measure the baseline's error: fixed-step RK4 on the radiation-free plant
(one compiled CasADi call per step), mu from the same trapezoid memory, extrapolated
quadratically to the stage times. It is second order in dt (the trapezoid rule); run it at two
steps to check that it has converged.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from mbcontrol import hydro as bem
from mbcontrol.sim.compiled import compile_function
from mbcontrol.sim.integrators import step_function, wave_terms
from mbcontrol.plant import dof_selector, build_plant

KERNEL_DECAY = 1e-4      # truncate K where every entry stays below this fraction of its peak
KERNEL_MAX_S = 30.0      # ... and at most this long (s)
TAPER = 0.25             # the kernel is tapered to zero over this last fraction of its length


@dataclass
class Run:
    """One run of the convolution equations: sample times (s), joint coordinates (n, n_q),
    wall time of the time stepping (s), right-hand-side calls per grid step, kernel length (s)."""
    t: np.ndarray
    q: np.ndarray
    wall_s: float
    rhs_per_step: float
    kernel_s: float


def radiation_free(scene):
    """The plant without radiation states (w = the whole wave load) and nu(x), the twists of
    the hydro DOFs, as a CasADi Function of the plant's state x = [q, s]."""
    plant = build_plant(scene, radiation=False)
    tree = plant.topology.tree
    q, s = ca.SX.sym("q", tree.n_q), ca.SX.sym("s", tree.n_s)
    select = dof_selector(plant.topology, list(plant.hydro.dofs))
    nu = ca.Function("nu", [ca.vertcat(q, s)], [ca.mtimes(select, ca.mtimes(tree.P(q).T, s))])
    return plant, nu


_MEMORY: dict = {}


def memory_length(plant, *, decay: float = KERNEL_DECAY, max_length: float = KERNEL_MAX_S,
                  resolution: float = 0.005) -> float:
    """How long the radiation memory lasts (s): where the impulse response, with the
    power-law tail of B(omega) beyond the data (``impulse_response(tail="auto")``), has decayed
    for good below `decay` of its peak, on a fixed grid of `resolution` s; at most
    `max_length`. Fixed in seconds, so that every grid step solves the same equations."""
    if id(plant) not in _MEMORY:
        hydro = plant.hydro
        t = np.arange(int(max_length / resolution) + 1) * resolution
        K = bem.impulse_response(hydro.data, t, dofs=list(hydro.dofs), tail="auto")
        envelope = np.abs(K).reshape(t.size, -1).max(axis=1)
        alive = np.flatnonzero(envelope > decay * envelope.max())
        _MEMORY[id(plant)] = (float(t[min(t.size - 1, alive[-1] + 1)]), plant)
    return _MEMORY[id(plant)][0]


def kernel(plant, delta: float, *, duration: float) -> np.ndarray:
    """K(k delta) for k delta <= the memory length, shape (nk, m, m) (N s^-1 per unit twist).

    K is the cosine transform of B(omega) over the BEM data's band, as WEC-Sim computes its
    IRF: the power-law tail that ``impulse_response`` can add beyond the last frequency makes
    K sharply peaked within milliseconds of t = 0 (barge chain), which the trapezoid rule
    resolves only on a sub-millisecond grid. Past the memory length (:func:`memory_length`)
    the band-limited K holds only Gibbs ringing at the last BEM frequency; it is cut there
    with a raised-cosine taper over the last TAPER of the length, so that the cut does not
    depend on delta (an abrupt cut makes the trapezoid rule first order and the equations
    differ with delta).
    """
    length = min(memory_length(plant), duration)
    t = np.arange(round(length / delta) + 1) * delta
    K = bem.impulse_response(plant.hydro.data, t, dofs=list(plant.hydro.dofs), tail=None)
    ramp = np.clip((t - (1 - TAPER) * length) / (TAPER * length), 0.0, 1.0)
    return K * (0.5 * (1 + np.cos(np.pi * ramp)))[:, None, None]


class Memory:
    """The twist history nu_0 .. nu_i on the grid and the trapezoid convolution over it."""

    def __init__(self, K: np.ndarray, n: int, delta: float):
        self.nk, self.m, self.delta = K.shape[0], K.shape[1], delta
        # one matrix-vector product per grid point: K_cat[:, j m + b] = delta K[nk-1-j, :, b]
        self.K_cat = np.ascontiguousarray(
            np.transpose(K[::-1], (1, 0, 2)).reshape(self.m, -1)) * delta
        self.K = K
        self.nu = np.zeros((n + 1, self.m))

    def mu(self, i: int) -> np.ndarray:
        """mu(t_i) = delta [K_i nu_0 / 2 + sum_{0<j<i} K_{i-j} nu_j + K_0 nu_i / 2] (samples older
        than the kernel's support see K = 0)."""
        if i == 0:
            return np.zeros(self.m)
        first = max(0, i - self.nk + 1)
        length = i + 1 - first
        mu = self.K_cat[:, (self.nk - length) * self.m:] @ self.nu[first:i + 1].ravel()
        mu -= 0.5 * self.delta * (self.K[0] @ self.nu[i])
        if first == 0:
            mu -= 0.5 * self.delta * (self.K[i] @ self.nu[0])
        return mu


def simulate_baseline(scene, wave, *, duration: float, delta: float, rtol: float,
                      model=None) -> Run:
    """The baseline (module docstring) for `duration` s on a grid of step `delta` s.

    model: (plant, nu) from :func:`radiation_free`, to reuse between runs. The wall time
    covers the time stepping (memory, solve_ivp, excitation), not the kernel's computation.
    """
    plant, nu_fun = model or radiation_free(scene)
    n = round(duration / delta)
    K = kernel(plant, delta, duration=duration)
    memory = Memory(K, n, delta)
    omega, Fc, Fs, ramp_time = wave_terms(plant, wave)
    f, p, u = plant.f, plant.p0, np.zeros(len(plant.inputs))
    x = plant.x0()
    n_q = plant.n_q
    Q = np.empty((n + 1, n_q))
    mu_prev = np.zeros(memory.m)
    calls = 0
    start = time.perf_counter()
    for i in range(n):
        Q[i] = x[:n_q]
        memory.nu[i] = np.asarray(nu_fun(x)).ravel()
        mu = memory.mu(i)
        slope = (mu - mu_prev) / delta if i > 0 else np.zeros_like(mu)
        t_i, t_next = i * delta, (i + 1) * delta

        def rhs(t, x, mu=mu, slope=slope, t_i=t_i):
            ramp = 1.0 if t >= ramp_time else 0.5 * (1 - np.cos(np.pi * t / ramp_time))
            w = ramp * (Fc @ np.cos(omega * t) + Fs @ np.sin(omega * t)) \
                - (mu + slope * (t - t_i))
            return np.asarray(f(x, u, w, p)).ravel()

        sol = solve_ivp(rhs, (t_i, t_next), x, method="RK45", rtol=rtol, atol=rtol * 1e-3,
                        first_step=t_next - t_i)
        if not sol.success or not np.all(np.isfinite(sol.y[:, -1])):
            raise RuntimeError(f"{plant.name}: solve_ivp failed at t = {t_i:.4g} s: {sol.message}")
        calls += sol.nfev
        x = sol.y[:, -1]
        mu_prev = mu
    Q[n] = x[:n_q]
    wall = time.perf_counter() - start
    return Run(np.arange(n + 1) * delta, Q, wall, calls / n, K.shape[0] * delta)


_REFERENCE_STEPS: dict = {}


def converged_reference(scene, wave, *, duration: float, dt: float, model=None) -> Run:
    """The convolution equations solved tightly: RK4 at step dt (compiled step, one call per
    step), mu by the same trapezoid memory on the dt grid, extrapolated quadratically to the
    stage times t + dt/2 and t + dt. Second order in dt; compare two dt to check convergence."""
    plant, nu_fun = model or radiation_free(scene)
    if id(plant) not in _REFERENCE_STEPS:
        step = step_function(plant, "rk4")        # (x, u, W[n_w x 3 nodes], p, h) -> x_next
        x, u, W = ca.MX.sym("x", plant.nx), ca.MX.sym("u", len(plant.inputs)), \
            ca.MX.sym("W", len(plant.disturbances), 3)
        p, h = ca.MX.sym("p", len(plant.p0)), ca.MX.sym("h")
        x_next = step(x, u, W, p, h)[0]
        fun = ca.Function("conv_ref_step", [x, u, W, p, h], [x_next, nu_fun(x_next)])
        _REFERENCE_STEPS[id(plant)] = (compile_function(fun), plant)
    step = _REFERENCE_STEPS[id(plant)][0]
    n = round(duration / dt)
    K = kernel(plant, dt, duration=duration)
    memory = Memory(K, n, dt)
    W_half = plant.excitation(wave, np.arange(2 * n + 1) * dt / 2)
    p, u = plant.p0, np.zeros(len(plant.inputs))
    x = plant.x0()
    Q = np.empty((n + 1, plant.n_q))
    mus = np.zeros((n + 1, memory.m))
    memory.nu[0] = np.asarray(nu_fun(x)).ravel()
    start = time.perf_counter()
    for i in range(n):
        Q[i] = x[:plant.n_q]
        mus[i] = mu = memory.mu(i)
        if i >= 2:                     # quadratic through mu_{i-2}, mu_{i-1}, mu_i
            half = (15 * mu - 10 * mus[i - 1] + 3 * mus[i - 2]) / 8
            full = 3 * mu - 3 * mus[i - 1] + mus[i - 2]
        elif i == 1:
            half, full = 1.5 * mu - 0.5 * mus[0], 2 * mu - mus[0]
        else:
            half = full = mu
        W = np.column_stack([W_half[2 * i] - mu, W_half[2 * i + 1] - half,
                             W_half[2 * i + 2] - full])
        x_next, nu_next = step(x, u, W, p, dt)
        x = np.asarray(x_next).ravel()
        memory.nu[i + 1] = np.asarray(nu_next).ravel()
        if not np.all(np.isfinite(x)):
            raise RuntimeError(f"{plant.name}: convolution reference diverged at t = "
                               f"{(i + 1) * dt:.4g} s (dt = {dt} s)")
    Q[n] = x[:plant.n_q]
    return Run(np.arange(n + 1) * dt, Q, time.perf_counter() - start, 4.0, K.shape[0] * dt)
