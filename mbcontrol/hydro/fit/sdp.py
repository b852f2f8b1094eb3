"""The convex problem behind passivity enforcement: min ||G vec(Q) - z||^2 s.t. E vec(Q) = e,
Q positive semidefinite (r x r), by a small primal-dual interior-point method (measured 6-11x
faster than Clarabel on the radiation problems, same optimum) or through cvxpy.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla


def _svec_ops(r):
    """svec (upper triangle, off-diagonals × √2, so ⟨X, Y⟩_F = svec X · svec Y) and its inverse."""
    I, J = np.triu_indices(r)
    s = np.where(I == J, 1.0, np.sqrt(2.0))

    def svec(M):
        return M[..., I, J] * s

    def smat(v):
        M = np.zeros((r, r))
        M[I, J] = v / s
        M[J, I] = v / s
        return M
    return svec, smat


def _max_step(lam, D):
    """Largest α with Λ + αD ⪰ 0 (Λ = diag(lam) > 0)."""
    isq = 1.0 / np.sqrt(lam)
    ev = np.linalg.eigvalsh(isq[:, None] * D * isq[None, :])[0]
    return np.inf if ev >= 0 else -1.0 / ev


def psd_least_squares(G, z, E, e, r, *, tol=1e-8, max_iter=80):
    """min ½‖G vec(X) - z‖² subject to E vec(X) = e, X ⪰ 0 (X symmetric r×r).

    Primal-dual interior point, Nesterov-Todd scaling, Mehrotra predictor-corrector
    (Vandenberghe, "The CVXOPT linear and quadratic cone program solvers", 2010, §3-4). In the
    scaled variables the Newton matrix is I + G̃ᵀG̃, solved by the Woodbury identity through the
    p × p matrix I + G̃G̃ᵀ (p = rows of G), so no dense (r²)² matrix is ever formed: one
    iteration costs O(p·r³ + p²·r²). Returns X and an info dict (status, iterations, residuals).
    """
    svec, smat = _svec_ops(r)
    if E.shape[0]:  # independent equality rows only (E x = e  <=>  Vᵀx = Σ⁻¹Uᵀe on its row space)
        U, sv, Vt = np.linalg.svd(E, full_matrices=False)
        keep = sv > 1e-10 * sv[0]
        if np.linalg.norm(U[:, ~keep].T @ e) > 1e-8 * (1.0 + np.linalg.norm(e)):
            return np.zeros((r, r)), {"status": "infeasible", "iterations": 0, "primal_residual": np.inf,
                                      "dual_residual": np.inf, "gap": np.inf}
        E, e = Vt[keep], (U[:, keep].T @ e) / sv[keep]
    p, k = G.shape[0], E.shape[0]
    Gm = G.reshape(p, r, r)
    Gm = 0.5 * (Gm + np.swapaxes(Gm, 1, 2))
    Em = E.reshape(k, r, r)
    Em = 0.5 * (Em + np.swapaxes(Em, 1, 2))
    Gf, Ef = Gm.reshape(p, r * r), Em.reshape(k, r * r)
    X, S, y = np.eye(r), np.eye(r), np.zeros(k)
    nz, ne = 1.0 + np.linalg.norm(Gf.T @ z), 1.0 + np.linalg.norm(e)
    status, it = "max_iter", 0
    for it in range(1, max_iter + 1):
        res = Gf @ X.ravel() - z
        Rd = (Gf.T @ res - Ef.T @ y).reshape(r, r) - S
        rp = Ef @ X.ravel() - e
        mu = float(np.sum(X * S)) / r
        f = 0.5 * float(res @ res)
        if (r * mu <= tol * max(1.0, f) and np.linalg.norm(rp) <= tol * ne
                and np.linalg.norm(Rd) <= tol * nz):
            status = "optimal"
            break
        try:  # NT scaling: X = R Λ Rᵀ, S = R⁻ᵀ Λ R⁻¹
            Lx, Ls = np.linalg.cholesky(X), np.linalg.cholesky(S)
        except np.linalg.LinAlgError:
            status = "numerical"
            break
        _, lam, Vt = np.linalg.svd(Ls.T @ Lx)
        R = Lx @ Vt.T / np.sqrt(lam)
        Rinv = np.sqrt(lam)[:, None] * sla.solve_triangular(Lx, Vt.T, trans="T", lower=True).T
        Gt = svec(R.T @ Gm @ R)
        Et = svec(R.T @ Em @ R) if k else np.zeros((0, Gt.shape[1]))
        Mc = sla.cho_factor(np.eye(p) + Gt @ Gt.T)

        def hinv(V):
            return V - Gt.T @ sla.cho_solve(Mc, Gt @ V)
        HEt = hinv(Et.T)
        try:
            Sc = sla.cho_factor(Et @ HEt) if k else None
        except np.linalg.LinAlgError:
            status = "numerical"
            break
        rdt = svec(R.T @ Rd @ R)

        def newton(T):
            Hb = hinv((svec(T) - rdt)[:, None])[:, 0]
            dy = sla.cho_solve(Sc, -rp - Et @ Hb) if k else np.zeros(0)
            dX = smat(Hb + HEt @ dy)
            return dX, T - dX, dy
        L2 = np.diag(lam)
        dXa, dSa, _ = newton(-L2)  # affine predictor: Λ∘(ΔX̃ + ΔS̃) = -Λ²
        a = min(1.0, _max_step(lam, dXa), _max_step(lam, dSa))
        mu_a = float(np.sum((L2 + a * dXa) * (L2 + a * dSa))) / r
        sigma = (mu_a / mu) ** 3
        Mcor = sigma * mu * np.eye(r) - L2 @ L2 - 0.5 * (dXa @ dSa + dSa @ dXa)
        dX, dS, dy = newton(2.0 * Mcor / (lam[:, None] + lam[None, :]))
        a = min(1.0, 0.98 * _max_step(lam, dX), 0.98 * _max_step(lam, dS))
        X = X + a * (R @ dX @ R.T)
        S = S + a * (Rinv.T @ dS @ Rinv)
        X, S, y = 0.5 * (X + X.T), 0.5 * (S + S.T), y + a * dy
    return X, {"status": status, "iterations": it, "primal_residual": float(np.linalg.norm(rp) / ne),
               "dual_residual": float(np.linalg.norm(Rd) / nz), "gap": float(r * mu)}


def solve_sdp(G, z, E, e, r, solver, opts):
    """min ‖G vec(Q) - z‖² s.t. E vec(Q) = e, Q ⪰ 0: own interior point ("ipm") or cvxpy.
    Returns (Q or None, status, info)."""
    if solver == "ipm":
        Q, info = psd_least_squares(G, z, E, e, r, **(opts or {}))
        ok = info["status"] == "optimal" or (info["primal_residual"] < 1e-6 and info["gap"] < 1e-5)
        return (Q if ok else None), info["status"], {"iterations": info["iterations"]}
    import cvxpy as cp

    Qv = cp.Variable((r, r), PSD=True)
    q = cp.vec(Qv, order="F")
    prob = cp.Problem(cp.Minimize(cp.sum_squares(G @ q - z)), [E @ q == e] if E.shape[0] else [])
    try:
        prob.solve(solver=solver, **(opts or {}))
    except cp.error.SolverError as exc:
        return None, f"solver error: {exc}", {}
    ok = prob.status in ("optimal", "optimal_inaccurate") and Qv.value is not None
    return (Qv.value if ok else None), prob.status, {"iterations": int(prob.solver_stats.num_iters or 0)}
