"""Negative radiation damping in read data: found on the scaled B(omega), then repaired (short
runs interpolated, the rest projected to the nearest positive semi-definite matrix) or refused."""
from __future__ import annotations

import warnings

import numpy as np

from ...errors import HydroError
from .layout import HydroCleaningWarning, fmt_omega, force_first, kind_scales, set_force_first


def _nearest_psd(X, scale):
    """Nearest positive semi-definite matrix to X (Frobenius norm of the scaled matrix), exactly symmetric."""
    lam, vec = np.linalg.eigh(0.5 * (X + X.T) / scale)
    P = (vec * np.clip(lam, 0.0, None)) @ vec.T
    return 0.5 * (P + P.T) * scale


def _flag_damping(Ss, diag_tol, eig_tol):
    """Per frequency: flagged?, set of offending DOF indices, min scaled eigenvalue."""
    out = []
    for S in Ss:
        d = np.diagonal(S)
        off = set(np.where(d < -diag_tol)[0].tolist())
        lam, vec = np.linalg.eigh(0.5 * (S + S.T))
        neg = lam < -eig_tol
        for k in np.where(neg)[0]:
            off |= set(np.where(vec[:, k] ** 2 >= 0.1)[0].tolist())
        out.append((bool(off), off, float(lam[0])))
    return out


def _runs(bad) -> list[tuple[int, int]]:
    """(first, last) index of each run of consecutive flagged frequencies."""
    n = len(bad)
    runs, k = [], 0
    while k < n:
        if bad[k]:
            k1 = k
            while k1 + 1 < n and bad[k1 + 1]:
                k1 += 1
            runs.append((k, k1))
            k = k1 + 1
        else:
            k += 1
    return runs


def _repairs_text(changes: list, dofs: list) -> str:
    """One sentence on the repairs: how many frequencies, where, which DOFs, by which method."""
    nw = sum(len(c["omega"]) for c in changes)
    runs_txt = [f"{c['omega'][0]:.4g}" + (f"..{c['omega'][-1]:.4g}" if len(c["omega"]) > 1 else "") for c in changes]
    touched = sorted({d for c in changes for d in c["dofs"]}, key=dofs.index)
    kinds = {}
    for c in changes:
        key = c["method"].split(" (")[0].split(":")[0]
        kinds[key] = kinds.get(key, 0) + len(c["omega"])
    return (f"negative radiation damping repaired at {nw} frequencies (ω = {', '.join(runs_txt)} rad/s; DOFs "
            f"{touched}; " + "; ".join(f"{k}: {v}" for k, v in kinds.items())
            + "); details in attrs['cleaning']['negative_damping']")


def repair_negative_damping(ds, src, record, notes, *, diag_tol, eig_tol, max_run, end_zero_tol, mode):
    dofs = [str(d) for d in ds["radiating_dof"].values]
    w = np.asarray(ds["omega"].values, dtype=float)
    B = force_first(ds["radiation_damping"]).copy()
    s = np.sqrt(kind_scales(dofs, np.abs(np.diagonal(B, axis1=1, axis2=2)).max(0)))
    scale = np.outer(s, s)
    flags = _flag_damping(B / scale, diag_tol, eig_tol)
    bad = np.array([f[0] for f in flags])
    if not bad.any():
        return ds
    if mode == "error":
        k = int(np.argmax(bad))
        raise HydroError(f"{src}: negative radiation damping at {int(bad.sum())} frequencies, first {fmt_omega(w[k])} "
                         f"(DOFs {[dofs[i] for i in sorted(flags[k][1])]}, min scaled eigenvalue "
                         f"{flags[k][2]:.3g}); expected B(ω) positive semi-definite")
    n = len(w)
    changes = []
    for k0, k1 in _runs(bad):
        idx = list(range(k0, k1 + 1))
        off = sorted(set().union(*(flags[i][1] for i in idx)))
        before = min(flags[i][2] for i in idx)
        interior = k0 > 0 and k1 < n - 1
        small = max(abs(B[i, j, j] / scale[j, j]) for i in idx for j in off) <= end_zero_tol
        still = lambda: any(f[0] for f in _flag_damping(B[idx] / scale, diag_tol, eig_tol))  # noqa: E731
        if interior and len(idx) <= max_run:
            lo, hi = k0 - 1, k1 + 1
            for rows_only in (True, False):
                for i in idx:
                    t = (w[i] - w[lo]) / (w[hi] - w[lo])
                    interp = (1 - t) * B[lo] + t * B[hi]
                    if rows_only:
                        Bi = B[i]  # a view: row/column assignment without advanced-index transposition
                        Bi[off, :] = interp[off, :]
                        Bi[:, off] = interp[:, off]
                    else:
                        B[i] = interp
                if not still():
                    break
                off = list(range(len(dofs)))  # rows/columns alone were not enough: whole matrices
            method = ("linear interpolation in ω from the neighbouring frequencies ("
                      + ("rows and columns of these DOFs)" if len(off) < len(dofs) else "whole matrix)"))
        elif not interior and small:
            for i in idx:
                Bi = B[i]
                Bi[off, :] = 0.0
                Bi[:, off] = 0.0
            method = ("set to 0 (rows and columns of these DOFs): the run touches the end of the frequency range "
                      f"and |B_kk| there is below {end_zero_tol:g} of its scale, consistent with B -> 0")
        else:
            method = None
        if method is None or still():
            if mode != "project":
                why = ("cannot be repaired from neighbouring frequencies" if method is None else
                       f"remains after {method.split(' (')[0]}")
                where = ("over the end of the range, where B is not small" if not interior else
                         f"over {len(idx)} consecutive frequencies" + (f" (more than {max_run})"
                                                                      if len(idx) > max_run else ""))
                raise HydroError(
                    f"{src}: negative radiation damping {where}: {fmt_omega(w[k0])} to {fmt_omega(w[k1])}, DOFs "
                    f"{[dofs[j] for j in off]}, min scaled eigenvalue {before:.3g}; expected B(ω) positive "
                    f"semi-definite. It {why} — set [hydro] source_options = {{ negative_damping = "
                    f"\"project\" }} in the scene (Python: negative_damping='project') to use the nearest "
                    "positive semi-definite matrix there, or fix the BEM run")
            for i in idx:
                B[i] = _nearest_psd(B[i], scale)
            off = list(range(len(dofs)))
            method = ("nearest positive semi-definite matrix (negative eigenvalues of the scaled B set to 0)"
                      if method is None else method + ", then nearest positive semi-definite matrix")
        changes.append({"omega": [float(w[i]) for i in idx], "dofs": [dofs[j] for j in off],
                        "method": method, "min_scaled_eigenvalue_before": before})
    set_force_first(ds, "radiation_damping", B)
    record["negative_damping"] = changes
    text = _repairs_text(changes, dofs)
    notes.append(text)
    warnings.warn(f"{src}: {text}", HydroCleaningWarning, stacklevel=4)
    return ds
