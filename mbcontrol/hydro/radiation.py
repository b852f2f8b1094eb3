"""Radiation memory: impulse response K(t), a coupled state-space fit, and a reference convolution.

Cummins' radiation force is μ(t) = ∫₀ᵗ K(t-τ) ν(τ) dτ with K(t) = (2/π)∫₀^∞ B(ω) cos(ωt) dω,
whose transfer function is K(jω) = B(ω) + jω(A(ω) - A∞) (ERRATA §4 "Radiation kernel").
:func:`fit_radiation` realises K(s) for the full coupled DOF set as χ' = Aχ + Bν, μ = Cχ (D = 0):

1. DOFs split into groups that are exactly uncoupled in the data; zero couplings stay exactly 0.
2. Per group, relaxed vector fitting (Gustavsen 2006; fast QR form of Deschrijver et al. 2008) of
   all entries with one common set of stable poles (unstable ones flipped), after the congruence
   scaling K̃ = S K S, S = diag(1/√max|K_ii|) with the max over each unit class (translations,
   rotations), that makes DOFs of different units comparable and leaves those of one unit as
   they are.
   Residues obey K(0) = 0 (B(0) = 0, A(0) finite) and C B = K(t=0+) = (2/π)∫B dω. The data are
   refined by interpolation where the BEM grid is sparse, and extended above the band by a few
   lightly weighted points of the asymptotic form, so the model cannot hide resonances between
   samples or invent a large response outside the data.
3. Realisation with one pole copy per input column (exact, non-minimal), square-root balanced
   truncation to the smallest order that still meets the tolerance, with the output matrix
   refitted (poles kept) at each trial order.
4. Passivity (``passive=True``): exact test, and if violated, the smallest data-weighted change
   of C that makes the group passive (KYP-lemma SDP, :mod:`mbcontrol.hydro.passivity`), at a
   higher order if the enforced error misses the tolerance.

All matrices use the layout X[i_force, j_motion]; ν are CoG twists in NED body axes (SI).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from mbcontrol.errors import HydroError

from .bem import matrix
from .passivity import _response, make_passive, passivity_test

ZERO_COUPLING = 1e-6  # |K_ij| <= this * sqrt(max|K_ii| max|K_jj|): treated as an exact zero
TAIL_POINTS, TAIL_WEIGHT = 40, 0.3  # extrapolated K(jω) on 1.02-10 ω_max, weight per point
DENSE_STEP = 0.02  # fit on a grid refined (by interpolation) to Δω <= 2 % of ω
RETARGETS = 2      # refits with a tighter target when the error on the BEM grid misses tol


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


# ---------------------------------------------------------------- vector fitting core
def _poles_real_form(poles):
    """Λ, b with Σ c_i φ_i(s) = cᵀ(sI - Λ)⁻¹b: real p -> [p], b = 1; pair -> [[a, β], [-β, a]], b = (2, 0).
    b is also the row giving the sum of residues (t = 0+ value) from the real parameters c."""
    blk = [np.array([[p.real]]) if p.imag == 0 else np.array([[p.real, p.imag], [-p.imag, p.real]]) for p in poles]
    return sla.block_diag(*blk), np.concatenate([[1.0] if p.imag == 0 else [2.0, 0.0] for p in poles])


def _basis(poles, s):
    """Real-parameter basis Φ (len(s), N): 1/(s-p) for real p; 1/(s-p)+1/(s-p̄), j/(s-p)-j/(s-p̄) for pairs."""
    cols = []
    for p in poles:
        u, v = 1.0 / (s - p), 1.0 / (s - np.conj(p))
        cols += [u] if p.imag == 0 else [u + v, 1j * (u - v)]
    return np.stack(cols, axis=1)


def _ri(x):
    return np.concatenate([x.real, x.imag], axis=0)


def _clean_poles(ev, wmax=np.inf):
    """Flip unstable poles, cap |p| at 10 ω_max (a pole far above the band only mimics a
    feedthrough, which K(∞) = 0 forbids), keep real poles and the upper member of each pair."""
    ev = np.where(ev.real > 0, -ev.real + 1j * ev.imag, ev)
    ev = np.where(np.abs(ev) > 10 * wmax, ev / np.abs(ev) * 10 * wmax, ev)
    tol = 1e-9 * np.maximum(np.abs(ev), 1e-300)
    cplx = ev[ev.imag > tol]
    return np.concatenate([np.sort(ev[np.abs(ev.imag) <= tol].real) + 0j, cplx[np.argsort(cplx.imag)]])


def _relocate(poles, s, H, wt):
    """One relaxed-VF pole relocation. H: (nω, n_entries) scaled data, wt: row weights."""
    Phi = _basis(poles, s)
    N, ns = Phi.shape[1], s.size
    rows = []
    for e in range(H.shape[1]):
        h = H[:, e:e + 1]
        M = _ri(wt[:, None] * np.hstack([Phi, -h * Phi, -h]))
        R = np.linalg.qr(M, mode="r")
        rows.append(R[N:2 * N + 1, N:])
    Rs = np.vstack(rows)
    a = np.concatenate([np.sum(Phi.real, axis=0), [ns]])  # relaxation: Re Σ_k σ(s_k) = nω
    x0 = a * ns / (a @ a)
    Z = sla.null_space(a[None, :])
    x = x0 + Z @ np.linalg.lstsq(Rs @ Z, -Rs @ x0, rcond=None)[0]
    ct, dt = x[:N], x[N]
    if abs(dt) < 1e-8:  # Gustavsen's fallback: fix d̃ away from zero, drop the relaxation row
        dt = np.copysign(1e-8, dt if dt != 0 else 1.0)
        ct = np.linalg.lstsq(Rs[:, :N], -Rs[:, N] * dt, rcond=None)[0]
    Lam, b = _poles_real_form(poles)
    return _clean_poles(np.linalg.eigvals(Lam - np.outer(b, ct) / dt), float(np.abs(s).max()))


def _constrained_lstsq(M, Y, Gc, Hc):
    """argmin ‖M x - y‖ subject to Gc x = h, for the columns y of Y and h of Hc (Gc full row rank)."""
    if Gc is None or Gc.shape[0] == 0:
        return np.linalg.lstsq(M, Y, rcond=None)[0]
    Xp = np.linalg.pinv(Gc) @ Hc
    Z = sla.null_space(Gc)
    return Xp + Z @ np.linalg.lstsq(M @ Z, Y - M @ Xp, rcond=None)[0]


def _residues(poles, s, H, wt, dc_zero=True, markov=None):
    """Real residue parameters C (N, n_entries) minimising |Φ C - H|, optionally with Φ(0) C = 0
    (K(0) = 0) and Σ residues = ``markov`` (K(t=0+), one value per entry)."""
    rows, vals = [], []
    if dc_zero:
        rows.append(_basis(poles, np.array([0.0 + 0.0j])).real[0])  # Φ(0) is real
        vals.append(np.zeros(H.shape[1]))
    if markov is not None:
        rows.append(_poles_real_form(poles)[1])
        vals.append(np.asarray(markov, dtype=float))
    if len(rows) >= len(rows[0] if rows else []):  # no freedom left: drop the constraints
        rows, vals = [], []
    Gc = np.array(rows) if rows else None
    return _constrained_lstsq(_ri(wt[:, None] * _basis(poles, s)), _ri(wt[:, None] * H), Gc,
                              np.array(vals) if rows else None)


def _nerr(fit, data):
    den = np.sum(np.abs(data) ** 2)
    return float(np.sqrt(np.sum(np.abs(fit - data) ** 2) / den)) if den > 0 else 0.0


def _psd_sqrt(W):
    ev, V = np.linalg.eigh((W + W.T) / 2)
    return V * np.sqrt(np.clip(ev, 0, None))


def _balanced(A, B, C):
    """Square-root balanced realisation (all states), Hankel singular values descending."""
    Wc = sla.solve_continuous_lyapunov(A, -B @ B.T)
    Wo = sla.solve_continuous_lyapunov(A.T, -C.T @ C)
    Lc, Lo = _psd_sqrt(Wc), _psd_sqrt(Wo)
    U, hsv, Vt = np.linalg.svd(Lo.T @ Lc)
    keep = hsv > 1e-14 * hsv[0]
    U, hsv, V = U[:, keep], hsv[keep], Vt[keep].T
    T, Ti = Lc @ V / np.sqrt(hsv), (U / np.sqrt(hsv)).T @ Lo.T
    return Ti @ A @ T, Ti @ B, C @ T, hsv


@dataclass(frozen=True, eq=False)
class RadiationModel:
    """χ' = Aχ + Bν, μ = Cχ + Dν for the listed DOFs (CoG twists in NED body axes, SI units).

    fit_error = sqrt(Σ|K_fit - K_bem|² / Σ|K_bem|²) over all entries and the fitted BEM
    frequencies, K(jω) = B(ω) + jω(A(ω) - A∞). entry_errors[i, j] is the same ratio per entry
    (0 for entries that are zero in the data). report (JSON-serialisable): method, n_states,
    fit_error, entry_errors, per-group poles ([re, im]), order history, Hankel singular values,
    max Re eig(A), and "passivity": the exact test of the final model (eigenvalues of the
    Hermitian part ½(K + Kᴴ), margin = min/max, violation bands) plus, if it was enforced,
    "before" (error and test of the unconstrained fit) and the error growth.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dofs: tuple
    order: int
    fit_error: float
    entry_errors: np.ndarray
    report: dict = field(default_factory=dict)

    def frequency_response(self, omega) -> np.ndarray:
        """K_fit(jω) = C(jωI - A)⁻¹B + D, shape (nω, n, n), ω in rad/s."""
        s = 1j * np.atleast_1d(np.asarray(omega, dtype=float))
        if self.order == 0:
            return np.broadcast_to(self.D.astype(complex), (s.size,) + self.D.shape).copy()
        return _response(self.A, self.B, self.C, self.D, s.imag, cond_max=1e10)

    def impulse_response(self, t) -> np.ndarray:
        """C e^{At} B (+ D δ ignored), shape (nt, n, n), t in s."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if self.order == 0:
            return np.zeros((t.size,) + self.D.shape)
        dt = np.diff(t)
        if t.size > 2 and dt[0] > 0 and np.allclose(dt, dt[0], rtol=1e-12, atol=0):  # X_k+1 = e^{AΔt} X_k
            X, Phi = [sla.expm(self.A * t[0]) @ self.B], sla.expm(self.A * dt[0])
            while len(X) < t.size:
                X.append(Phi @ X[-1])
            return self.C @ np.stack(X)
        return np.stack([self.C @ sla.expm(self.A * tk) @ self.B for tk in t])


def _densify(w, K, max_step=DENSE_STEP):
    """Insert monotone-cubic (PCHIP) interpolates of K so that Δω <= max_step·ω everywhere.

    A sparse grid lets a fit put a sharp resonance between two samples unseen; the interpolates
    (as smooth as the data) expose it to the fit and to the order selection."""
    from scipy.interpolate import PchipInterpolator

    pts = [w[:1]]
    for a, b in zip(w[:-1], w[1:]):
        k = max(1, int(np.ceil((b - a) / (max_step * b))))
        pts.append(np.linspace(a, b, k + 1)[1:])
    wd = np.concatenate(pts)
    if wd.size == w.size:
        return w, K
    re, im = PchipInterpolator(w, K.real, axis=0), PchipInterpolator(w, K.imag, axis=0)
    return wd, re(wd) + 1j * im(wd)


def _groups(K):
    """Connected components of the coupling graph of K (nω, n, n)."""
    mag = np.max(np.abs(K), axis=0)
    d = np.sqrt(np.diag(mag))
    link = mag > ZERO_COUPLING * np.outer(d, d)
    link = link | link.T
    from scipy.sparse.csgraph import connected_components

    labels = connected_components(link, directed=False)[1]
    groups = [sorted(np.flatnonzero(labels == g)) for g in np.unique(labels[d > 0])]
    return [[int(i) for i in g] for g in groups], link


def _vector_fit(w, H, wt, nd, tol, max_order, n_iter, dc_zero, markov=None):
    """Common poles for all columns of H (nω, n_entries), N = 2, 4, … poles until the error is met.
    Each order starts from pairs spread log-uniformly over the data band with damping ratio ~0.1
    (well-damped starts avoid spurious sharp resonances). Rows from nd on are the weighted
    asymptotic tail; errors count the first nd (data) rows only."""
    s = 1j * w
    history, best = [], None
    for N in range(2, max_order + 1, 2):
        beta = np.geomspace(w[:nd].min(), w[:nd].max(), N // 2)
        poles = -beta / 10 + 1j * beta
        for _ in range(n_iter):
            new = _relocate(poles, s, H, wt)
            done = new.size == poles.size and np.allclose(new, poles, rtol=1e-8, atol=0)
            poles = new
            if done:
                break
        Cr = _residues(poles, s, H, wt, dc_zero, markov)
        err = _nerr(_basis(poles, s[:nd]) @ Cr, H[:nd])
        history.append({"poles": int(sum(1 if p.imag == 0 else 2 for p in poles)), "error_scaled": err})
        if best is None or err < best[2]:
            best = (poles, Cr, err)
        # stop at the target, or when 4 more pole pairs gained < 20 %: beyond that VF fits the
        # non-rational remainder (log-k behaviour at low ω, truncated band) with spurious poles
        stalled = len(history) > 4 and best[2] > 0.8 * min(h["error_scaled"] for h in history[:-4])
        if err <= tol or stalled:
            break
    return best[0], best[1], history


def _refit_output(A, B, s, G, wt, pattern, dc_zero, markov=None):
    """Least-squares output matrix C for fixed (A, B): truncation keeps the poles, this restores
    the accuracy (and K(0) = 0, C B = K(0+)) that dropping states costs. Zero-pattern entries are
    fitted to 0."""
    r, m = B.shape
    X = wt[:, None, None] * _response(A, B, np.eye(r), None, s.imag, 1e10)  # (nω, r, m): (sI - A)⁻¹B, weighted
    Xt = np.einsum("krm->kmr", X).reshape(-1, r)
    M = np.concatenate([Xt.real, Xt.imag])  # same regressors for every output row
    tgt = wt[:, None, None] * np.where(pattern[None], G, 0.0)  # (nω, m_out, m_in)
    Y = np.concatenate([tgt.transpose(0, 2, 1).reshape(-1, m).real, tgt.transpose(0, 2, 1).reshape(-1, m).imag])
    rows, vals = [], []
    if dc_zero:
        rows.append(np.linalg.solve(A, B).T)  # c A⁻¹B = 0  <=>  K(0) = 0
        vals.append(np.zeros((m, m)))
    if markov is not None:
        rows.append(B.T)  # c B = K(0+)
        vals.append(np.where(pattern, markov, 0.0).T)
    while rows and sum(x.shape[0] for x in rows) >= r:  # keep some freedom for the fit
        rows.pop(), vals.pop()
    Gc = np.vstack(rows) if rows else None
    return _constrained_lstsq(M, Y, Gc, np.vstack(vals) if rows else None).T


def _congruence_scale(Kg, unit_class):
    """S of K̃ = S K S: 1/√max|K_ii| taken over all DOFs of one unit class (translations, rotations).

    Entries of one class share units, so their sizes are commensurable and stay as they are: a
    small entry (the deep RM3 plate's heave damping, 2 % of the float's) is not inflated to the
    size of the large one, where its BEM noise (13 % there, by the Kramers-Kronig check) would
    draw the fit away from the entries that carry the force. Between classes the scale makes
    N s/m and N m s/rad comparable."""
    diag = np.max(np.abs(np.einsum("kii->ki", Kg)), axis=0)
    classes = np.asarray(unit_class)
    peak = np.array([diag[classes == c].max() for c in classes])
    return 1.0 / np.sqrt(peak)


def _unit_class(dof: str) -> str:
    kind = dof.rsplit("__", 1)[-1]
    return {"Surge": "m", "Sway": "m", "Heave": "m", "Roll": "rad", "Pitch": "rad", "Yaw": "rad"}.get(kind, dof)


def _fit_group(w, Kg, pattern, unit_class, tol, max_order, n_iter, dc_zero, refit, M1=None, p_tail=3.0,
               passive_states=0, vf_frac=0.7):
    """VF of one coupled group (scaled) to vf_frac·tol, column realisation, balanced truncation to tol."""
    m = Kg.shape[1]
    sc = _congruence_scale(Kg, unit_class)
    G = Kg * sc[None, :, None] * sc[None, None, :]
    ent = [(i, j) for i in range(m) for j in range(m) if pattern[i, j]]
    M1s = None if M1 is None else M1 * sc[:, None] * sc[None, :]  # scaled like G
    nd = w.size
    # Above the band the data say nothing. Lightly weighted points of an extrapolation keep the
    # model from inventing a large out-of-band response (which spoils K(t) near t = 0):
    # Re K = B_N (ω_N/ω)^p, and Im K = ω(A - A∞) = -[M1 + (c_N - M1)(ω_N/ω)²]/ω, the two-term
    # asymptotic form (K(0+)/ω, then K''(0+)/ω³) that is continuous with the data (c_N = -ω_N Im K_N)
    # and tends to the first Markov parameter M1 = K(0+).
    we, Ge, wt = w, G, np.ones(nd)
    if M1s is not None:
        wn = w.max()
        wx = np.geomspace(1.02 * wn, 10 * wn, TAIL_POINTS)[:, None, None]
        cn = -wn * G[-1].imag
        ext = G[-1].real[None] * (wn / wx) ** p_tail - 1j * (M1s[None] + (cn - M1s)[None] * (wn / wx) ** 2) / wx
        wx = wx[:, 0, 0]
        we = np.concatenate([w, wx])
        Ge = np.concatenate([G, np.where(pattern[None], ext, 0.0)])
        wt = np.concatenate([np.ones(nd), np.full(wx.size, TAIL_WEIGHT)])
    He = np.stack([Ge[:, i, j] for i, j in ent], axis=1)
    # most of the error budget for the fit, the rest for the truncation (errors add ~ in quadrature)
    poles, Cr, history = _vector_fit(we, He, wt, nd, vf_frac * tol, max_order, n_iter, dc_zero,
                                     None if M1s is None else np.array([M1s[i, j] for i, j in ent]))
    Lam, bvec = _poles_real_form(poles)
    N = Lam.shape[0]
    A = np.kron(np.eye(m), Lam)
    B = np.kron(np.eye(m), bvec[:, None])
    C = np.zeros((m, m * N))
    for e, (i, j) in enumerate(ent):
        C[i, j * N:(j + 1) * N] = Cr[:, e]
    Ab, Bb, Cb, hsv = _balanced(A, B, C)

    def error(Ar, Br, Cr_):
        fit = _response(Ar, Br, Cr_, None, w, 1e10)
        fit[:, ~pattern] = 0.0
        return max(_nerr(fit, G), _nerr(fit / (sc[None, :, None] * sc[None, None, :]), Kg))

    def trial(r):
        Ar, Br = Ab[:r, :r], Bb[:r]
        if np.max(np.linalg.eigvals(Ar).real) >= 0:
            return np.inf, None
        Cr_ = _refit_output(Ar, Br, 1j * we, Ge, wt, pattern, dc_zero, M1s) if refit else Cb[:, :r]
        return error(Ar, Br, Cr_), (Ar, Br, Cr_)

    # smallest r meeting tol (or, if the fit itself misses it, within 5 % of the full-order error);
    # the error is close to monotone in r, so bisect
    target = max(tol, 1.05 * trial(hsv.size)[0])
    lo, hi = 1, hsv.size
    while lo < hi:
        mid = (lo + hi) // 2
        if trial(mid)[0] <= target:
            hi = mid
        else:
            lo = mid + 1
    err, (Ar, Br, Cr_) = trial(lo)
    info = {"poles": [[float(p.real), float(p.imag)] for p in poles], "history": history, "hsv": hsv.tolist(),
            "order": int(lo), "error_gate": float(err)}
    before = (Ar, Br / sc[None, :], Cr_ / sc[:, None])
    if passive_states:
        Ar, Br, Cr_, err, info["passivity"] = make_passive(trial, error, (Ar, Br, Cr_), err, target, hsv.size,
                                                           passive_states, we, np.where(pattern[None], Ge, 0.0), wt,
                                                           dc_zero, M1s)
        info["order"] = int(Ar.shape[0])
    return Ar, Br / sc[None, :], Cr_ / sc[:, None], info, before


def _best_scaled_fit(common, rest, dofs, passive):
    """Fit one group under each distinct congruence scaling (per unit class, per DOF) and keep the
    model that meets tol, then one whose passivity enforcement kept C B = K(0+), then the fewest
    states, then the most accurate (error on the group's data).

    Which weighting lets the fit reach the tolerance soonest depends on the data: per-DOF scaling
    helps a small, clean entry; per-class scaling keeps the fit off a small, noisy one."""
    w, Kg, _ = common
    tol = rest[0]
    options = {"unit class": [_unit_class(d) for d in dofs], "per DOF": list(dofs)}
    if np.allclose(_congruence_scale(Kg, options["unit class"]), _congruence_scale(Kg, options["per DOF"])):
        options.pop("per DOF")
    best, tried = None, []
    for label, classes in options.items():
        args = (*common, classes, *rest)
        *abc, rep, before = _fit_group(*args)
        if passive and not rep["passivity"]["met"]:  # passive fits may need more poles: fit deeper, retry
            *abc2, rep2, _ = _fit_group(*args, vf_frac=0.15)
            if rep2["passivity"]["error_after"] < rep["passivity"]["error_after"]:
                abc, rep = abc2, {**rep2, "deeper_vector_fit": True}
        err = _nerr(_response(*abc, None, w, 1e10), Kg)
        markov_dropped = rep.get("passivity", {}).get("markov_kept") is False
        tried.append({"scaling": label, "n_states": int(abc[0].shape[0]), "error": float(err),
                      "markov_dropped": markov_dropped})
        key = (err > tol, markov_dropped, abc[0].shape[0], err)
        if best is None or key < best[0]:
            best = (key, abc, {**rep, "scaling": label}, before)
    _, abc, rep, before = best
    return abc, {**rep, "scalings_tried": tried}, before


def fit_radiation(ds, dofs=None, *, tol: float = 0.02, max_order: int = 30, omega_max=None,
                  n_iter: int = 20, dc_zero: bool = True, refit: bool = True,
                  markov: bool = True, passive: bool = True,
                  passive_max_states: int = 100) -> RadiationModel:
    """Fit one coupled, strictly proper, stable state-space model to K(jω) of ``dofs``.

    tol : target normalised error (see RadiationModel.fit_error), met per decoupled group so the
        total meets it too. max_order : most poles tried per group in vector fitting (the state
        count before truncation is poles × group size). omega_max : fit only ω <= omega_max
        (rad/s), e.g. the mesh limit ``ds.attrs["omega_max_mesh"]``. n_iter : pole relocations.
        dc_zero : impose K(0) = 0 (vector fit and output refit). refit : after truncating to r states,
        refit C by least squares with A, B fixed (keeps stability, lowers the order needed).
        markov : impose C B = K(t=0+) = (2/π)∫B dω (data, B(0) = 0, tail as impulse_response's "auto")
        and fit lightly weighted extrapolated points above the band; skipped for a DOF group
        (report["markov_imposed"]) whose B has not decayed to 25 % of its peak at the top
        frequency, where K(0+) is unknown.
        The data fix the model only inside the band; this pins its initial impulse value and the
        high-frequency asymptote K(jω) ≈ C B/(jω), instead of leaving them to far-away poles.
    passive : test each group exactly; if not passive, change C (poles kept) by the least data-weighted
        amount that makes it passive (K(0) = 0, and C B = K(0+) where feasible, kept), then search orders
        up to passive_max_states for the smallest meeting tol (an SDP per order: ~1 s at 51 states, ~4 s
        at 90). fit_error is that of the returned model; report["passivity"] has before/after numbers.
    """
    w, K, dofs = kernel_data(ds, dofs, omega_max)
    if w.size < 4:
        raise HydroError(f"fit_radiation: {w.size} frequencies below omega_max={omega_max}; expected at least 4")
    n = len(dofs)
    asym = np.linalg.norm(K - np.swapaxes(K, 1, 2)) / max(np.linalg.norm(K), 1e-300)
    Ks = 0.5 * (K + np.swapaxes(K, 1, 2)) if asym < 1e-2 else K  # BEM reciprocity, up to discretisation
    groups, link = _groups(Ks)
    # K(t=0+) = (2/π)∫B dω = C B, with B(0) = 0 and the power-law tail of impulse_response. Only
    # meaningful for a group whose B has decayed inside the band (Σ|B_ii| over its DOFs at ω_max
    # <= 25 % of its peak); otherwise the tail is a guess and neither the constraint nor the
    # extrapolation is used for that group.
    wz, Bz, p_tail = _with_tail(w, Ks.real, "auto")
    M1_all = _cos_transform(wz, Bz, np.zeros(1))[0] if markov else None
    diag_b = np.abs(np.einsum("kii->ki", Ks.real))

    def group_markov(gidx):
        bsum = diag_b[:, gidx].sum(axis=1)
        decayed = bool(bsum[-1] <= 0.25 * bsum.max())
        return M1_all[np.ix_(gidx, gidx)] if M1_all is not None and decayed else None
    wf, Kf = _densify(w, Ks)
    # the groups are fitted on the refined grid; the tolerance holds on the BEM frequencies, so
    # if interpolated points diluted the error there, refit to a proportionally tighter target
    target, targets, best = tol, [], None
    for _ in range(RETARGETS + 1):
        targets.append(float(target))
        parts, pre, info = [], [], []  # pre: the unconstrained fits (what passive=False returns)
        for gidx in groups:
            Kg = Kf[:, gidx][:, :, gidx]
            common = (wf, Kg, link[np.ix_(gidx, gidx)])
            rest = (target, max_order, n_iter, dc_zero, refit, group_markov(gidx),
                    p_tail, passive_max_states if passive else 0)
            abc, rep, before = _best_scaled_fit(common, rest, [dofs[i] for i in gidx], passive)
            parts.append((gidx, *abc))
            pre.append((gidx, *before))
            info.append({"dofs": [dofs[i] for i in gidx], **rep})
        model, entry, err = _assemble(parts, w, K, dofs)
        if best is None or err < best[2]:
            best = (model, entry, err, parts, pre, info)
        if err <= tol or wf.size == w.size:
            break
        target *= 0.95 * tol / err
    model, entry, err, parts, pre, info = best     # a tighter target can cost passivity: keep the best
    A, B, C, order = model.A, model.B, model.C, model.order
    k0_data = _cos_transform(*_with_tail(w, K.real, None)[:2], np.zeros(1))[0]
    pas = {"enforce": bool(passive), "enforced": any(g.get("passivity", {}).get("enforced") for g in info),
           **passivity_test(A, B, C).as_dict()}
    if pas["enforced"]:  # the unconstrained fit's numbers, for comparison
        m0, _, e0 = _assemble(pre, w, K, dofs)
        t0 = passivity_test(m0.A, m0.B, m0.C).as_dict()
        pas.update(before={"fit_error": e0, "n_states": m0.order, **{k: t0[k] for k in (
            "passive", "margin", "min_eig", "omega_at_min", "max_eig", "bands", "grid_min_eig")}},
            fit_error_growth=err / e0 if e0 > 0 else 1.0,
            enforcement_seconds=sum(g["passivity"]["seconds"] for g in info if "passivity" in g))
    report = {
        "method": "relaxed vector fitting, common poles per coupled DOF group, K(0)=0 and CB=K(0+) imposed; "
                  "balanced truncation with output refit" + ("; passivity by KYP-lemma SDP on C" if passive else ""),
        "n_states": int(order), "poles_per_group": [g["history"][-1]["poles"] for g in info],
        "fit_error": err, "dofs": list(dofs), "entry_errors": entry.tolist(),
        "groups": info, "symmetrized": bool(asym < 1e-2), "asymmetry": float(asym),
        "tail_exponent": float(p_tail), "markov_imposed": [group_markov(g) is not None for g in groups],
        "omega_fit": [float(w.min()), float(w.max())], "n_omega": int(w.size), "tol": float(tol),
        "tol_met": bool(err <= tol), "internal_targets": targets,
        "max_real_eig": float(np.max(np.linalg.eigvals(A).real)) if order else None,
        # K_fit(t=0+) = C B against the data's (2/π)∫B dω without tail: far from 1 flags
        # out-of-band poles with big residues
        "markov_ratio": float(np.linalg.norm(C @ B) / max(np.linalg.norm(k0_data), 1e-300)),
        "K0_relative": float(np.linalg.norm(model.frequency_response([0.0])[0])
                             / np.max(np.linalg.norm(K, axis=(1, 2)))),
        "passivity": pas,
    }
    return RadiationModel(A=A, B=B, C=C, D=np.zeros((n, n)), dofs=tuple(dofs), order=order,
                          fit_error=err, entry_errors=entry, report=report)


def _assemble(parts, w, K, dofs):
    """Block-diagonal model from per-group (gidx, A, B, C), its entry and total errors on w."""
    n = len(dofs)
    order = sum(a.shape[0] for _, a, _, _ in parts)
    A = sla.block_diag(*[a for _, a, _, _ in parts]) if parts else np.zeros((0, 0))
    B, C = np.zeros((order, n)), np.zeros((n, order))
    k = 0
    for gidx, a, b, c in parts:
        B[k:k + a.shape[0], gidx], C[gidx, k:k + a.shape[0]] = b, c
        k += a.shape[0]
    model = RadiationModel(A=A, B=B, C=C, D=np.zeros((n, n)), dofs=tuple(dofs), order=order,
                           fit_error=0.0, entry_errors=np.zeros((n, n)))
    fit = model.frequency_response(w)
    return model, entry_error(fit, K), _nerr(fit, K)


def entry_error(fit, K):
    """Per-entry normalised error sqrt(Σ_ω|fit - K|² / Σ_ω|K|²), 0 where the data entry is 0."""
    den = np.sqrt(np.sum(np.abs(K) ** 2, axis=0))
    return np.where(den > 0, np.sqrt(np.sum(np.abs(fit - K) ** 2, axis=0)) / np.where(den > 0, den, 1), 0.0)
