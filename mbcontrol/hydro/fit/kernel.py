"""The radiation kernel from BEM data: K(jω) = B(ω) + jω(A(ω) - A∞), the impulse response
K(t) = (2/π)∫₀^∞ B(ω) cos(ωt) dω with its high-frequency tail, and a reference convolution.

All matrices use the layout X[i_force, j_motion]; ν are CoG twists in NED body axes (SI).
"""
from __future__ import annotations

import numpy as np

from mbcontrol.errors import HydroError

from ..data.dataset import matrix


def _dof_list(ds, dofs):
    all_dofs = [str(d) for d in ds["radiating_dof"].values]
    if dofs is None:
        return all_dofs
    missing = [d for d in dofs if d not in all_dofs]
    if missing:
        raise HydroError(f"radiation: DOFs {missing} not in the dataset; expected names among {all_dofs}")
    return list(dofs)


def kernel_data(ds, dofs=None, omega_max=None):
    """(ω, K(jω)) from a hydro dataset: K = B + jω(A - A∞), shape (nω, n, n), ω in rad/s."""
    dofs = _dof_list(ds, dofs)
    w = np.asarray(ds["omega"].values, dtype=float)
    keep = w <= omega_max if omega_max is not None else np.ones(w.size, bool)
    A, B = matrix(ds["added_mass"], dofs)[keep], matrix(ds["radiation_damping"], dofs)[keep]
    K = B + 1j * w[keep, None, None] * (A - matrix(ds["added_mass_inf"], dofs))
    return w[keep], K, dofs


RECIPROCITY = 1e-2   # relative asymmetry of K below which it is BEM discretisation error


def reciprocal(K) -> tuple[np.ndarray, float]:
    """(K, asymmetry): K (nω, n, n) made symmetric, as BEM reciprocity has it, when its relative
    asymmetry ‖K - Kᵀ‖ / ‖K‖ is below RECIPROCITY; otherwise K as it is (data that mean it)."""
    asym = float(np.linalg.norm(K - np.swapaxes(K, 1, 2)) / max(np.linalg.norm(K), 1e-300))
    return (0.5 * (K + np.swapaxes(K, 1, 2)) if asym < RECIPROCITY else K), asym


def tail_exponent(w, B) -> float:
    """Decay exponent p of B(ω) ∝ ω^-p above the band, from the diagonal over the top 40 % of ω.

    Log-log least squares on Σ_i |B_ii|; clipped to [2, 6] (3-D bodies decay at least like ω⁻²;
    a Capytaine hemisphere decays like ω^-3.6 at kR = 8). Returns 3 if fewer than 3 points.
    """
    w = np.asarray(w, dtype=float)
    y = np.sum(np.abs(np.einsum("kii->ki", B)), axis=1)
    sel = (w >= 0.6 * w.max()) & (y > 0)
    if np.count_nonzero(sel) < 3:
        return 3.0
    slope = np.polyfit(np.log(w[sel]), np.log(y[sel]), 1)[0]
    return float(np.clip(-slope, 2.0, 6.0))


def _with_tail(w, B, tail):
    """Frequency grid and B with B(0) = 0 prepended and, unless tail is None, the power-law tail
    B_N (ω_N/ω)^p on a geometric grid up to 50 ω_N (the rest is < 2 % of the tail for p >= 2)."""
    w0 = np.concatenate([[0.0], w])
    B0 = np.concatenate([np.zeros((1,) + B.shape[1:]), B])
    if tail is None:
        return w0, B0, None
    p = tail_exponent(w, B) if tail == "auto" else float(tail)
    if not p > 1:
        raise HydroError(f"impulse_response: tail = {tail!r}; expected 'auto', None or an exponent > 1")
    u = np.geomspace(1.0, 50.0, 121)[1:]
    return (np.concatenate([w0, w[-1] * u]),
            np.concatenate([B0, B[-1][None] * u[:, None, None] ** -p]), p)


def _cos_transform(w, f, t):
    """(2/π)∫ f(ω) cos(ωt) dω over the grid w, f piecewise linear, each piece exact (Filon form
    of the trapezoid rule: equal to it at t = 0, free of aliasing when Δω·t > 1)."""
    slope = np.diff(f, axis=0) / np.diff(w)[:, None, None]
    a, b = w[:-1], w[1:]
    out = np.empty((t.size,) + f.shape[1:])
    for k, tk in enumerate(t):
        if tk == 0.0:
            val = np.trapezoid(f, w, axis=0)
        else:
            # Σ β_k (cos b t - cos a t)/t², written with sines to avoid cancellation at small t
            dcos = -2.0 * np.sin((a + b) * tk / 2) * np.sin((b - a) * tk / 2) / tk**2
            val = (f[-1] * np.sin(w[-1] * tk) - f[0] * np.sin(w[0] * tk)) / tk + np.tensordot(dcos, slope, (0, 0))
        out[k] = 2.0 / np.pi * val
    return out


def impulse_response(ds, t, dofs=None, *, tail="auto") -> np.ndarray:
    """K(t) = (2/π)∫₀^∞ B(ω) cos(ωt) dω, shape (nt, n, n), layout [i_force, j_motion], SI per s.

    Quadrature: B is piecewise linear between the BEM frequencies, with B(0) = 0 added (true for
    every entry: damping vanishes at zero frequency), and each piece is integrated exactly against
    cos(ωt) (Filon form of the trapezoid rule). Tail beyond the last frequency ω_N:
    B_N (ω_N/ω)^p with p from :func:`tail_exponent` (``"auto"``) or given (a number > 1);
    ``None`` truncates at ω_N.
    """
    dofs = _dof_list(ds, dofs)
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if np.any(t < 0):
        raise HydroError("impulse_response: t must be >= 0 (s)")
    w, f, _ = _with_tail(np.asarray(ds["omega"].values, dtype=float), matrix(ds["radiation_damping"], dofs), tail)
    return _cos_transform(w, f, t)


def convolution_force(K, dt, nu_history) -> np.ndarray:
    """Reference Cummins convolution μ(t_n) = ∫₀^{t_n} K(t_n - τ) ν(τ) dτ on a uniform grid.

    K : (nt, n, n) kernel at t = 0, dt, 2dt, … (layout [i_force, j_motion]); dt : s;
    nu_history : (nt, n) twists at the same instants. Trapezoid rule, evaluated with FFTs.
    Returns μ, shape (nt, n).
    """
    from scipy.signal import fftconvolve

    K, nu = np.asarray(K, dtype=float), np.asarray(nu_history, dtype=float)
    if K.ndim != 3 or nu.ndim != 2 or K.shape[0] != nu.shape[0] or K.shape[2] != nu.shape[1]:
        raise HydroError(f"convolution_force: K {K.shape} and nu_history {nu.shape}; "
                         "expected (nt, n, n) and (nt, n)")
    nt = nu.shape[0]
    mu = np.zeros((nt, K.shape[1]))
    for i in range(K.shape[1]):
        for j in range(K.shape[2]):
            if np.any(K[:, i, j]):
                mu[:, i] += fftconvolve(K[:, i, j], nu[:, j])[:nt]
    # trapezoid end corrections: half weight on τ = 0 and τ = t_n
    mu -= 0.5 * (K[:, :, :] @ nu[0]) + 0.5 * (K[0] @ nu.T).T
    mu[0] = 0.0
    return dt * mu
