"""The kernel's own error (module :mod:`mbcontrol.hydro.fit.radiation`, "Error"): per-frequency
relative errors of the damping and added-mass parts in the response band, the global RMS error
over the fit band, and where the worst one lies. It decides a fit's order only when no device is
given (a dataset fitted on its own); with one, it is reported beside the response error
(module response_error), and the miss message names whichever decided.
"""
from __future__ import annotations

import numpy as np

FLOOR = 1e-2       # error denominators: at least FLOOR × the DOFs' peak |K_ii| (K -> 0 as ω -> 0)
INTERP_WEIGHT = 0.25  # interpolated points count at 1/4: PCHIP is no more accurate than ~1 %, and a
                      # resonance hidden between BEM points is an error of order 1, still seen


def _normaliser(data):
    """d_i = 1/sqrt(max_ω|K_ii|): D K D has each DOF's peak 1, whatever congruence scaling K had."""
    peak = np.max(np.abs(np.einsum("kii->ki", data)), axis=0)
    return 1.0 / np.sqrt(np.where(peak > 0, peak, 1.0))


def part_sizes(data, w, ainf, inband=None):
    """Per frequency, the sizes errors are relative to, in D K D (each DOF's peak 1): damping part
    max(largest |Re K_ij|, FLOOR); added-mass part max(largest |Im K_ij|, ω × largest A∞_ii, FLOOR).
    w (nω,) rad/s, ainf (m,) the diagonal of A∞ in K's units × s. Outside ``inband`` (a mask on w;
    None: all in band) both sizes are 1, the peak: there the error is absolute, as before."""
    d = _normaliser(data)
    N = data * d[None, :, None] * d[None, None, :]
    inertia = np.asarray(w) * np.max(np.abs(ainf) * d**2)
    re = np.maximum(np.max(np.abs(N.real), axis=(1, 2)), FLOOR)
    im = np.maximum(np.maximum(np.max(np.abs(N.imag), axis=(1, 2)), inertia), FLOOR)
    if inband is not None:
        re, im = np.where(inband, re, 1.0), np.where(inband, im, 1.0)
    return re, im


def part_errors(fit, data, w, ainf):
    """Per-frequency relative errors (nω, n, n) of a coupled DOF group, module radiation's "Error":
    in D K D, |Re δK_ij| and |Im δK_ij| over the sizes of :func:`part_sizes`, the larger of the two."""
    d = _normaliser(data)
    dd = d[None, :, None] * d[None, None, :]
    re, im = part_sizes(data, w, ainf)
    dlt = (fit - data) * dd
    return np.maximum(np.abs(dlt.real) / re[:, None, None], np.abs(dlt.imag) / im[:, None, None])


def _group_errors(fit, K, groups, w, ainf, inband):
    """part_errors per decoupled group in the response band (zero between groups and outside the
    band): (nω, n, n)."""
    e = np.zeros(K.shape)
    for g in groups:
        ix = np.ix_(range(K.shape[0]), g, g)
        e[ix] = part_errors(fit[ix], K[ix], w, ainf[g]) * np.asarray(inband)[:, None, None]
    return e


def _worst(fit, K, w, dofs, groups, ainf, inband):
    """Where the in-band error is largest: ω (rad/s), entry (force DOF, motion DOF), part, error,
    K there (data and fit)."""
    e = _group_errors(fit, K, groups, w, ainf, inband)
    k, i, j = np.unravel_index(int(np.argmax(e)), e.shape)
    g = next(g for g in groups if i in g)
    re = part_sizes(K[np.ix_(range(K.shape[0]), g, g)], w, ainf[g])[0][k]
    d = np.max(np.abs(K[:, [i, j], [i, j]]), axis=0)
    er = abs(fit[k, i, j].real - K[k, i, j].real) / np.sqrt(d[0] * d[1]) / re
    return {"error": float(e[k, i, j]), "omega": float(w[k]), "entry": [dofs[i], dofs[j]],
            "part": "damping (Re K)" if er >= e[k, i, j] * (1 - 1e-9) else "added mass (Im K)",
            "data": [float(K[k, i, j].real), float(K[k, i, j].imag)],
            "fit": [float(fit[k, i, j].real), float(fit[k, i, j].imag)]}


def _gate(fit, data, w, ainf, bem, inband, scale=None):
    """The error that decides the order: the worst part error in the response band (``inband``;
    interpolated rows, ~bem, at INTERP_WEIGHT) or the global norm on the BEM rows, the larger. With
    ``scale`` (the group's congruence scaling, data = S K S) the global norm is also taken in K's
    own units, as fit_radiation reports it."""
    e = np.max(part_errors(fit, data, w, ainf), axis=(1, 2)) * np.where(bem, 1.0, INTERP_WEIGHT)
    rms = _nerr(fit[bem], data[bem])
    if scale is not None:
        u = scale[None, :, None] * scale[None, None, :]
        rms = max(rms, _nerr(fit[bem] / u, data[bem] / u))
    return max(float(np.max(e * inband, initial=0.0)), rms)


def _nerr(fit, data):
    den = np.sum(np.abs(data) ** 2)
    return float(np.sqrt(np.sum(np.abs(fit - data) ** 2) / den)) if den > 0 else 0.0


def miss_message(report) -> str:
    """The warning text of a fit that misses its tolerance, from its report."""
    wst, (lo, hi) = report["worst"], report["response_band"]
    at = f"{wst['part']} of K[{wst['entry'][0]}, {wst['entry'][1]}] at ω = {wst['omega']:.4g} rad/s"
    if report["limited_by"] == "device response":
        rw = report["response_worst"]
        where = (f"in the device's response (PTOs free): at ω = {rw['omega']:.4g} rad/s the response changes "
                 f"by {rw['error']:.2%}, most the {rw['what']} (the kernel's own worst: {wst['error']:.2%}, {at})")
    elif report["limited_by"] == "response band":
        where = f"in the {at} (response band {lo:.3g}-{hi:.3g} rad/s)"
    else:
        where = (f"as the global RMS error over the fit band (worst per frequency {wst['error']:.2%}, {at}"
                 + ("" if report.get("band_given") else "; [hydro] response_band judges it where the device moves")
                 + ")")
    what = "response error" if report["limited_by"] == "device response" else "error"
    return (f"radiation fit misses its tolerance: {what} {report['fit_error']:.2%} > tol {report['tol']:.2%}, "
            f"{where}, {report['n_states']} states; the model is used as it is")
