"""Reference simulation with direct Cummins convolution (no radiation state space).

mu(t) = int_0^t K(t - tau) nu(tau) d tau with K(t) = (2/pi) int B(omega) cos(omega t) d omega
from the BEM data, evaluated by the trapezoid rule over the whole history at every step:
O(n^2) work, the approach a user would write by hand. It exists to check the state-space
radiation model (tests, benchmarks), not for production runs.
"""
from __future__ import annotations

import numpy as np

from .. import hydro as bem
from ..plant import build_plant


def simulate_convolution(scene, wave, *, duration: float, dt: float, params=None,
                         kernel_length: float | None = None, x0=None):
    """Time histories (t, Y) of every plant output, radiation by direct convolution.

    RK4 on the radiation-free plant; within a step, mu is held at its value for the
    mid-step velocity, extrapolated from the last two samples (second order in dt).
    kernel_length (s): K(t) is truncated there (default: until it has decayed to 1e-4 of its
    peak, at most the record length). x0: initial q and s (radiation memory starts at zero).
    """
    plant = build_plant(scene, radiation=False)
    hyd = plant.hydro
    p = plant.params(**params) if isinstance(params, dict) else plant.p0
    n = int(round(duration / dt))
    n_k = n + 1 if kernel_length is None else min(n + 1, int(kernel_length / dt) + 1)
    K = bem.impulse_response(hyd.data, np.arange(n_k) * dt, dofs=list(hyd.dofs))   # (nk, m, m)
    if kernel_length is None:
        peak = np.abs(K).max()
        alive = np.flatnonzero(np.abs(K).reshape(n_k, -1).max(axis=1) > 1e-4 * peak)
        K = K[: alive[-1] + 2]
    exc_half = plant.excitation(wave, np.arange(2 * n + 1) * dt / 2)
    select = _select(plant)
    x = plant.x0() if x0 is None else np.asarray(x0, float)
    nu = np.zeros((n + 1, len(hyd.dofs)))
    nu[0] = _nu(plant, x, select)
    Y = np.empty((n + 1, len(plant.outputs)))
    u = np.zeros(len(plant.inputs))
    for i in range(n):
        nu_mid = nu[i] + 0.5 * (nu[i] - nu[i - 1]) if i > 0 else nu[i]
        mu = _memory(K, nu, i, nu_mid, dt)
        w = [exc_half[2 * i] - mu, exc_half[2 * i + 1] - mu, exc_half[2 * i + 2] - mu]
        Y[i] = np.asarray(plant.h(x, u, w[0], p)).ravel()
        k1 = np.asarray(plant.f(x, u, w[0], p)).ravel()
        k2 = np.asarray(plant.f(x + dt / 2 * k1, u, w[1], p)).ravel()
        k3 = np.asarray(plant.f(x + dt / 2 * k2, u, w[1], p)).ravel()
        k4 = np.asarray(plant.f(x + dt * k3, u, w[2], p)).ravel()
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        nu[i + 1] = _nu(plant, x, select)
    Y[n] = np.asarray(plant.h(x, u, exc_half[-1] - _memory(K, nu, n, nu[n], dt), p)).ravel()
    return np.arange(n + 1) * dt, Y, plant


def _memory(K, nu, i, nu_mid, dt):
    """mu(t_i + dt/2): trapezoid rule over the samples nu_j (lags (i - j) dt + dt/2, K
    interpolated to them) within the kernel's support, plus the half interval up to now."""
    n_k = K.shape[0]
    first = max(0, i - (n_k - 2))                         # older samples see K = 0
    j = np.arange(first, i + 1)
    lag_index = i - j                                     # lag = (lag_index + 1/2) dt
    K_lag = 0.5 * (K[lag_index] + K[lag_index + 1])
    weights = np.full(j.size, dt)
    weights[-1] = dt / 2                                  # trapezoid ends (t_i and, if in
    if first == 0:                                        # the support, t_0)
        weights[0] = dt / 2 if i > 0 else 0.0
    total = np.einsum("j,jab,jb->a", weights, K_lag, nu[first:i + 1])
    # [t_i, t_i + dt/2]: trapezoid between K(dt/2) nu_i and K(0) nu_mid
    return total + dt / 4 * (0.5 * (K[0] + K[1]) @ nu[i] + K[0] @ nu_mid)


def _select(plant):
    from ..plant import dof_selector
    return dof_selector(plant.topology, list(plant.hydro.dofs))


def _nu(plant, x, select):
    import casadi as ca
    tree = plant.topology.tree
    q, s = x[:tree.n_q], x[tree.n_q:tree.n_q + tree.n_s]
    if not hasattr(plant, "_P_fun"):
        qs = ca.SX.sym("q", tree.n_q)
        object.__setattr__(plant, "_P_fun", ca.Function("P", [qs], [tree.P(qs)]))
    return select @ (np.asarray(plant._P_fun(q)).T @ s)
