"""The incident field by the exact sum over a sea's components, at any times and points: the
reference the Chebyshev series of `mbcontrol.waves.local_field` are checked against
(tests/waves/test_local_field.py), and a cost baseline (a cosine per component per point).

NED (z down), SI units; linear wave kinematics with Wheeler stretching, as `LocalField.pressure`.
"""
from __future__ import annotations

import math

import numpy as np

from .local_field import _wavenumbers, depth_factor
from .synthesis import ramp


def _phases(wave, t, x, y, water_depth: float, g: float):
    """k (rad/m, per component), the points' times (broadcast, flattened) and a generator of
    (slice, cos theta) over blocks of points, theta = k_j xi_j - omega_j t - phi_j
    (n_block, n_components): Re a exp(-i (omega t + phi)) exp(i k xi) = a cos theta."""
    t, x, y = (a.ravel() for a in np.broadcast_arrays(*(np.asarray(v, float) for v in (t, x, y))))
    k = _wavenumbers(wave.omega, water_depth, g)
    beta = np.broadcast_to(np.asarray(wave.direction, float), k.shape)   # a spread sea too
    kx, ky = k * np.cos(beta), k * np.sin(beta)

    def blocks(size=512):                  # bounded memory: points x components per block
        for start in range(0, t.size, size):
            s = slice(start, start + size)
            theta = (np.multiply.outer(x[s], kx) + np.multiply.outer(y[s], ky)
                     - np.multiply.outer(t[s], wave.omega) - wave.phase)
            yield s, np.cos(theta)
    return k, t, blocks


def direct_elevation(wave, t, x, y, *, water_depth: float = math.inf,
                     g: float = 9.81) -> np.ndarray:
    """eta (m, up) by the exact sum over components at times t (s) and points x, y (m, NED),
    broadcast together (shape of the broadcast), ramp included as `Wave.elevation`: the
    reference for the series. A spread sea's per-component directions are honoured."""
    shape = np.broadcast_shapes(np.shape(t), np.shape(x), np.shape(y))
    _, times, blocks = _phases(wave, t, x, y, water_depth, g)
    out = np.empty(times.size)
    for s, cos in blocks():
        out[s] = cos @ wave.amplitude
    return (ramp(times, wave.ramp_time) * out).reshape(shape)


def direct_pressure(wave, t, x, y, z, *, water_depth: float = math.inf, rho: float = 1025.0,
                    g: float = 9.81) -> np.ndarray:
    """Total incident pressure (Pa) by the exact sum at times t (s) and points x, y, z (m,
    NED, z down), broadcast: p = rho g max(z + p_dyn(d) / (rho g), 0) at the Wheeler-stretched
    depth d = H (z + eta) / (H + eta) clipped to >= 0 (deep: z + eta), as `LocalField.pressure`
    (0 above the surface); eta and p_dyn each sum every component, ramp included."""
    shape = np.broadcast_shapes(np.shape(t), np.shape(x), np.shape(y), np.shape(z))
    z = np.broadcast_to(np.asarray(z, float), shape).ravel()
    eta = direct_elevation(wave, t, x, y, water_depth=water_depth, g=g)
    eta = np.broadcast_to(eta, shape).ravel()
    depth = z + eta if math.isinf(water_depth) else water_depth * (z + eta) / (water_depth + eta)
    depth = np.maximum(depth, 0.0)
    k, times, blocks = _phases(wave, np.broadcast_to(t, shape), np.broadcast_to(x, shape),
                               np.broadcast_to(y, shape), water_depth, g)
    head = np.empty(times.size)
    for s, cos in blocks():
        head[s] = np.sum(cos * wave.amplitude * depth_factor(k, depth[s, None], water_depth),
                         axis=1)
    head *= ramp(times, wave.ramp_time)
    return (rho * g * np.maximum(z + head, 0.0)).reshape(shape)
