"""Passivity of a column-wise radiation model (module array_fit): test and enforcement.

The model: per column j, poles of its class and residue parameters C_r (rows permuted), plus an
optional diagonal "shunt" (the same positive-real band-pass terms on every diagonal entry).
Absorbed power ν^H ½(K + K^H) ν must be >= 0 at every ω:

- **Test.** Eigenvalues of the Hermitian part on 3,000 log-spaced frequencies from 1e-2 × the
  lowest to 1e2 × the highest pole or data frequency, 9 points across every resonance, the
  asymptote ω → ∞ (K ≈ M1/s + M2/s²: ω² Re K -> -M2 must be PSD), and for models of up to
  ``EXACT_TEST_STATES`` states the exact crossings of the Hamiltonian pencil (module passivity).
- **Residue perturbation.** The worst point and every local minimum of a violation join a set of
  active frequencies; each pass linearises afresh at all of them (eigenvalues and vectors of the
  current model) and changes the residues by the least amount that lifts every eigenvalue
  there to a small margin, K(0) = 0 kept: a QP whose Hessian is block-diagonal per column
  class, solved through its dual (one NNLS in as many unknowns as constraints); a step that
  makes the worst violation worse is halved. The change is weighed on the data and, with
  ``OUT_OF_BAND_WEIGHT``, two decades either side of them: on the data alone the changes they
  barely see (fast poles' residues) are cheap, and at 25 floats one pass grew them 90-fold and
  turned the asymptote ω → ∞ negative for good.
- **Shunt.** If ``RESIDUE_PASSES`` passes leave a violation, what is left is covered exactly:
  adding δ(ω) I adds δ to every eigenvalue, and δ is a non-negative sum of band-pass terms
  2ζω_k s/(s² + 2ζω_k s + ω_k²) (positive real, K(0) = 0) chosen by an LP, on the check grid
  and the asymptote, that spends the least error in the data band; centres from where their
  poles are no slower than the fits' floor (SLOW_POLE) to 10 × the data's top frequency.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla
from scipy.optimize import nnls

from .passivity import _crossings
from .radiation import RadiationModel
from .vector_fit import SLOW_POLE, _basis, _poles_real_form

EXACT_TEST_STATES = 600  # up to this many states the Hamiltonian crossings join the check grid
MAX_PASSES = 44         # passivity correction passes in all
RESIDUE_PASSES = 40     # of which residue perturbation; what it leaves, a diagonal shunt covers
OUT_OF_BAND_WEIGHT = 1.0  # of a residue change's response outside the data band, against in it
SHUNT_ZETA = 0.7        # damping ratio of the shunt's band-pass terms (broad: an octave or more)


class _Columns:
    """The column model's pieces: per class its poles' basis and residue parameters."""

    def __init__(self, fits, classes, n):
        self.fits, self.classes, self.n = fits, classes, n
        self.shunt = []          # [(ω_k, ζ, b_k)]: the same passive term on every diagonal entry

    def response(self, w, C=None):
        """K_fit(jω) (nω, n, n) with residue parameters C (dict per class; default the fits');
        at ω = inf the limit of ω² Re K(jω) (passivity far above the band: module docstring)."""
        s = _jw(w)
        out = np.empty((s.size, self.n, self.n), complex)
        phis = {r: _basis_inf(f[0], s) for r, f in self.fits.items()}
        for j, (r, perm) in enumerate(self.classes):
            c = (C or {}).get(r, self.fits[r][1])
            out[:, :, j] = phis[r] @ c[:, perm]
        if self.shunt:
            extra = sum(b * _bandpass(s, wk, z) for wk, z, b in self.shunt)
            out += extra[:, None, None] * np.eye(self.n)[None]
        return out


    def state_space(self, C=None):
        blocks, Bs, Cs = [], [], []
        for j, (r, perm) in enumerate(self.classes):
            lam, b = _poles_real_form(self.fits[r][0])
            c = (C or {}).get(r, self.fits[r][1])
            blocks.append(lam)
            Bs.append((b, j))
            Cs.append(c[:, perm].T)
        A = sla.block_diag(*blocks)
        B, Cm = np.zeros((A.shape[0], self.n)), np.hstack(Cs)
        k = 0
        for (b, j), lam in zip(Bs, blocks):
            B[k:k + lam.shape[0], j] = b
            k += lam.shape[0]
        if self.shunt:   # per DOF and term: x1' = x2, x2' = -ω² x1 - 2ζω x2 + ν, μ = 2ζω b x2
            extra = [(j, wk, z, b) for j in range(self.n) for wk, z, b in self.shunt]
            A = sla.block_diag(A, *[np.array([[0.0, 1.0], [-wk**2, -2 * z * wk]]) for _, wk, z, _ in extra])
            B = np.vstack([B, np.zeros((2 * len(extra), self.n))])
            Cm = np.hstack([Cm, np.zeros((self.n, 2 * len(extra)))])
            for m, (j, wk, z, b) in enumerate(extra):
                B[k + 2 * m + 1, j] = 1.0
                Cm[j, k + 2 * m + 1] = 2 * z * wk * b
        return A, B, Cm


def _jw(w):
    """jω as complex numbers, ω = inf giving 0 + j∞ (1j * inf would be nan + j∞)."""
    w = np.atleast_1d(np.asarray(w, dtype=float))
    s = np.zeros(w.shape, complex)
    s.imag = w
    return s


def _basis_inf(poles, s):
    """_basis, with rows at s = j∞ replaced by the coefficient of -1/ω² in Re K(jω) there:
    K ≈ M1/s + M2/s², so ω² Re K -> -M2; per basis function M2 = p (real pole), and for a pair
    (2 Re p, -2 Im p). Its eigenvalues must be >= 0 for the model to stay passive up to ∞."""
    finite = np.isfinite(s)
    out = np.zeros((s.size, sum(1 if p.imag == 0 else 2 for p in poles)), complex)
    if finite.any():
        out[finite] = _basis(poles, s[finite])
    if not finite.all():
        m2 = np.concatenate([[p.real] if p.imag == 0 else [2 * p.real, -2 * p.imag] for p in poles])
        out[~finite] = -m2
    return out


def _bandpass(s, wk, zeta):
    """2ζω_k s / (s² + 2ζω_k s + ω_k²): positive real, Re = 1 at ω_k, K(0) = 0 (at s = j∞ the
    limit of ω² Re, (2ζω_k)², as _basis_inf)."""
    s = np.asarray(s)
    with np.errstate(invalid="ignore"):
        val = 2 * zeta * wk * s / (s**2 + 2 * zeta * wk * s + wk**2)
    return np.where(np.isfinite(s), val, (2 * zeta * wk) ** 2 + 0j)


def _shunt_terms(cols, C, grid, w):
    """[(ω_k, ζ, b_k)]: the cheapest (in added error over the data band) non-negative sum of
    positive-real band-pass terms that, added to every diagonal entry, lifts the Hermitian part's
    smallest eigenvalue to zero wherever it is negative on the grid (an LP). Adding δ(ω) I adds δ
    to every eigenvalue, so what residue perturbation leaves is covered exactly."""
    from scipy.optimize import linprog
    ev = _hermitian_eigs(cols, grid, C)[0]
    fin = np.isfinite(grid)
    scale = np.where(fin, float(ev[fin, -1].max()), np.abs(ev).max(axis=1))  # ω = ∞: its own units
    need = np.where(ev[:, 0] < -1e-9 * scale, -ev[:, 0] + 1e-6 * scale, 0.0)
    if not need.any():
        return []
    # centres up to 10x the data band (a faster term would set the time step: RK4 at 0.01 s is
    # stable to 278 rad/s); above its centre a term still gives (2ζω_k)² b / ω², which is
    # what covers the asymptote's row
    top = 10 * float(np.max(w))
    # ... and down to where a term's poles (Re = -ζω_k) are no slower than the fits' floor
    lo = max(float(grid[fin].min()), SLOW_POLE * float(np.min(w)) / SHUNT_ZETA)
    centres = np.geomspace(lo, top, int(8 * np.log10(top / lo)) + 1)
    R = _bandpass(_jw(grid)[:, None], centres[None, :], SHUNT_ZETA).real
    cost = np.sqrt(np.mean(np.abs(_bandpass(1j * w[:, None], centres[None, :], SHUNT_ZETA)) ** 2, axis=0))
    res = linprog(cost, A_ub=-R[need > 0], b_ub=-need[need > 0], bounds=(0, None), method="highs")
    if not res.success:
        return []
    return [(float(c), SHUNT_ZETA, float(b)) for c, b in zip(centres, res.x) if b > 1e-12 * scale[fin][0]]


def _check_grid(fits, w):
    """Dense ω grid for the passivity check: log-spaced over 1e-2..1e2 × the span of data and
    poles (20 points per decade... and more), plus 9 points across each pole's resonance."""
    poles = np.concatenate([f[0] for f in fits.values()])
    lo = min(w.min(), np.abs(poles).min()) / 100
    hi = max(w.max(), np.abs(poles).max()) * 100
    pts = [np.geomspace(lo, hi, 3000)]
    for p in poles[poles.imag > 0]:
        pts.append(p.imag + p.real * np.linspace(-4, 4, 9))
    g = np.concatenate(pts)
    return np.append(np.unique(g[g > 0]), np.inf)   # ω = ∞: the asymptote (_basis_inf)


def enforce_columns(fits, classes, n, dofs, wf, weight, w):
    """The column model made passive (module docstring): (RadiationModel, passivity info).

    fits: class -> (poles, residue parameters (P, n), history); classes: per column (class,
    permutation); wf, weight: the fit's frequencies (rad/s) and weights; w: the data's."""
    cols = _Columns(fits, classes, n)
    C = {r: f[1].copy() for r, f in fits.items()}
    size = {r: sum(1 for q, _ in classes if q == r) for r in fits}
    # the change is weighed on the data and, with OUT_OF_BAND_WEIGHT, outside their band (two
    # decades each way): changes the data barely see (fast poles' residues) would otherwise be
    # cheap, and grow without bound there and at ω = ∞
    s = 1j * np.concatenate([wf, np.geomspace(wf.min() / 100, wf.min(), 10, endpoint=False),
                             np.geomspace(1.02 * wf.max(), 100 * wf.max(), 30)])
    weight = np.concatenate([weight, np.full(40, OUT_OF_BAND_WEIGHT)])
    # per class: K(0) = 0 kept (ΔC = Z Y), Hessian of the data-weighted change of its columns
    Z, Hinv = {}, {}
    for r, f in fits.items():
        phi0 = _basis(f[0], np.array([0j])).real
        Z[r] = sla.null_space(phi0)
        P = _basis(f[0], s) * weight[:, None]
        M = Z[r].T @ (P.conj().T @ P).real @ Z[r] * size[r]
        M += 1e-12 * np.trace(M) / M.shape[0] * np.eye(M.shape[0])
        Hinv[r] = np.linalg.inv(M)
    grid = _check_grid(fits, w)
    t0, passes, active, exact, n_con = time.perf_counter(), 0, np.zeros(0), False, 0
    for passes in range(MAX_PASSES + 1):
        ev = _hermitian_eigs(cols, grid, C)[0]
        rel, scale = _relative(ev, grid)
        bad = np.flatnonzero(rel < -1e-9)
        if bad.size == 0 and not exact:
            A, B, Cm = cols.state_space(C)
            exact = True
            if A.shape[0] <= EXACT_TEST_STATES:      # the pencil's crossings: exact edges
                cross = _crossings(A, B, Cm, np.zeros((n, n)))
                if cross.size:
                    extra = np.unique(np.concatenate([cross * (1 - 1e-6), cross * (1 + 1e-6),
                                                      np.sqrt(cross[1:] * cross[:-1])]))
                    grid = np.unique(np.concatenate([grid, extra]))
                    continue
        if bad.size == 0 or passes == MAX_PASSES:
            break
        if passes >= RESIDUE_PASSES:
            cols.shunt += _shunt_terms(cols, C, grid, w)
            continue
        # the worst point and each local minimum of the violation join the active points, which
        # stay active: each pass linearises afresh at all of them (eigenvectors of the current
        # model), so a correction cannot push a point it fixed before back below zero
        picks = [int(bad[np.argmin(rel[bad])])]
        picks += [int(k) for k in bad if rel[k] <= (rel[k - 1] if k else np.inf)
                  and rel[k] <= (rel[k + 1] if k + 1 < grid.size else np.inf)]
        active = np.unique(np.concatenate([active, grid[picks]]))
        dC, n_con = _correction(cols, C, Z, Hinv, active, scale)
        for step in (1.0, 0.5, 0.25, 0.125):          # a step that makes the worst worse is halved
            trial = {r: C[r] + step * dC[r] for r in C}
            if _relative(_hermitian_eigs(cols, grid, trial)[0], grid)[0].min() >= rel.min() or step == 0.125:
                C = trial
                break
    A, B, Cm = cols.state_space(C)
    ev = _hermitian_eigs(cols, grid, C)[0]
    rel, scale = _relative(ev, grid)
    fin = np.isfinite(grid)
    k = int(np.argmin(np.where(fin, ev[:, 0], np.inf)))
    info = {"passive": bool(rel.min() >= -1e-9), "min_eig": float(ev[k, 0]),
            "omega_at_min": float(grid[k]), "max_eig": scale, "margin": float(rel[fin].min()),
            "asymptote_margin": float(rel[~fin].min()) if (~fin).any() else None,
            "corrections": int(passes),
            "shunt_terms": [[wk, z, b] for wk, z, b in cols.shunt], "active_points": int(active.size), "constraints": int(n_con), "check_points": int(grid.size),
            "exact_crossings_used": bool(exact), "seconds": time.perf_counter() - t0,
            "method": "dense-grid eigenvalues of the Hermitian part (plus Hamiltonian crossings up to "
                      f"{EXACT_TEST_STATES} states); residue perturbation, K(0) = 0 kept"}
    model = RadiationModel(A=A, B=B, C=Cm, D=np.zeros((n, n)), dofs=tuple(dofs), order=A.shape[0],
                           fit_error=0.0, entry_errors=np.zeros((n, n)))
    return model, info


def _relative(ev, grid):
    """(smallest eigenvalue per row over its scale, the scale): finite ω over the largest
    eigenvalue on the grid; ω = ∞ (the asymptote, other units) over its own largest."""
    fin = np.isfinite(grid)
    scale = float(ev[fin, -1].max())
    rel = ev[:, 0] / scale
    if (~fin).any():
        rel[~fin] = ev[~fin, 0] / max(float(np.abs(ev[~fin]).max()), 1e-300)
    return rel, scale


def _hermitian_eigs(cols, omega, C):
    """Eigenvalues and vectors of ½(K + Kᴴ) at omega (rad/s) with residue parameters C."""
    K = cols.response(omega, C)
    return np.linalg.eigh(0.5 * (K + np.conj(np.swapaxes(K, 1, 2))))


def _correction(cols, C, Z, Hinv, active, scale):
    """The least data-weighted residue change (per class, K(0) = 0 kept) that lifts every
    eigenvalue of the Hermitian part at the active frequencies to a small margin, to first order:
    min Σ yᵀH y subject to gᵀy >= h, solved through its dual (one NNLS). (ΔC per class, rows)."""
    ev, V = _hermitian_eigs(cols, active, C)
    phis = {r: _basis_inf(f[0], _jw(active)) for r, f in cols.fits.items()}
    n, rows = cols.n, []
    for k in range(active.size):
        margin = 1e-4 * max(abs(ev[k, -1]), 1e-6 * scale)
        for e in np.flatnonzero(ev[k] < margin):
            v = V[k, :, e]
            g = {r: np.zeros((f[1].shape[0], n)) for r, f in cols.fits.items()}
            for j, (r, perm) in enumerate(cols.classes):
                vi = np.zeros(n, complex)      # Re(vᴴ ΔK v) with ΔK[i, j] = φ_r · ΔC_r[:, perm[i]]
                vi[perm] = np.conj(v) * v[j]
                g[r] += np.real(phis[r][k][:, None] * vi[None, :])
            g = {r: Z[r].T @ x for r, x in g.items()}
            norm = np.sqrt(sum(np.sum(x ** 2) for x in g.values()))   # unit rows: near ω = 0 they are ~ω²
            rows.append(({r: x / norm for r, x in g.items()}, (margin - ev[k, e]) / norm))
    G = {r: np.stack([gk[r] for gk, _ in rows]) for r in cols.fits}      # (m, P - 1, n) per class
    HG = {r: np.einsum("pq,kqn->kpn", Hinv[r], G[r]) for r in cols.fits}
    Q = sum(np.einsum("kpn,lpn->kl", G[r], HG[r]) for r in cols.fits)
    h = np.array([hk for _, hk in rows])
    scale_q = np.trace(Q) / Q.shape[0]
    for jitter in (1e-12, 1e-10, 1e-8, 1e-6):     # nearly equal rows (degenerate eigenvalues)
        try:
            L = np.linalg.cholesky(Q + jitter * scale_q * np.eye(Q.shape[0]))
            break
        except np.linalg.LinAlgError:
            continue
    lam = nnls(L.T, np.linalg.solve(L, h), maxiter=50 * Q.shape[0])[0]
    return {r: Z[r] @ np.einsum("k,kpn->pn", lam, HG[r]) for r in cols.fits}, len(rows)
