"""Model reduction of linear control-plant models: balanced truncation (square-root method).

python-control's `balred` needs slycot (Fortran, often not installable); this is the same
method in NumPy/SciPy for a stable model. The Hankel singular values are returned so the user
sees what a given order leaves out: the H-infinity error of the truncated model is at most
twice the sum of the discarded ones (Glover's bound), which the tests check.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy import linalg

from ..errors import InputError

if TYPE_CHECKING:       # python-control costs 2.5 s to import: only where it is used
    import control


@dataclass
class Reduction:
    """A reduced model and its map from the full state: x_r = T x, x ~ Ti x_r."""
    system: control.StateSpace
    T: np.ndarray                 # (order, n) full -> reduced state
    Ti: np.ndarray                # (n, order) reduced -> full state
    hankel: np.ndarray            # Hankel singular values of the full model, descending
    error_bound: float            # 2 sum of the discarded Hankel singular values (H-inf norm)


def balanced_truncation(sys: control.StateSpace, order: int) -> Reduction:
    """Balanced truncation of a stable continuous-time StateSpace to `order` states.

    Keeps input, output names and the feedthrough D. Raises ValueError for an unstable model
    (no finite gramians) or an order outside 1..n.
    """
    import control
    A, B, C, D = (np.asarray(M, float) for M in (sys.A, sys.B, sys.C, sys.D))
    n = A.shape[0]
    if not 1 <= order <= n:
        raise InputError(f"{sys.name}: reduced order must be in 1..{n}, got {order}")
    worst = float(np.max(np.linalg.eigvals(A).real))
    if worst >= 0:
        raise InputError(f"{sys.name}: balanced truncation needs a stable model; the largest "
                         f"pole real part is {worst:.3g}")
    Wc = linalg.solve_continuous_lyapunov(A, -B @ B.T)
    Wo = linalg.solve_continuous_lyapunov(A.T, -C.T @ C)
    Lc = _psd_factor(Wc)
    Lo = _psd_factor(Wo)
    U, s, Vt = np.linalg.svd(Lo.T @ Lc)
    keep = s[:order]
    if keep[-1] <= 1e-13 * s[0]:
        minimal = int(np.sum(s > 1e-13 * s[0]))
        raise InputError(f"{sys.name}: order {order} exceeds the model's numerically minimal "
                         f"order {minimal} (Hankel singular values below round-off)")
    scale = 1.0 / np.sqrt(keep)
    T = (scale[:, None] * U[:, :order].T) @ Lo.T            # order x n
    Ti = Lc @ Vt[:order].T * scale[None, :]                 # n x order
    reduced = control.ss(T @ A @ Ti, T @ B, C @ Ti, D, inputs=sys.input_labels,
                         outputs=sys.output_labels,
                         states=[f"xr{i}" for i in range(order)], name=f"{sys.name}_r{order}")
    return Reduction(reduced, T, Ti, s, float(2 * s[order:].sum()))


def _psd_factor(W: np.ndarray) -> np.ndarray:
    """L with L L^T = W for a symmetric positive semidefinite W (eigen-factor: a gramian is
    often singular to round-off, where a Cholesky factor fails)."""
    w, V = np.linalg.eigh(0.5 * (W + W.T))
    return V * np.sqrt(np.clip(w, 0.0, None))[None, :]
