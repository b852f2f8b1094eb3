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
   of C that makes the group passive (KYP-lemma SDP, :mod:`mbcontrol.hydro.fit.passivity`), at a
   higher order if the enforced error misses the tolerance.

Error (decides the order; ``tol`` bounds it). With a ``device`` (every plant built from a scene
passes one, :func:`mbcontrol.plant.device_around`) it is the error the fit causes in the device's
own response, per BEM frequency: the largest relative change of the device's velocity under any
generalised force, ‖D Z'⁻¹ P δK Pᵀ D⁻¹‖ in the kinetic-energy norm, the device linear at rest with
its joint stiffness and drivetrains and its PTOs free, weighted down where its wave motion is under
a tenth of its peak (module response_error); ``response_band`` then only limits where it is
judged. A kernel error where the device does not move is then free (rm3's plate damping at
0.3 rad/s, 537 % off in K and nothing in the motion), and one at a lightly damped mode is not (the
flap's hinge damping). The kernel's own errors are reported beside it. Without a device (a dataset fitted on its own):
- in the response band (``response_band``), per decoupled group, in D K D (D = diag(1/√max_ω|K_ii|):
  each DOF's peak 1, so units drop out), at every BEM frequency ω and entry ij
      e_ij(ω) = max(|Re δK_ij| / R(ω), |Im δK_ij| / I(ω)),   R = max(max_kl |Re K_kl(ω)|, FLOOR),
      I = max(max_kl |Im K_kl(ω)|, ω max_k A∞_kk, FLOOR);
- over the whole fit band, the global sqrt(Σ|δK|²/Σ|K|²) (report "rms_error"), the larger of the two.
These kernel errors are what the report shows as "band_error", "worst" and "rms_error" in either case.
Interpolated points count at INTERP_WEIGHT. VF, the output refit and
the passivity enforcement minimise the matching weighted least squares. A fit missing ``tol`` warns
(:class:`RadiationFitWarning`: value, ω, entry, part), also when a shipped or cached one is loaded;
it is not an error, so plants build with the best fit found, and ``mbcontrol hydro`` prints it.
Poles: Re p <= -SLOW_POLE × the lowest fitted ω, real or complex (VF poles are moved there,
truncation orders that make a slower one are rejected): the data resolve neither a slower pole
nor a narrower resonance, and such transients made designs wait thousands of seconds.

All matrices use the layout X[i_force, j_motion]; ν are CoG twists in NED body axes (SI).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from mbcontrol import defaults
from mbcontrol.errors import HydroError

from ..data.dataset import matrix
from .kernel import RECIPROCITY, _cos_transform, _with_tail, kernel_data, reciprocal
from .passivity import _response, passivity_test_groups
from .fit_error import FLOOR, _group_errors, _nerr, _worst, miss_message
from .group_fit import _best_scaled_fit, group_error, same_group_fit
from .vector_fit import SLOW_POLE

ZERO_COUPLING = 1e-6  # |K_ij| <= this * sqrt(max|K_ii| max|K_jj|): treated as an exact zero
DENSE_STEP = 0.02  # fit on a grid refined (by interpolation) to Δω <= 2 % of ω


RESPONSE_DEFINITION = ("the worst over the fit band's ω (in the response band) of the largest relative change the fit "
                       "makes in the device's velocity under any generalised force, ||D Z'^-1 P dK P^T D^-1|| with "
                       "D = diag(sqrt(M_ii)), the device linear at rest with its joint stiffness and drivetrains and "
                       "its PTOs free, weighted by min(1, wave motion / (0.1 x its peak)) (module response_error)")


class RadiationFitWarning(UserWarning):
    """A radiation fit that misses its tolerance (the message says by how much, and where)."""


# ---------------------------------------------------------------- vector fitting core
@dataclass(frozen=True, eq=False)
class RadiationModel:
    """χ' = Aχ + Bν, μ = Cχ + Dν for the listed DOFs (CoG twists in NED body axes, SI units).

    fit_error: the larger of the worst per-frequency relative error in the response band and the
    global RMS error over the fit band (module docstring, "Error"; dimensionless). entry_errors[i, j]:
    the same per entry (0 for entries that are zero in the data). report (JSON-serialisable):
    method, n_states, fit_error, "response_band", "band_error" and "worst" (its ω, entry, part,
    data and fit values), "rms_error" (sqrt(Σ|δK|²/Σ|K|²)), "limited_by", "tol_met", entry_errors,
    per-group poles ([re, im]), order history, Hankel singular values, "slowest_decay" (1/s),
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


def coupled_groups(ds, dofs) -> list[list[str]]:
    """The DOF groups of ``dofs`` that radiation couples (connected through entries of K(jω)
    above ZERO_COUPLING): each is fitted on its own."""
    _, K, dofs = kernel_data(ds, dofs, None)
    return [[dofs[i] for i in g] for g in _groups(reciprocal(K)[0])[0]]


def fit_radiation(ds, dofs=None, *, tol: float | None = None, max_order: int = 30, omega_max=None,
                  n_iter: int = 20, dc_zero: bool = True, refit: bool = True,
                  markov: bool = True, passive: bool = True,
                  passive_max_states: int = 100, response_band=None, device=None) -> RadiationModel:
    """Fit one coupled, strictly proper, stable state-space model to K(jω) of ``dofs``.

    tol : target error (RadiationModel.fit_error), met per decoupled group so the total meets it
        (None: the 'hydro.radiation_tol' default, mbcontrol.defaults);
        too. response_band : (lo, hi) rad/s where the error is judged per frequency (module
        docstring, "Error"); None: the global error only (the worst per frequency is reported). With a
        ``device``, the band where the device's response is judged instead.
    device : a :class:`mbcontrol.hydro.fit.response_error.Device` (the plant around the kernel, from
        :func:`mbcontrol.plant.device_around`): the error that chooses the order and passivity is
        the error the fit causes in the device's response (module response_error); the kernel's own
        errors are reported beside it. max_order : most poles tried per group in vector fitting (the state
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
    tol = defaults.get("hydro.radiation_tol") if tol is None else tol
    w, K, dofs = kernel_data(ds, dofs, omega_max)
    if w.size < 4:
        raise HydroError(f"fit_radiation: {w.size} frequencies below omega_max={omega_max}; expected at least 4")
    n = len(dofs)
    Ks, asym = reciprocal(K)                 # BEM reciprocity, up to discretisation
    groups, link = _groups(Ks)
    # K(t=0+) = (2/π)∫B dω = C B, with B(0) = 0 and the power-law tail of impulse_response. Only meaningful
    # for a group whose B has decayed inside the band (Σ|B_ii| over its DOFs at ω_max <= 25 % of its peak);
    # otherwise the tail is a guess and neither the constraint nor the extrapolation is used for that group.
    wz, Bz, p_tail = _with_tail(w, Ks.real, "auto")
    M1_all = _cos_transform(wz, Bz, np.zeros(1))[0] if markov else None
    diag_b = np.abs(np.einsum("kii->ki", Ks.real))

    def group_markov(gidx):
        bsum = diag_b[:, gidx].sum(axis=1)
        decayed = bool(bsum[-1] <= 0.25 * bsum.max())
        return M1_all[np.ix_(gidx, gidx)] if M1_all is not None and decayed else None
    wf, Kf = _densify(w, Ks)
    ainf = np.abs(np.diag(matrix(ds["added_mass_inf"], dofs)))  # inertia the added-mass part is judged by
    given = response_band is not None
    lo, hi = (-np.inf, np.inf) if not given else map(float, response_band)
    inband = (w >= lo) & (w <= hi) & given     # where the per-frequency error gates the order
    if device is not None:                     # the response gates; the kernel's errors are shown
        device = device.restricted(dofs)
        gate_f, gate_w = device.at(wf, Kf), device.at(w, Ks)
        inband = (w >= lo) & (w <= hi)
    # the groups are fitted on the refined grid; their gate takes the BEM frequencies at full weight
    # (interpolated ones at INTERP_WEIGHT), so it is the error reported here
    settings = {"tol": tol, "max_order": max_order, "n_iter": n_iter, "dc_zero": dc_zero, "refit": refit,
                "p_tail": p_tail, "passive_states": passive_max_states if passive else 0}
    parts, pre, info = _fit_groups(groups, dofs, wf, Kf, link, np.isin(wf, w), ainf,
                                   (wf >= lo) & (wf <= hi) & given & (device is None),
                                   gate=gate_f if device is not None else None, markov_of=group_markov,
                                   settings=settings, passive=passive)
    model, entry, err = _assemble(parts, w, Ks, dofs, groups, ainf, inband)
    if device is not None:
        err = float(np.max(gate_w.errors(model.frequency_response(w))))
    A, B, C, order = model.A, model.B, model.C, model.order
    k0_data = _cos_transform(*_with_tail(w, K.real, None)[:2], np.zeros(1))[0]
    pas = _passivity_summary(parts, pre, info, passive, err, (w, Ks, dofs, groups, ainf, inband),
                             gate_w if device is not None else None)
    fit = model.frequency_response(w)
    shown = inband if given or device is not None else np.ones(w.size, bool)  # the worst shown, not gated
    worst = _worst(fit, Ks, w, dofs, groups, ainf, shown) if shown.any() else None
    rms = _nerr(fit, K)
    ev = np.linalg.eigvals(A) if order else np.zeros(0)
    report = {
        "method": "relaxed vector fitting, common poles per coupled DOF group, K(0)=0 and CB=K(0+) imposed; "
                  "balanced truncation with output refit" + ("; passivity by KYP-lemma SDP on C" if passive else ""),
        "n_states": int(order), "poles_per_group": [g["history"][-1]["poles"] for g in info],
        "fit_error": err, "error_definition": RESPONSE_DEFINITION if device is not None else (
            "the larger of: in the response band, the worst over the BEM ω and coupled entries of |Re δK| / "
            "largest |Re K| and |Im δK| / max(largest |Im K|, ωA∞) at that ω, DOF peaks normalised to 1, sizes "
            f"at least {FLOOR:g}; the global RMS error over the fit band (module radiation)"),
        "response_band": [float(max(lo, w.min())), float(min(hi, w.max()))],
        "band_given": given,
        "band_error": worst["error"] if worst else 0.0, "worst": worst, "rms_error": rms,
        "limited_by": ("device response" if device is not None else
                       "response band" if given and worst and worst["error"] >= rms else "global RMS"),
        "response_error": err if device is not None else None,
        "response_worst": gate_w.worst(fit) if device is not None else None,
        "slowest_decay": float(-np.max(ev.real)) if order else None, "decay_floor": SLOW_POLE * float(w.min()),
        "dofs": list(dofs), "entry_errors": entry.tolist(),
        "groups": info, "symmetrized": bool(asym < RECIPROCITY), "asymmetry": float(asym),
        "tail_exponent": float(p_tail), "markov_imposed": [group_markov(g) is not None for g in groups],
        "omega_fit": [float(w.min()), float(w.max())], "n_omega": int(w.size), "tol": float(tol),
        "tol_met": bool(err <= tol),
        "max_real_eig": float(np.max(np.linalg.eigvals(A).real)) if order else None,
        # K_fit(t=0+) = C B against the data's (2/π)∫B dω without tail: far from 1 flags
        # out-of-band poles with big residues
        "markov_ratio": float(np.linalg.norm(C @ B) / max(np.linalg.norm(k0_data), 1e-300)),
        "K0_relative": float(np.linalg.norm(model.frequency_response([0.0])[0])
                             / np.max(np.linalg.norm(K, axis=(1, 2)))),
        "passivity": pas,
    }
    if err > tol:
        warnings.warn(RadiationFitWarning(miss_message(report)), stacklevel=2)
    return RadiationModel(A=A, B=B, C=C, D=np.zeros((n, n)), dofs=tuple(dofs), order=order,
                          fit_error=err, entry_errors=entry, report=report)


def _fit_groups(groups, dofs, wf, Kf, link, bem, ainf, band, *, gate, markov_of, settings, passive):
    """Each coupled DOF group fitted (an identical group reuses an earlier fit): its (gidx, A, B, C),
    the unconstrained fit before passivity enforcement (what passive=False returns) and its report."""
    parts, pre, info = [], [], []
    done = []                      # groups fitted so far: an identical one reuses its fit
    for gidx in groups:
        common = (wf, Kf[:, gidx][:, :, gidx], link[np.ix_(gidx, gidx)], bem, ainf[gidx], band)
        markov_g, judge = markov_of(gidx), None if gate is None else gate.on(gidx)
        reused = same_group_fit(done, common, markov_g, judge, settings["tol"])
        abc, rep, before = reused or _best_scaled_fit(common, {**settings, "M1": markov_g},
                                                      [dofs[i] for i in gidx], passive, judge)
        if reused is None:
            done.append((common, markov_g, abc, rep, before, group_error(abc, common, judge)))
        parts.append((gidx, *abc))
        pre.append((gidx, *before))
        info.append({"dofs": [dofs[i] for i in gidx], **rep})
    return parts, pre, info


def _passivity_summary(parts, pre, info, passive, err, data, gate) -> dict:
    """The report's passivity block: the exact test of the returned model and, where enforcement
    changed it, the unconstrained fit's numbers for comparison. data: (w, K, dofs, groups, ainf,
    inband) as _assemble takes them; gate: the device response's error (or None)."""
    pas = {"enforce": bool(passive), "enforced": any(g.get("passivity", {}).get("enforced") for g in info),
           **passivity_test_groups(parts).as_dict()}
    if pas["enforced"]:
        m0, _, e0 = _assemble(pre, *data)
        if gate is not None:
            e0 = float(np.max(gate.errors(m0.frequency_response(data[0]))))
        t0 = passivity_test_groups(pre).as_dict()
        pas.update(before={"fit_error": e0, "n_states": m0.order, **{k: t0[k] for k in (
            "passive", "margin", "min_eig", "omega_at_min", "max_eig", "bands", "grid_min_eig")}},
            fit_error_growth=err / e0 if e0 > 0 else 1.0,
            enforcement_seconds=sum(g["passivity"]["seconds"] for g in info if "passivity" in g))
    return pas


def _assemble(parts, w, K, dofs, groups, ainf, inband):
    """Block-diagonal model from per-group (gidx, A, B, C), its per-entry and total errors on w
    (in-band per-frequency or global RMS, the larger)."""
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
    e = _group_errors(fit, K, groups, w, ainf, inband)
    return model, np.maximum(e.max(axis=0), entry_error(fit, K)), max(float(e.max()), _nerr(fit, K))


def entry_error(fit, K):
    """Per-entry normalised error sqrt(Σ_ω|fit - K|² / Σ_ω|K|²), 0 where the data entry is 0."""
    den = np.sqrt(np.sum(np.abs(K) ** 2, axis=0))
    return np.where(den > 0, np.sqrt(np.sum(np.abs(fit - K) ** 2, axis=0)) / np.where(den > 0, den, 1), 0.0)
