"""Linear dispersion in water of finite depth: wavenumber and group velocity.

omega^2 = g k tanh(k h), omega in rad/s, k in rad/m, depth h in m (math.inf: deep water).
"""
from __future__ import annotations

import math

import numpy as np


def wavenumber(omega: float, depth: float, g: float = 9.81) -> float:
    """k (rad/m) of the linear dispersion relation omega^2 = g k tanh(k h), omega in rad/s and
    the water depth h in m (Newton's method from the deep-water guess)."""
    k = omega ** 2 / g
    if math.isinf(depth):
        return k
    for _ in range(50):
        f = g * k * math.tanh(k * depth) - omega ** 2
        kh = k * depth
        df = g * math.tanh(kh) + (g * kh / math.cosh(kh) ** 2 if kh < 350 else 0.0)
        k, step = k - f / df, f / df
        if abs(step) < 1e-14 * k:
            break
    return k


def group_velocity(omega: float, depth: float, g: float = 9.81) -> float:
    """c_g (m/s) in water of depth h (m): (omega / k) (1 + 2 k h / sinh 2 k h) / 2."""
    k = wavenumber(omega, depth, g)
    kh2 = 2 * k * depth
    return omega / k * 0.5 * (1 + (kh2 / math.sinh(kh2) if kh2 < 700 else 0.0))  # deep: 1/2


def group_velocities(omega, depth: float, g: float = 9.81) -> np.ndarray:
    """c_g (m/s) at each omega (rad/s, > 0) in water of depth h (m; math.inf: g / (2 omega))."""
    omega = np.asarray(omega, dtype=float)
    if math.isinf(depth):
        return g / (2 * omega)
    return np.array([group_velocity(float(w), depth, g) for w in omega.ravel()]).reshape(omega.shape)
