"""Vector fitting of a coupled radiation kernel group: common poles, realisation, truncation.

The machinery behind :func:`mbcontrol.hydro.radiation.fit_radiation` for one group of coupled
DOFs: relaxed vector fitting with common stable poles (Gustavsen 2006; fast QR form of
Deschrijver et al. 2008), a column realisation, square-root balanced truncation with the output
matrix refitted, the congruence scaling that makes DOFs of different units comparable, and
passivity enforcement around it (:mod:`mbcontrol.hydro.passivity`).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .passivity import _response, make_passive

TAIL_POINTS, TAIL_WEIGHT = 40, 0.3  # extrapolated K(jω) on 1.02-10 ω_max, weight per point


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
