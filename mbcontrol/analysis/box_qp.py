"""A dense primal-dual interior-point solver for the pseudo-spectral bound's QP, with a dual
certificate.

    minimise 1/2 z' diag(h) z + q' z   subject to   lower <= C z + d <= upper,

h >= 0 (a diagonal cost: the power of each Fourier coefficient), C dense (time samples of the
force or position on the collocation grid). Why not a sparse conic solver (Clarabel): C is
dense, so the KKT system's factorisation costs it far more than the dense normal equations
(diag(h) + C' W C) dz = r here, whose formation is one BLAS product of n_rows x n^2 flops and
whose Cholesky is n^3 / 3; on a 300 s sea over the sphere's whole 0.05-12 rad/s band (n = 1146
coefficients, 2294 samples) about 0.3 s an iteration against Clarabel's minutes.

The certificate: for any multipliers lambda >= 0 of the two-sided bounds, weak duality gives

    max(-objective) <= 1/2 sum_i r_i^2 / h_i + lambda_u'(upper - d) + lambda_l'(d - lower),

r = q + C'(lambda_u - lambda_l), a valid upper bound whatever the solver's accuracy (inf where
h_i = 0 and r_i != 0). Mehrotra's predictor-corrector, as in Nocedal & Wright (2006) 16.6.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve
from scipy.linalg.blas import dsyrk


@dataclass(frozen=True)
class BoxQPResult:
    """z: the minimiser; objective: 1/2 z'Hz + q'z at z; dual_bound: the certified lower
    bound on the minimum (so -dual_bound >= max of -objective); status: 'optimal',
    'infeasible' or 'max_iterations'; iterations: interior-point steps."""
    z: np.ndarray
    objective: float
    dual_bound: float
    status: str
    iterations: int


def dual_value(h, q, C, d, lower, upper, lam_u, lam_l) -> float:
    """The Lagrangian dual function at multipliers lam_u, lam_l >= 0: a lower bound on the
    minimum of the QP (see the module docstring)."""
    lam_u, lam_l = np.maximum(lam_u, 0.0), np.maximum(lam_l, 0.0)
    r = q + C.T @ (lam_u - lam_l)
    free = h > 0
    if np.any(r[~free] != 0):
        return -np.inf
    return float(-0.5 * np.sum(r[free] ** 2 / h[free]) - lam_u @ (upper - d)
                 - lam_l @ (d - lower))


def fourier_gram(k, beta, n_t: int):
    """C' diag(w) C as a function of w, in O(n_t log n_t + n^2), for rows of samples
    y_j = Re sum_k beta_k (c_k + i s_k) exp(-2 pi i k j / n_t), columns (c, s) (the
    pseudo-spectral QP's): products of two phasors sum to the DFT of w at k + l and k - l."""
    k = np.asarray(k, int)
    beta = np.asarray(beta, complex)
    bb = beta[:, None] * beta[None, :]
    bc = beta[:, None] * np.conj(beta)[None, :]
    plus, minus = (k[:, None] + k[None, :]) % n_t, (k[:, None] - k[None, :]) % n_t

    def gram(w):
        W = np.fft.fft(w)
        S, D = bb * W[plus], bc * W[minus]
        return 0.5 * np.block([[(S + D).real, (1j * (S - D)).real],
                               [(1j * (S + D)).real, (D - S).real]])
    return gram


# The DFT's round-off is of the order of its largest weight: rows within DFT_RANGE of the least
# weight go through it (every row in the first iterations), heavier ones through the product.
DFT_RANGE = 1e6


def _weighted_gram(C, w):
    """C' diag(w) C, upper triangle only (what cho_factor(lower=False) reads): one BLAS syrk,
    half the flops of the plain product."""
    A = np.sqrt(w)[:, None] * C
    return dsyrk(1.0, A.T, trans=0, lower=0)        # A.T is Fortran-ordered: no copy


def _normal_factor(h, C, w, gram):
    """Cholesky factor of diag(h) + C' diag(w) C. Near the optimum w spans ~20 decades (active
    rows huge, the rest tiny); a DFT of w spreads the round-off of the huge ones over every
    entry, so those rows (above DFT_RANGE times the least, and above 1e-6 of the largest) go
    through the dense product (few) and the DFT takes the rest."""
    big = w > max(1e-6 * np.max(w), DFT_RANGE * np.min(w))
    if gram is None or big.mean() > 0.5:
        K = _weighted_gram(C, w)
    else:
        K = gram(np.where(big, 0.0, w))
        if big.any():
            K += _weighted_gram(C[big], w[big])     # its upper triangle: all cho_factor reads
    K[np.diag_indices(h.size)] += h
    try:
        return cho_factor(K, lower=False)
    except np.linalg.LinAlgError:   # the DFT's round-off after all: the dense product
        K = _weighted_gram(C, w)
        K[np.diag_indices(h.size)] += h
    # on dense grids (oversample 16, a 300 s sea) many rows are near-active and K loses
    # definiteness to round-off: a ridge of 1e-14.. of its diagonal makes the step inexact
    # only (the iteration and the dual certificate do not assume an exact step)
    scale = float(np.max(np.diag(K)))
    for ridge in (0.0, 1e-14, 1e-12, 1e-10, 1e-8):
        try:
            return cho_factor(K + ridge * scale * np.eye(h.size), lower=False)
        except np.linalg.LinAlgError:
            continue
    return cho_factor(K + 1e-6 * scale * np.eye(h.size), lower=False)


def solve_box_qp(h, q, C, d, lower, upper, *, gram=None, tol: float = 1e-10,
                 max_iterations: int = 80) -> BoxQPResult:
    """Minimise 1/2 z' diag(h) z + q' z subject to lower <= C z + d <= upper (finite bounds,
    lower < upper). gram: w -> C' diag(w) C when it has a faster form (fourier_gram) than
    the dense product. tol: relative residuals and gap at which to stop."""
    h, q, d = (np.asarray(a, float) for a in (h, q, d))
    C = np.asarray(C, float)
    hu, hl = np.asarray(upper, float) - d, d - np.asarray(lower, float)   # C z <= hu, -C z <= hl
    n, m = q.size, 2 * d.size
    z = np.zeros(n)
    # start from z = 0 with slacks at least 1 (the scaled limits are of order one)
    s_u, s_l = np.maximum(hu, 1.0), np.maximum(hl, 1.0)
    l_u, l_l = np.ones(d.size), np.ones(d.size)
    scale = 1.0 + max(np.max(np.abs(q)), np.max(np.abs(hu)), np.max(np.abs(hl)))
    status, it = "max_iterations", 0
    for it in range(1, max_iterations + 1):
        Cz = C @ z
        r_d = h * z + q + C.T @ (l_u - l_l)
        r_u, r_l = Cz + s_u - hu, -Cz + s_l - hl
        mu = (s_u @ l_u + s_l @ l_l) / m
        objective = 0.5 * z @ (h * z) + q @ z
        if (max(np.max(np.abs(r_u)), np.max(np.abs(r_l))) < tol * scale
                and np.max(np.abs(r_d)) < tol * scale and m * mu < tol * (1 + abs(objective))):
            status = "optimal"
            break
        if max(np.max(l_u), np.max(l_l)) > 1e14:     # multipliers without limit: no feasible z
            status = "infeasible"
            break
        w_u, w_l = l_u / s_u, l_l / s_l
        w = w_u + w_l
        factor = _normal_factor(h, C, w, gram)

        def step(c_u, c_l):
            # complementarity rows lambda ds + s dlambda = c; see the docstring's reference
            rhs = -r_d - C.T @ ((c_u / s_u + w_u * r_u) - (c_l / s_l + w_l * r_l))
            dz = cho_solve(factor, rhs)
            Cdz = C @ dz
            ds_u, ds_l = -r_u - Cdz, -r_l + Cdz
            return dz, ds_u, ds_l, (c_u - l_u * ds_u) / s_u, (c_l - l_l * ds_l) / s_l

        def longest(*pairs):
            alpha = 1.0
            for v, dv in pairs:
                neg = dv < 0
                if np.any(neg):
                    alpha = min(alpha, float(np.min(-v[neg] / dv[neg])))
            return alpha

        aff = step(-s_u * l_u, -s_l * l_l)
        a = longest((s_u, aff[1]), (s_l, aff[2]), (l_u, aff[3]), (l_l, aff[4]))
        mu_aff = ((s_u + a * aff[1]) @ (l_u + a * aff[3])
                  + (s_l + a * aff[2]) @ (l_l + a * aff[4])) / m
        sigma = (mu_aff / mu) ** 3
        dz, ds_u, ds_l, dl_u, dl_l = step(sigma * mu - s_u * l_u - aff[1] * aff[3],
                                          sigma * mu - s_l * l_l - aff[2] * aff[4])
        a = 0.99 * longest((s_u, ds_u), (s_l, ds_l), (l_u, dl_u), (l_l, dl_l))
        z, s_u, s_l = z + a * dz, s_u + a * ds_u, s_l + a * ds_l
        l_u, l_l = l_u + a * dl_u, l_l + a * dl_l
    objective = float(0.5 * z @ (h * z) + q @ z)
    bound = dual_value(h, q, C, d, lower, upper, l_u, l_l)
    return BoxQPResult(z, objective, bound, status, it)
