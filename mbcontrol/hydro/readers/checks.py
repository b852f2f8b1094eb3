"""Validation and cleaning shared by the hydrodynamic data readers.

Every reader builds its result with :func:`~mbcontrol.hydro.readers.layout.build_dataset` (the
data-frame layout that :func:`mbcontrol.hydro.bem.solve.compute` assembles before
:func:`~mbcontrol.hydro.to_body_frames`) and passes it through :func:`clean`, which checks and
repairs it the same way for every format.

Scales. Added mass and damping mix units (kg, kg m, kg m²), so every relative measure below is
taken on the scaled matrix S = D^{-1/2} X D^{-1/2}, with D = diag(s_k): s_k is the largest
|X_kk(ω)| over all frequencies and all DOFs of the same kind as k (translations or rotations).
S is dimensionless and its largest diagonal entry over the frequency range is 1.
"""
from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from ... import defaults
from ...errors import HydroError
from ..data.frames import split_dof
from .damping import repair_negative_damping
from .layout import MAT, HydroCleaningWarning, fmt_omega, force_first, kind_scales, set_force_first
from .physical import check_physical

# Defaults of clean(); documented there.
ASYM_TOL = 1e-3
# Reciprocity (A = Aᵀ, B = Bᵀ) holds for the exact potential flow; a panel solution meets it only to its
# discretisation error, which for a converged low-order run is of order 1 % of an entry (WAMIT's own
# convergence guidance; its output carries 5-6 digits). An asymmetry up to BEM_ASYM_TOL (scaled, module
# docs) is therefore that error, not a wrong file: symmetrised with a warning. Larger ones, where the fit
# looks, are refused (rm3.out's float/spar roll pair: 2 % in A, 24 % in B).
# BEM_ASYM_TOL: the default "hydro.bem_asymmetry_tol" (mbcontrol.defaults)
DIAG_TOL = 1e-6
EIG_TOL = 1e-3
MAX_INTERP_RUN = 3
END_ZERO_TOL = 1e-2


# ----------------------------------------------------------------------------- checks
def _check_structure(ds, src):
    need = ("added_mass", "radiation_damping", "hydrostatic_stiffness", "excitation_force", "reference_point")
    missing = [v for v in need if v not in ds]
    if missing:
        raise HydroError(f"{src}: missing variable(s) {missing}; expected the data-frame layout of mbcontrol.hydro")
    for d in MAT + ("omega", "wave_direction", "body"):
        if d not in ds.dims:
            raise HydroError(f"{src}: no '{d}' dimension; expected the data-frame layout of mbcontrol.hydro")
    rad = [str(d) for d in ds["radiating_dof"].values]
    inf = [str(d) for d in ds["influenced_dof"].values]
    if len(rad) != len(inf) or set(rad) != set(inf):
        raise HydroError(f"{src}: wrong DOF count: {len(rad)} radiating DOFs {rad} but {len(inf)} influenced "
                         f"DOFs {inf}; expected the same DOFs in both (square matrices)")
    if len(set(rad)) != len(rad):
        dup = sorted({d for d in rad if rad.count(d) > 1})
        raise HydroError(f"{src}: DOF(s) {dup} appear more than once; expected each DOF once")
    bodies = [str(b) for b in ds["body"].values]
    per_body: dict[str, list[str]] = {}
    for d in rad:
        try:
            b, dof = split_dof(d)
        except HydroError as exc:
            raise HydroError(f"{src}: {exc}") from None
        if "." in b or "__" in b:
            raise HydroError(f"{src}: body name {b!r} in DOF {d!r}; expected no '.' or '__'")
        per_body.setdefault(b, []).append(dof)
    unknown = sorted(set(per_body) - set(bodies))
    if unknown:
        raise HydroError(f"{src}: DOFs of bod(y/ies) {unknown} not listed in the 'body' coordinate {bodies}")
    empty = [b for b in bodies if b not in per_body]
    if empty:
        raise HydroError(f"{src}: wrong DOF count: body/bodies {empty} have no DOF; expected 1 to 6 rigid DOFs each")
    if inf != rad:  # same set, other order: align influenced with radiating
        ds = ds.sel(influenced_dof=rad)
    return ds


def _check_omega(ds, src, notes):
    w = np.asarray(ds["omega"].values, dtype=float)
    if w.ndim != 1 or w.size == 0:
        raise HydroError(f"{src}: missing frequencies: the omega coordinate is empty; expected at least one ω > 0")
    specials = {0.0: "added_mass_zero", np.inf: "added_mass_inf"}
    for value, target in specials.items():
        hit = np.where(w == value)[0]
        if hit.size:
            if hit.size > 1:
                raise HydroError(f"{src}: duplicate frequency {fmt_omega(value)} ({hit.size} times)")
            a = ds["added_mass"].isel(omega=int(hit[0]))
            if target not in ds or not np.any(np.isfinite(ds[target].values)):
                ds[target] = a.drop_vars("omega").transpose(*MAT)
                notes.append(f"{target}: taken from the {fmt_omega(value)} entry of the frequency list")
            ds = ds.isel(omega=np.where(w != value)[0])
            w = np.asarray(ds["omega"].values, dtype=float)
    bad = ~np.isfinite(w) | (w <= 0)
    if bad.any():
        raise HydroError(f"{src}: frequency {w[bad][0]!r} rad/s is not finite and > 0; expected ω > 0 (rad/s)")
    if w.size == 0:
        raise HydroError(f"{src}: missing frequencies: no finite ω > 0 in the file")
    uniq, counts = np.unique(w, return_counts=True)
    if np.any(counts > 1):
        raise HydroError(f"{src}: duplicate frequency {fmt_omega(float(uniq[counts > 1][0]))} "
                         f"({int(counts[counts > 1][0])} times); expected each frequency once")
    if np.any(np.diff(w) < 0):
        ds = ds.sortby("omega")
        notes.append(f"frequencies were not in ascending order in the file; sorted ({w.size} values)")
    h = np.asarray(ds["wave_direction"].values, dtype=float)
    if h.size == 0 or not np.all(np.isfinite(h)):
        raise HydroError(f"{src}: wave directions {h.tolist()}; expected at least one finite heading (rad)")
    if np.unique(h).size != h.size:
        raise HydroError(f"{src}: duplicate wave direction in {np.degrees(h).round(6).tolist()} deg")
    if np.any(np.diff(h) < 0):
        ds = ds.sortby("wave_direction")
        notes.append("wave directions were not in ascending order; sorted")
    return ds


def _select_dofs(ds, src, dofs, notes):
    have = [str(d) for d in ds["radiating_dof"].values]
    unknown = [d for d in dofs if d not in have]
    if unknown or not dofs:
        raise HydroError(f"{src}: dofs {unknown or dofs} not in the data; expected a non-empty subset of {have}")
    keep = [d for d in have if d in dofs]
    bodies = [str(b) for b in ds["body"].values]
    used = [b for b in bodies if any(split_dof(d)[0] == b for d in keep)]
    ds = ds.sel(radiating_dof=keep, influenced_dof=keep, body=used)
    notes.append(f"DOFs restricted to {keep}")
    return ds


def _crop(ds, src, omega_range, notes):
    try:
        lo, hi = (float(x) for x in omega_range)
    except (TypeError, ValueError):
        raise HydroError(f"{src}: omega_range = {omega_range!r}; expected (lo, hi) in rad/s") from None
    w = ds["omega"].values
    keep = (w >= lo) & (w <= hi)
    if not keep.any():
        raise HydroError(f"{src}: no frequency in omega_range = ({lo}, {hi}) rad/s; the data span "
                         f"{w.min():.6g}..{w.max():.6g} rad/s")
    if not keep.all():
        notes.append(f"frequencies outside omega_range = ({lo:g}, {hi:g}) rad/s dropped: {int((~keep).sum())} of "
                     f"{w.size} (kept {w[keep].min():.6g}..{w[keep].max():.6g} rad/s)")
    return ds.isel(omega=np.where(keep)[0])


def _first_bad(da: xr.DataArray):
    """(omega, dof text) of the first non-finite entry of ``da`` (lowest frequency first)."""
    x = da.values
    bad = ~np.isfinite(x)
    if "omega" in da.dims:
        ax = da.dims.index("omega")
        per_w = np.any(np.moveaxis(bad, ax, 0).reshape(bad.shape[ax], -1), axis=1)
        k = int(np.argmax(per_w))
        sub = da.isel(omega=k)
        w = float(da["omega"].values[k])
    else:
        sub, w = da, None
    idx = np.argwhere(~np.isfinite(sub.values))[0]
    where = ", ".join(f"{d}={sub[d].values[i]!s}" if d in sub.coords else f"{d}[{i}]"
                      for d, i in zip(sub.dims, idx))
    return w, where


def _check_finite(ds, src, notes):
    for name in ("added_mass", "radiation_damping", "excitation_force", "froude_krylov_force",
                 "diffraction_force", "hydrostatic_stiffness", "displaced_volume", "center_of_buoyancy",
                 "reference_point"):
        if name not in ds:
            continue
        if not np.all(np.isfinite(ds[name].values)):
            w, where = _first_bad(ds[name])
            at = f" at {fmt_omega(w)}" if w is not None else ""
            raise HydroError(f"{src}: {name} has NaN or infinite values{at} ({where}); "
                             f"expected finite numbers — missing or corrupt data in the file")
    for name in ("added_mass_zero", "added_mass_inf"):
        if name not in ds:
            ds[name] = xr.DataArray(np.full((ds.sizes["radiating_dof"],) * 2, np.nan), dims=MAT)
            ds[name].attrs["note"] = "NaN: not in the file"
            notes.append(f"{name}: not in the file, stored as NaN")
            continue
        x = ds[name].values
        if np.any(np.isfinite(x)) and not np.all(np.isfinite(x)):
            _, where = _first_bad(ds[name])
            raise HydroError(f"{src}: {name} is partly NaN ({where}); expected a complete matrix or none")
    return ds


def _symmetry(ds, src, record, notes, *, tol, force, band_max=None):
    """Symmetrise A-family and B: silently (with a note) up to ``tol``; with a warning above it
    when the asymmetry at or below ``band_max`` (rad/s: the radiation fit's band, the scene's
    fit_omega_max; None: every frequency) is at most BEM_ASYM_TOL, or with ``force``; else error."""
    dofs = [str(d) for d in ds["radiating_dof"].values]
    families = {"added_mass": ("added_mass", "added_mass_zero", "added_mass_inf"),
                "radiation_damping": ("radiation_damping",)}
    for fam, names in families.items():
        mats = {v: force_first(ds[v]) for v in names if v in ds and np.all(np.isfinite(ds[v].values))}
        diag = np.max([np.abs(np.diagonal(x, axis1=-2, axis2=-1)).reshape(-1, len(dofs)).max(0)
                       for x in mats.values()], axis=0)
        s = np.sqrt(kind_scales(dofs, diag))
        for v, x in mats.items():
            S = x / np.outer(s, s)
            diff = np.abs(S - np.swapaxes(S, -1, -2))
            worst = float(diff.max()) if diff.size else 0.0
            if worst == 0.0:
                continue
            flat = np.unravel_index(int(np.argmax(diff)), diff.shape)
            i, j = flat[-2], flat[-1]
            w = float(ds["omega"].values[flat[0]]) if x.ndim == 3 else None
            where = (f"{dofs[i]} / {dofs[j]}" + (f" at {fmt_omega(w)}" if w is not None else ""))
            vals = (x[flat], x[flat[:-2] + (j, i)])
            info = {"max_relative_asymmetry": worst, "where": where, "values": [float(vals[0]), float(vals[1])]}
            if worst > tol:
                msg = (f"{src}: {v} is not symmetric: relative asymmetry {worst:.3g} > {tol:g} at {where} "
                       f"(X[force {dofs[i]}, motion {dofs[j]}] = {vals[0]:.6g}, transposed entry {vals[1]:.6g}); "
                       "expected reciprocity (X = Xᵀ)")
                in_band = (float(diff[ds["omega"].values <= band_max].max(initial=0.0))
                           if band_max is not None and x.ndim == 3 else worst)
                outside = in_band <= tol
                if not (force or outside or in_band <= defaults.get("hydro.bem_asymmetry_tol")):
                    raise HydroError(msg + f" — set [hydro] source_options = {{ force_symmetric = true }} "
                                     f"in the scene to symmetrise it (Python: force_symmetric=True), or "
                                     f"[hydro] fit_omega_max below {w:.3g} rad/s if the device's seas lie "
                                     f"below it" if w is not None else msg + " — set [hydro] "
                                     "source_options = { force_symmetric = true } in the scene to "
                                     "symmetrise it (Python: force_symmetric=True)")
                why = ("force_symmetric = true" if force else
                       f"it lies above the radiation fit's band ([hydro] fit_omega_max = {band_max:g} "
                       f"rad/s; set [hydro] source_options = {{ force_symmetric = true }} to say so)"
                       if outside else
                       f"{worst:.2g} is within the BEM's discretisation error ({defaults.get('hydro.bem_asymmetry_tol'):g}: a "
                       f"panel solution is reciprocal only to its accuracy); set [hydro] source_options "
                       f"= {{ asym_tol = {float(f'{worst * 1.05:.2g}'):g} }} to accept it without this warning")
                warnings.warn(msg + f"; symmetrised because {why}", HydroCleaningWarning, stacklevel=4)
                info["forced"] = True
            set_force_first(ds, v, 0.5 * (x + np.swapaxes(x, -1, -2)))
            record.setdefault("symmetrised", {})[v] = info
        done = [record["symmetrised"][v]["max_relative_asymmetry"] for v in names
                if v in record.get("symmetrised", {})]
        if done:
            notes.append(f"{fam} family symmetrised (X + Xᵀ)/2; largest relative asymmetry {max(done):.3g} "
                         "(scaled by the largest diagonal of the same DOF kind)")


# ----------------------------------------------------------------------------- public
def clean(ds: xr.Dataset, *, source: str, asym_tol: float = ASYM_TOL, force_symmetric: bool = False,
          negative_damping: str = "repair", diag_tol: float = DIAG_TOL, eig_tol: float = EIG_TOL,
          max_interp_run: int = MAX_INTERP_RUN, end_zero_tol: float = END_ZERO_TOL, dofs=None,
          omega_range=None, band_max: float | None = None) -> xr.Dataset:
    """Check a data-frame dataset and repair what can be repaired, recording every change.

    Steps (each error is a HydroError naming ``source`` and the problem):

    1. Structure: the layout's variables and dimensions; DOF names ``<body>__<Dof>`` with a rigid
       Dof; the same DOFs radiating and influenced ("wrong DOF count" otherwise); every body listed.
       ``dofs`` (optional) keeps only those DOFs (bodies left without DOFs are dropped); a callable
       is given the structured dataset and returns them.
    2. Frequencies: ω = 0 / ∞ entries move to ``added_mass_zero`` / ``added_mass_inf``; the rest must
       be finite, > 0 and distinct (duplicates: error); unsorted ω (or headings) are sorted, with a note.
       ``omega_range = (lo, hi)`` (rad/s, optional) drops the frequencies outside it, e.g. those the
       BEM mesh cannot resolve, before the checks below.
    3. NaN/∞ in A, B, excitation, Froude-Krylov, diffraction, stiffness, volumes or points: error
       naming the variable and the first bad frequency. A(0)/A(∞) may be all NaN (absent).
    4. Symmetry of A(ω), A(0), A(∞), B(ω): relative asymmetry max|S - Sᵀ| of the scaled matrix
       (module docs). Up to ``asym_tol`` the matrix is replaced by (X + Xᵀ)/2 and the largest
       asymmetry is recorded; above it, error — unless ``force_symmetric``, or every such
       asymmetry lies above ``band_max`` (rad/s, the scene's fit_omega_max: where the radiation
       fit does not look), or the asymmetry at or below ``band_max`` (None: anywhere) is at most
       BEM_ASYM_TOL (1 %: the panel solution's own error); then warn and record.
       The hydrostatic stiffness is left as stored (WAMIT's C46, C56 are legitimately one-sided).
    5. Negative damping (e.g. irregular frequencies): a frequency is flagged when a scaled diagonal
       B_kk < -``diag_tol`` or the smallest eigenvalue of the scaled symmetric B < -``eig_tol``
       ("clearly negative"). Offending DOFs: negative diagonals and DOFs carrying ≥ 10 % of a
       negative eigenvector. Each run of consecutive flagged frequencies is repaired by
       ``negative_damping="repair"``: inside the range and at most ``max_interp_run`` long ->
       rows/columns of the offending DOFs linearly interpolated from the two neighbouring
       frequencies; touching an end of the range where |S_kk| ≤ ``end_zero_tol`` -> those
       rows/columns set to 0 (the B -> 0 limit); otherwise error. ``"project"`` also accepts the
       rest by taking the nearest positive semi-definite matrix; ``"error"`` repairs nothing.
       Every repair warns (HydroCleaningWarning) and is listed in ``attrs["cleaning"]``.
    6. Physics, after the repairs (module physical): positive added-mass diagonals (A(∞) always,
       A(ω) at both ends of the range; a dip between them is a resonance, noted), passive
       damping, C33 = ρ g Awp ≥ 0, V ≥ 0, buoyancy centre not above the surface. What cannot be
       true is an error, never repaired; what was measured is ``attrs["cleaning"]["physical"]``.

    Returns a new dataset; ``attrs["notes"]`` lists every conversion and repair.
    """
    src = str(source)
    if negative_damping not in ("repair", "project", "error"):
        raise HydroError(f"{src}: negative_damping = {negative_damping!r}; expected 'repair', 'project' or 'error'")
    ds = ds.copy(deep=True)
    notes = list(ds.attrs.get("notes", []))
    record = dict(ds.attrs.get("cleaning", {}))
    ds = _check_structure(ds, src)
    if callable(dofs):   # a choice that depends on the file's bodies (module hydro.source)
        dofs = dofs(ds)
    if dofs is not None:
        ds = _select_dofs(ds, src, list(dofs), notes)
    ds = _check_omega(ds, src, notes)
    if omega_range is not None:
        ds = _crop(ds, src, omega_range, notes)
    ds = _check_finite(ds, src, notes)
    _symmetry(ds, src, record, notes, tol=float(asym_tol), force=bool(force_symmetric),
              band_max=band_max)
    ds = repair_negative_damping(ds, src, record, notes, diag_tol=float(diag_tol), eig_tol=float(eig_tol),
                                 max_run=int(max_interp_run), end_zero_tol=float(end_zero_tol), mode=negative_damping)
    ds.attrs.setdefault("source", src)   # rho, g, frame: set by the reader's layout
    record["physical"] = check_physical(ds, src)
    for band in record["physical"]["resonance_bands"]:
        notes.append(f"{band['entry']} < 0 over {band['omega'][0]:.4g}..{band['omega'][1]:.4g} rad/s (down to "
                     f"{band['min_scaled']:.3g} of its scale) and > 0 on both sides: accepted as a resonance "
                     "(gap, moonpool, submerged body); check that the body has one there")
    ds.attrs["notes"] = notes
    ds.attrs["cleaning"] = record
    ds.attrs.setdefault("source", src)
    return ds
