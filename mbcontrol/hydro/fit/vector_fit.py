"""Vector fitting of a coupled radiation kernel group: common poles, realisation, truncation.

The machinery behind :func:`mbcontrol.hydro.fit.radiation.fit_radiation` for one group of coupled
DOFs: relaxed vector fitting with common stable poles (Gustavsen 2006; fast QR form of
Deschrijver et al. 2008), a column realisation, square-root balanced truncation with the output
matrix refitted, the congruence scaling that makes DOFs of different units comparable, and
passivity enforcement around it (:mod:`mbcontrol.hydro.fit.passivity`). Every least-squares step
weighs each frequency by what the order is chosen by (module radiation, "Error"): with a device,
how much its response feels the kernel there (:meth:`ResponseGate.sensitivity`, at least LS_FLOOR
of the most); without one, in the response band, the inverse size of the damping and added-mass
parts (:func:`mbcontrol.hydro.fit.fit_error.part_sizes`).
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from mbcontrol.errors import HydroError

from .fit_error import INTERP_WEIGHT, _gate, _nerr, part_errors, part_sizes
from .passive_order import make_passive
from .passivity import _response
from .response_error import LS_FLOOR

TAIL_POINTS, TAIL_WEIGHT = 40, 0.3  # extrapolated K(jω) on 1.02-10 ω_max, weight per point
SLOW_POLE = 0.1    # every pole decays at least at SLOW_POLE × the lowest data frequency (1/s)


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


def _clean_poles(ev, wmax=np.inf, wmin=0.0):
    """Flip unstable poles, cap |p| at 10 ω_max (a pole far above the band only mimics a
    feedthrough, which K(∞) = 0 forbids), make Re p <= -SLOW_POLE ω_min (the data resolve
    neither a slower real pole nor a narrower resonance; either only makes simulations wait
    for its transient), keep real poles and the upper member of each pair."""
    ev = np.where(ev.real > 0, -ev.real + 1j * ev.imag, ev)
    ev = np.where(np.abs(ev) > 10 * wmax, ev / np.abs(ev) * 10 * wmax, ev)
    ev = np.minimum(ev.real, -SLOW_POLE * wmin) + 1j * ev.imag
    tol = 1e-9 * np.maximum(np.abs(ev), 1e-300)
    cplx = ev[ev.imag > tol]
    return np.concatenate([np.sort(ev[np.abs(ev.imag) <= tol].real) + 0j, cplx[np.argsort(cplx.imag)]])


def _wri(x, wr, wi):
    """Rows [w_re Re x; w_im Im x] (weights per row)."""
    return np.concatenate([wr[:, None] * x.real, wi[:, None] * x.imag], axis=0)


def _relocate(poles, s, H, Wr, Wi):
    """One relaxed-VF pole relocation. H: (nω, n_entries) scaled data; Wr, Wi: weights of the
    real and imaginary rows, same shape."""
    Phi = _basis(poles, s)
    N, ns = Phi.shape[1], s.size
    rows = []
    for e in range(H.shape[1]):
        h = H[:, e:e + 1]
        M = _wri(np.hstack([Phi, -h * Phi, -h]), Wr[:, e], Wi[:, e])
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
    return _clean_poles(np.linalg.eigvals(Lam - np.outer(b, ct) / dt), float(np.abs(s).max()),
                        float(np.abs(s).min()))


def _constrained_lstsq(M, Y, Gc, Hc):
    """argmin ‖M x - y‖ subject to Gc x = h, for the columns y of Y and h of Hc (Gc full row rank)."""
    if Gc is None or Gc.shape[0] == 0:
        return np.linalg.lstsq(M, Y, rcond=None)[0]
    Xp = np.linalg.pinv(Gc) @ Hc
    Z = sla.null_space(Gc)
    return Xp + Z @ np.linalg.lstsq(M @ Z, Y - M @ Xp, rcond=None)[0]


def _residues(poles, s, H, Wr, Wi, dc_zero=True, markov=None):
    """Real residue parameters C (N, n_entries) minimising the weighted |Φ C - H| per entry,
    optionally with Φ(0) C = 0 (K(0) = 0) and Σ residues = ``markov`` (K(t=0+), one per entry)."""
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
    hc = np.array(vals) if rows else None
    Phi = _basis(poles, s)
    return np.stack([_constrained_lstsq(_wri(Phi, Wr[:, e], Wi[:, e]), _wri(H[:, e:e + 1], Wr[:, e], Wi[:, e]),
                                        Gc, None if hc is None else hc[:, e:e + 1])[:, 0]
                     for e in range(H.shape[1])], axis=1)


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


def _vector_fit(w, H, Wr, Wi, nd, err_fn, *, tol, max_order, n_iter, dc_zero, markov=None):
    """Common poles for all columns of H (nω, n_entries), N = 2, 4, … poles until the error is met.
    Each order starts from pairs spread log-uniformly over the data band with damping ratio ~0.1
    (well-damped starts avoid spurious sharp resonances). Rows from nd on are the weighted
    asymptotic tail; errors (``err_fn`` of the fitted first nd rows) count the data rows only."""
    s = 1j * w
    history, best = [], None
    for N in range(2, max_order + 1, 2):
        beta = np.geomspace(w[:nd].min(), w[:nd].max(), N // 2)
        poles = -beta / 10 + 1j * beta
        for _ in range(n_iter):
            new = _relocate(poles, s, H, Wr, Wi)
            done = new.size == poles.size and np.allclose(new, poles, rtol=1e-8, atol=0)
            poles = new
            if done:
                break
        Cr = _residues(poles, s, H, Wr, Wi, dc_zero, markov)
        err = err_fn(_basis(poles, s[:nd]) @ Cr)
        history.append({"poles": int(sum(1 if p.imag == 0 else 2 for p in poles)), "error_scaled": err})
        if best is None or err < best[2]:
            best = (poles, Cr, err)
        # stop at the target, or when 4 more pole pairs gained < 20 %: beyond that VF fits the
        # non-rational remainder (log-k behaviour at low ω, truncated band) with spurious poles
        stalled = len(history) > 4 and best[2] > 0.8 * min(h["error_scaled"] for h in history[:-4])
        if err <= tol or stalled:
            break
    return best[0], best[1], history


def _refit_output(A, B, s, G, Wr, Wi, pattern, dc_zero, markov=None):
    """Least-squares output matrix C for fixed (A, B): truncation keeps the poles, this restores
    the accuracy (and K(0) = 0, C B = K(0+)) that dropping states costs. Zero-pattern entries are
    fitted to 0. Wr, Wi (nω, m, m): weights of the real and imaginary parts; one solve per row."""
    r, m = B.shape
    X = _response(A, B, np.eye(r), None, s.imag, 1e10)  # (nω, r, m): (sI - A)⁻¹B
    Xt = np.einsum("krm->kmr", X).reshape(-1, r)           # rows (ω, input j)
    tgt = np.where(pattern[None], G, 0.0)
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
    Hc = np.vstack(vals) if rows else None
    C = np.empty((m, r))
    for i in range(m):
        wr, wi = Wr[:, i, :].ravel(), Wi[:, i, :].ravel()
        C[i] = _constrained_lstsq(_wri(Xt, wr, wi), _wri(tgt[:, i, :].reshape(-1, 1), wr, wi), Gc,
                                  None if Hc is None else Hc[:, i:i + 1])[:, 0]
    return C


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


def _fit_group(w, Kg, pattern, bem, ainf, inband, unit_class, *, tol, max_order, n_iter, dc_zero, refit, M1=None,
               p_tail=3.0, passive_states=0, vf_frac=0.7, judge=None):
    """VF of one coupled group (scaled) to vf_frac·tol, column realisation, balanced truncation to tol.

    judge (a :class:`mbcontrol.hydro.fit.response_error.GroupJudge`, or None): the error that gates is
    the device's response error, and the least squares weigh each ω by the response's sensitivity;
    None: the kernel's own error (module radiation, "Error")."""
    m = Kg.shape[1]
    sc = _congruence_scale(Kg, unit_class)
    G = Kg * sc[None, :, None] * sc[None, None, :]
    ent = [(i, j) for i in range(m) for j in range(m) if pattern[i, j]]
    M1s = None if M1 is None else M1 * sc[:, None] * sc[None, :]  # scaled like G
    nd = w.size
    we, Ge, tw = _extended(w, G, pattern, M1s, p_tail)
    ainf_s = ainf * sc**2  # A∞ scaled like G
    wr, wi = _ls_weights(we, Ge, tw, nd, pattern, ainf_s, inband, judge, sc)
    Wr = np.broadcast_to(wr[:, None, None], Ge.shape)
    Wi = np.broadcast_to(wi[:, None, None], Ge.shape)
    wt = wr   # passivity enforcement: one weight per ω, as the LS fit
    u = sc[None, :, None] * sc[None, None, :]
    Gp = np.where(pattern[None], G, 0.0)

    def per_omega(fit):        # the gate's error per data ω (interpolated rows at INTERP_WEIGHT)
        e = judge(fit / u) if judge is not None else np.max(part_errors(fit, Gp, w, ainf_s), axis=(1, 2)) * inband
        return e * np.where(bem, 1.0, INTERP_WEIGHT)

    def gate(fit):
        if judge is None:
            return _gate(fit, Gp, w, ainf_s, bem, inband, sc)
        return float(np.max(per_omega(fit)))
    He = np.stack([Ge[:, i, j] for i, j in ent], axis=1)
    pick = (slice(None), [i for i, _ in ent], [j for _, j in ent])

    def err_fn(rows):  # entries of the fitted data rows -> the worst part error
        fit = np.zeros_like(G)
        fit[pick] = rows
        return gate(fit)
    # most of the error budget for the fit, the rest for the truncation (errors add ~ in quadrature)
    poles, Cr, history = _vector_fit(we, He, Wr[pick], Wi[pick], nd, err_fn, tol=vf_frac * tol,
                                     max_order=max_order, n_iter=n_iter, dc_zero=dc_zero,
                                     markov=None if M1s is None else np.array([M1s[i, j] for i, j in ent]))
    Ab, Bb, Cb, hsv = _balanced(*_column_realisation(poles, Cr, ent, m))

    def error(Ar, Br, Cr_):
        fit = _response(Ar, Br, Cr_, None, w, 1e10)
        fit[:, ~pattern] = 0.0
        return gate(fit)

    def profile(Ar, Br, Cr_):   # gated error / target per enforcement frequency (the tail: 0)
        fit = _response(Ar, Br, Cr_, None, w, 1e10)
        fit[:, ~pattern] = 0.0
        return np.concatenate([per_omega(fit), np.zeros(we.size - nd)]) / target

    def trial(r):
        Ar, Br = Ab[:r, :r], Bb[:r]
        ev = np.linalg.eigvals(Ar)
        if np.max(ev.real) > -0.99 * SLOW_POLE * w.min():  # unstable, or slow (truncation can make them)
            return np.inf, None
        Cr_ = _refit_output(Ar, Br, 1j * we, Ge, Wr, Wi, pattern, dc_zero, M1s) if refit else Cb[:, :r]
        return error(Ar, Br, Cr_), (Ar, Br, Cr_)

    # smallest r meeting tol (or, if the fit itself misses it, within 5 % of the full-order error)
    target = max(tol, 1.05 * trial(hsv.size)[0])
    lo, err, (Ar, Br, Cr_) = _smallest_order(trial, hsv.size, target)
    info = {"poles": [[float(p.real), float(p.imag)] for p in poles], "history": history, "hsv": hsv.tolist(),
            "order": int(lo), "error_gate": float(err)}
    before = (Ar, Br / sc[None, :], Cr_ / sc[:, None])
    if passive_states:
        Ar, Br, Cr_, err, info["passivity"] = make_passive(
            trial, error, (Ar, Br, Cr_), err, target=target, n_max=hsv.size, max_states=passive_states, omega=we,
            H=np.where(pattern[None], Ge, 0.0), weights=wt, dc_zero=dc_zero, markov=M1s, profile=profile)
        info["order"] = int(Ar.shape[0])
    return Ar, Br / sc[None, :], Cr_ / sc[:, None], info, before


def _extended(w, G, pattern, M1s, p_tail):
    """(ω, G, weight) of the data and, with a first Markov parameter M1s, its asymptotic tail.

    Above the band the data say nothing. Lightly weighted points of an extrapolation keep the
    model from inventing a large out-of-band response (which spoils K(t) near t = 0):
    Re K = B_N (ω_N/ω)^p, and Im K = ω(A - A∞) = -[M1 + (c_N - M1)(ω_N/ω)²]/ω, the two-term
    asymptotic form (K(0+)/ω, then K''(0+)/ω³) that is continuous with the data (c_N = -ω_N Im K_N)
    and tends to the first Markov parameter M1 = K(0+)."""
    nd = w.size
    if M1s is None:
        return w, G, np.ones(nd)
    wn = w.max()
    wx = np.geomspace(1.02 * wn, 10 * wn, TAIL_POINTS)[:, None, None]
    cn = -wn * G[-1].imag
    ext = G[-1].real[None] * (wn / wx) ** p_tail - 1j * (M1s[None] + (cn - M1s)[None] * (wn / wx) ** 2) / wx
    wx = wx[:, 0, 0]
    return (np.concatenate([w, wx]), np.concatenate([G, np.where(pattern[None], ext, 0.0)]),
            np.concatenate([np.ones(nd), np.full(wx.size, TAIL_WEIGHT)]))


def _ls_weights(we, Ge, tw, nd, pattern, ainf_s, inband, judge, sc):
    """Least-squares weights (real, imaginary parts) per ω: relative, the error measure's (each
    part at each ω by 1/its size; the tail absolute), or, with a judge, where the response feels
    the kernel (relative; LS_FLOOR elsewhere)."""
    re, im = part_sizes(np.where(pattern[None], Ge, 0.0), we, ainf_s,
                        np.concatenate([inband, np.zeros(we.size - nd, bool)]))
    wr, wi = tw / re, tw / im
    if judge is not None:
        feel = judge.sensitivity(sc)
        feel = np.maximum(feel / max(feel.max(), 1e-300), LS_FLOOR)
        wr = wi = tw * np.concatenate([feel, np.full(we.size - nd, feel[-1])])
    return wr, wi


def _column_realisation(poles, Cr, ent, m):
    """(A, B, C) of a group's common-pole fit: one copy of the poles per input column."""
    Lam, bvec = _poles_real_form(poles)
    N = Lam.shape[0]
    A = np.kron(np.eye(m), Lam)
    B = np.kron(np.eye(m), bvec[:, None])
    C = np.zeros((m, m * N))
    for e, (i, j) in enumerate(ent):
        C[i, j * N:(j + 1) * N] = Cr[:, e]
    return A, B, C


def _smallest_order(trial, n, target):
    """(r, error, (A, B, C)): the smallest truncation order r <= n whose error is within
    target, by bisection (the error is close to monotone in r), then up past any order
    rejected for slow or unstable poles."""
    lo, hi = 1, n
    while lo < hi:
        mid = (lo + hi) // 2
        if trial(mid)[0] <= target:
            hi = mid
        else:
            lo = mid + 1
    err, abc = trial(lo)
    while abc is None and lo < n:  # every order rejected (slow poles) up to here
        lo += 1
        err, abc = trial(lo)
    if abc is None:
        raise HydroError("radiation fit: no truncation order free of slow or unstable poles")
    return lo, err, abc
