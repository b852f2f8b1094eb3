"""Radiation fits that grow with the number of matrix entries: arrays and farms of bodies.

:func:`mbcontrol.hydro.fit.radiation.fit_radiation` fits a coupled DOF group with one common pole set
and enforces passivity with a dense SDP; at 16 bodies that costs hours and ~10 GB. Here
(:func:`fit_radiation_columns`):

1. **Columns.** K[:, j] (the forces on every DOF when DOF j moves) is fitted on its own by
   relaxed vector fitting with its own stable poles (module vector_fit; K(0) = 0 imposed) and
   realised as χ_j' = Λ_j χ_j + b_j ν_j, μ += C_j χ_j. The work per column grows with its
   entries; the model has (poles per column) × N states, A block-diagonal.
2. **Symmetry.** A column that is a row permutation of one already fitted (identical bodies at
   mirrored or equal relative positions: a centred n × n grid has about n²/8 classes) reuses
   that fit with its rows permuted. The match is checked on the data (``SYMMETRY_TOL``); the
   error reported is always against the data of every column.
3. **Passivity** (module array_passivity). Absorbed power ν^H ½(K + K^H) ν >= 0 at every ω,
   checked on a dense grid, the asymptote ω → ∞ and, up to a size, the exact crossings of the
   Hamiltonian pencil; violations are lifted by the least data-weighted residue change
   (first-order eigenvalue perturbation, after Gustavsen & Semlyen 2001), and what a few passes
   leave by a positive-real band-pass term added to every diagonal entry.
4. **Error.** The global RMS error sqrt(Σ|δK|²/Σ|K|²) over the fit band (fit_radiation's), and
   with a response band also the per-frequency errors there; each column is fitted to a fraction
   of ``tol`` so the whole meets it; a model that still misses it after ``ROUNDS`` tightenings
   raises :class:`HydroError` (a farm's model is not used silently off its tolerance). The
   report lists the per-entry, per-frequency errors, worst first.

Layout X[i_force, j_motion], SI units, as in module radiation.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.optimize import linear_sum_assignment

from mbcontrol import defaults
from mbcontrol.errors import HydroError

from .array_passivity import enforce_columns
from .fit_error import _group_errors, _nerr
from .kernel import RECIPROCITY, _cos_transform, _with_tail, kernel_data, reciprocal
from .radiation import RadiationModel
from .vector_fit import TAIL_POINTS, TAIL_WEIGHT, _basis, _relocate, _residues

SYMMETRY_TOL = 1e-3     # columns equal to this (relative RMS) under a row permutation share a fit
COLUMN_SHARE = 0.7      # each column is fitted to this share of tol, leaving room for passivity
COLUMN_MAX = 0.014      # ... but never looser: the violations passivity must repair grow with it
ROUNDS = 3              # tightenings of the column target (× 0.6 each) before giving up


def column_classes(K, tol=SYMMETRY_TOL):
    """[(representative j, permutation π)] per column: K[:, i, j] ≈ K[:, π[i], rep] for all i.

    K (nω, n, n). A column joins the first earlier representative whose entries match its own
    under a one-to-one row assignment (diagonal to diagonal) within ``tol`` of the column's RMS."""
    n = K.shape[1]
    reps, out = [], []
    for j in range(n):
        col = K[:, :, j]
        size = np.sqrt(np.mean(np.abs(col) ** 2))
        found = None
        for r in reps:
            if abs(np.linalg.norm(K[:, j, j] - K[:, r, r])) > tol * size * np.sqrt(K.shape[0]):
                continue
            ref = K[:, :, r]
            cost = np.sqrt(np.mean(np.abs(col[:, :, None] - ref[:, None, :]) ** 2, axis=0)) / size
            cost[j, :], cost[j, r] = np.inf, 0.0        # the moving DOF maps onto the moving DOF
            cost[:, r] = np.where(np.arange(n) == j, 0.0, np.inf)
            try:
                rows, perm = linear_sum_assignment(cost)
            except ValueError:                          # no finite assignment
                continue
            if np.max(cost[rows, perm]) <= tol:
                found = (r, perm)
                break
        if found is None:
            reps.append(j)
            found = (j, np.arange(n))
        out.append(found)
    return out


def fit_radiation_columns(ds, dofs=None, *, tol: float | None = None, omega_max=None, response_band=None,
                          max_order: int = 80, n_iter: int = 10) -> RadiationModel:
    """Fit K(jω) of ``dofs`` column by column (module docstring); a stable, passive RadiationModel.

    tol : the global RMS error over the fit band (and, with ``response_band`` (lo, hi) rad/s,
    the per-frequency error there, module radiation "Error") to meet, else HydroError (None: the
    'hydro.radiation_tol' default).
    omega_max : fit only ω <= omega_max (rad/s). max_order : most poles per column. n_iter :
    pole relocations per order."""
    t_start = time.perf_counter()
    tol = defaults.get("hydro.radiation_tol") if tol is None else tol
    w, K, dofs = kernel_data(ds, dofs, omega_max)
    if w.size < 4:
        raise HydroError(f"fit_radiation_columns: {w.size} frequencies below omega_max={omega_max}; "
                         "expected at least 4")
    n = len(dofs)
    Ks, asym = reciprocal(K)                 # BEM reciprocity, up to discretisation
    # BEM frequencies only: a far pair's K_ij turns its phase by k d (k = ω²/g), 2 rad between
    # samples at 12 rad/s and 4 m, so interpolates would be fitted as if they were data
    wf, Kf, weight, bem = w, Ks, np.ones(w.size), np.ones(w.size, bool)
    tail = _tail(w, Ks)
    classes = column_classes(Ks)
    reps = sorted({r for r, _ in classes})
    ainf = np.abs(np.diag(np.asarray(ds["added_mass_inf"].sel(
        influenced_dof=list(dofs), radiating_dof=list(dofs)).values)))
    given = response_band is not None
    lo, hi = map(float, response_band) if given else (-np.inf, np.inf)
    inband = (w >= lo) & (w <= hi) & given
    target, history = min(COLUMN_SHARE * tol, COLUMN_MAX), []
    for round_ in range(ROUNDS):
        fits = {r: _fit_column(wf, Kf[:, :, r], weight, bem, target, max_order, n_iter, tail, r) for r in reps}
        model, passivity = enforce_columns(fits, classes, n, dofs, wf, weight, w)
        fit = model.frequency_response(w)
        rms = _nerr(fit, Ks)
        band = float(_group_errors(fit, Ks, [list(range(n))], w, ainf, inband).max()) if given else 0.0
        err = max(rms, band)
        history.append({"column_target": target, "n_states": model.order, "rms_error": rms,
                        "band_error": band, "passive": passivity["passive"]})
        if err <= tol and passivity["passive"]:
            break
        target *= 0.6
    if not passivity["passive"]:
        raise HydroError(f"fit_radiation_columns: passivity not reached after {passivity['corrections']} corrections "
                         f"(smallest eigenvalue {passivity['min_eig']:.3g} at {passivity['omega_at_min']:.4g} "
                         f"rad/s, {model.order} states)")
    if err > tol:
        raise HydroError(f"fit_radiation_columns: error {err:.2%} > tolerance {tol:.2%} after {ROUNDS} "
                         f"tightenings ({model.order} states, at most {max_order} poles per column); "
                         "raise [hydro] radiation_tol or max_order")
    entry = np.sqrt(np.sum(np.abs(fit - Ks) ** 2, axis=0)
                    / np.maximum(np.sum(np.abs(Ks) ** 2, axis=0), 1e-300))
    report = _report(model, fit, Ks, w, dofs, classes=classes, fits=fits, passivity=passivity,
                     history=history, tol=tol, err=err, rms=rms, band=band, given=given,
                     band_lims=(lo, hi), asym=asym, seconds=time.perf_counter() - t_start)
    return RadiationModel(A=model.A, B=model.B, C=model.C, D=np.zeros((n, n)), dofs=tuple(dofs),
                          order=model.order, fit_error=err, entry_errors=entry, report=report)


def _tail(w, K):
    """K(0+) = (2/π)∫B dω per entry and the tail exponent, or None when the damping has not
    decayed to 25 % of its peak by the top frequency (then K(0+) is unknown; module radiation)."""
    wz, Bz, p_tail = _with_tail(w, K.real, "auto")
    diag = np.abs(np.einsum("kii->ki", K.real)).sum(axis=1)
    if diag[-1] > 0.25 * diag.max():
        return None
    return _cos_transform(wz, Bz, np.zeros(1))[0], p_tail


def _fit_column(wf, H, weight, bem, target, max_order, n_iter, tail, j):
    """(poles, residue parameters (P, n)) of column j, H (nω, n), its RMS error on the BEM rows
    at most ``target`` if max_order poles allow. With ``tail`` (K(0+), exponent): C B = K(0+) and
    lightly weighted points of the asymptotic form above the band, as fit_radiation's groups."""
    nd, we, He, tw, markov = wf.size, wf, H, weight, None
    if tail is not None:
        M1, p = tail[0][:, j], tail[1]
        wn = wf[-1]
        wx = np.geomspace(1.02 * wn, 10 * wn, TAIL_POINTS)[:, None]
        cn = -wn * H[-1].imag
        ext = H[-1].real[None] * (wn / wx) ** p - 1j * (M1[None] + (cn - M1)[None] * (wn / wx) ** 2) / wx
        we, He = np.concatenate([wf, wx[:, 0]]), np.concatenate([H, ext])
        tw, markov = np.concatenate([weight, np.full(TAIL_POINTS, TAIL_WEIGHT)]), M1
    Wr = np.repeat(tw[:, None], H.shape[1], axis=1)
    s = 1j * we
    history, best = [], None
    # 4 poles more per order, to max_order, without fit_radiation's stall test: a column of
    # far pairs (K_ij turning its phase by k d) keeps gaining slowly where a group would stall
    for N in range(4, max_order + 1, 4):
        beta = np.geomspace(wf.min(), wf.max(), N // 2)
        poles = -beta / 10 + 1j * beta
        for _ in range(n_iter):
            new = _relocate(poles, s, He, Wr, Wr)
            done = new.size == poles.size and np.allclose(new, poles, rtol=1e-8, atol=0)
            poles = new
            if done:
                break
        Cr = _residues(poles, s, He, Wr, Wr, True, markov)
        err = _nerr((_basis(poles, s[:nd]) @ Cr)[bem], H[bem])
        history.append({"poles": int(sum(1 if p.imag == 0 else 2 for p in poles)), "error": err})
        if best is None or err < best[2]:
            best = (poles, Cr, err)
        if err <= target:
            break
    return best[0], best[1], history


def worst_entries(fit, K, w, dofs, count=20):
    """Per entry and frequency |δK_ij| relative to the largest |K_ii| at that ω, worst first:
    [{"entry", "omega", "error", "data", "fit"}], one row per entry (its worst ω)."""
    ref = np.max(np.abs(np.einsum("kii->ki", K)), axis=1)[:, None, None]
    e = np.abs(fit - K) / np.maximum(ref, 1e-300)
    per = e.max(axis=0)
    at = e.argmax(axis=0)
    order = np.argsort(per, axis=None)[::-1][:count]
    rows = []
    for flat in order:
        i, j = np.unravel_index(flat, per.shape)
        k = at[i, j]
        rows.append({"entry": [dofs[i], dofs[j]], "omega": float(w[k]), "error": float(per[i, j]),
                     "data": [float(K[k, i, j].real), float(K[k, i, j].imag)],
                     "fit": [float(fit[k, i, j].real), float(fit[k, i, j].imag)]})
    return rows


def _report(model, fit, K, w, dofs, *, classes, fits, passivity, history, tol, err, rms, band,
            given, band_lims, asym, seconds):
    worst = worst_entries(fit, K, w, dofs)
    w0 = worst[0]
    ev = np.linalg.eigvals(model.A)
    return {
        "method": "column-wise vector fitting, symmetric columns shared, passivity by residue perturbation",
        "n_states": int(model.order), "fit_error": float(err), "rms_error": float(rms),
        "band_error": float(band), "band_given": bool(given),
        "response_band": [float(max(band_lims[0], w.min())), float(min(band_lims[1], w.max()))],
        "limited_by": "response band" if given and band >= rms else "global RMS",
        "worst": {"error": w0["error"], "omega": w0["omega"], "entry": w0["entry"],
                  "part": "K (damping and added mass)", "data": w0["data"], "fit": w0["fit"]},
        "worst_entries": worst,
        "error_definition": "global RMS sqrt(Σ|δK|²/Σ|K|²) over the fit band (and, with a response band, "
                            "module radiation's per-frequency error there); worst_entries: |δK_ij| over the "
                            "largest |K_ii| at that ω",
        "column_classes": len(fits), "class_of_column": [int(r) for r, _ in classes],
        "poles_per_column": {dofs[r]: int(f[1].shape[0]) for r, f in fits.items()},
        "rounds": history, "tol": float(tol), "tol_met": bool(err <= tol),
        "dofs": list(dofs), "symmetrized": bool(asym < RECIPROCITY), "asymmetry": float(asym),
        "omega_fit": [float(w.min()), float(w.max())], "n_omega": int(w.size),
        "slowest_decay": float(-np.max(ev.real)), "max_real_eig": float(np.max(ev.real)),
        "passivity": {"enforce": True, "enforced": passivity["corrections"] > 0, **passivity},
        "seconds": float(seconds),
    }
