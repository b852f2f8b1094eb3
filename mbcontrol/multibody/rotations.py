"""Rotation and shift matrices as CasADi expressions (SNAME / Fossen conventions, NED axes).

Every function accepts floats, numpy arrays or CasADi DM/SX/MX and returns a CasADi
expression of the matching type, so model parameters may stay symbolic.

Conventions (ERRATA, "Conventions"): ``S(a) @ b == a x b``; a rotation matrix ``R_b^n``
maps body components to n components; angles are in radians, lengths in metres.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

_CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def as_casadi(value, shape: tuple[int, int] | None = None):
    """Convert floats, sequences, numpy arrays or CasADi objects to a CasADi matrix.

    Sequences may mix floats and SX/MX scalars (e.g. ``(0.3, L, 0.0)`` with ``L`` symbolic).
    ``shape`` (rows, cols), if given, is checked; a flat 3-sequence becomes a 3x1 column.
    """
    if isinstance(value, _CASADI_TYPES):
        out = value
    else:
        arr = np.asarray(value, dtype=object)
        if arr.ndim == 0:
            out = _scalar(arr.item())
        elif arr.ndim == 1:
            out = ca.vertcat(*[_scalar(x) for x in arr])
        elif arr.ndim == 2:
            out = ca.vertcat(*[ca.horzcat(*[_scalar(x) for x in row]) for row in arr])
        else:
            raise ValueError(f"expected a scalar, vector or matrix, got an array of shape {arr.shape}")
    if shape is not None and tuple(out.shape) != tuple(shape):
        raise ValueError(f"expected shape {shape}, got {tuple(out.shape)}")
    return out


def _scalar(x):
    """One element: CasADi objects pass through, numbers become DM (so DM mixes with SX or MX)."""
    return x if isinstance(x, _CASADI_TYPES) else ca.DM(float(x))


def S(a):
    """Skew-symmetric (cross-product) matrix, 3x3: ``S(a) @ b = a x b``."""
    a = as_casadi(a, (3, 1))
    return ca.vertcat(
        ca.horzcat(0, -a[2], a[1]),
        ca.horzcat(a[2], 0, -a[0]),
        ca.horzcat(-a[1], a[0], 0),
    )


def H(r):
    """Fossen's 6x6 shift matrix ``H(r) = [[I, S(r)^T], [0, I]]`` (ERRATA conventions).

    ``H(r) @ [v_o; w] = [v_o + w x r; w]`` is the twist of the point at ``r`` (m) from o;
    wrenches shift with the transpose: ``H(r)^T @ [f; m_p] = [f; m_p + r x f]`` is the
    wrench about o of a force applied at r.
    """
    zeros, eye = ca.DM.zeros(3, 3), ca.DM.eye(3)
    return ca.vertcat(ca.horzcat(eye, S(r).T), ca.horzcat(zeros, eye))


def Rot(axis, angle):
    """Rotation by ``angle`` (rad) about the unit vector ``axis`` (Rodrigues' formula), 3x3.

    ``Rot(axis, angle)`` maps components in the rotated frame to the original frame, e.g.
    ``Rot((0, 1, 0), theta)`` is the pitch matrix R_y(theta) of Fossen. ``axis`` is
    normalised; a zero axis raises ValueError.
    """
    a = np.asarray(axis, dtype=float).reshape(-1)
    norm = np.linalg.norm(a)
    if a.shape != (3,) or not np.isfinite(norm) or norm < 1e-12:
        raise ValueError(f"rotation axis must be a non-zero 3-vector, got {axis!r}")
    Sa = S(a / norm)
    return ca.DM.eye(3) + ca.sin(angle) * Sa + (1 - ca.cos(angle)) * (Sa @ Sa)


def R_zyx(Theta):
    """ZYX Euler rotation ``R_b^n = R_z(psi) R_y(theta) R_x(phi)`` (Fossen 2.18), 3x3.

    ``Theta = [phi, theta, psi]`` (roll, pitch, yaw; rad).
    """
    Theta = as_casadi(Theta, (3, 1))
    cphi, sphi = ca.cos(Theta[0]), ca.sin(Theta[0])
    cth, sth = ca.cos(Theta[1]), ca.sin(Theta[1])
    cpsi, spsi = ca.cos(Theta[2]), ca.sin(Theta[2])
    return ca.vertcat(
        ca.horzcat(cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth),
        ca.horzcat(spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi),
        ca.horzcat(-sth, cth * sphi, cth * cphi),
    )


def T_zyx(Theta):
    """ZYX Euler-rate matrix, ``Theta_dot = T(Theta) @ w^b`` (Fossen 2.29), 3x3.

    Singular at pitch ``theta = +-pi/2`` (cos(theta) = 0); see
    ``Tree.euler_singularity_margin``.
    """
    Theta = as_casadi(Theta, (3, 1))
    cphi, sphi = ca.cos(Theta[0]), ca.sin(Theta[0])
    cth, tth = ca.cos(Theta[1]), ca.tan(Theta[1])
    return ca.vertcat(
        ca.horzcat(1, sphi * tth, cphi * tth),
        ca.horzcat(0, cphi, -sphi),
        ca.horzcat(0, sphi / cth, cphi / cth),
    )
