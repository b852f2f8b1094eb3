"""Layout, validation and cleaning shared by the hydrodynamic data readers.

Every reader builds its result with :func:`build_dataset` (the data-frame layout that
:func:`mbcontrol.hydro.bem.compute` assembles before :func:`~mbcontrol.hydro.to_body_frames`)
and passes it through :func:`clean`, which checks and repairs it the same way for every format.

Scales. Added mass and damping mix units (kg, kg m, kg m²), so every relative measure below is
taken on the scaled matrix S = D^{-1/2} X D^{-1/2}, with D = diag(s_k): s_k is the largest
|X_kk(ω)| over all frequencies and all DOFs of the same kind as k (translations or rotations).
S is dimensionless and its largest diagonal entry over the frequency range is 1.
"""
from __future__ import annotations

import re
import warnings

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError
from mbcontrol.hydro.bem import _UNITS as BODY_FRAME_UNITS
from mbcontrol.hydro.frames import split_dof
from mbcontrol.hydro.geometry import RIGID_DOFS

MAT = ("radiating_dof", "influenced_dof")
WRENCH = ("wave_direction", "omega", "influenced_dof")
MATRIX_LAYOUT = "X[radiating_dof, influenced_dof]; force_i = -sum_j X[j, i] * motion_j"
TIME_CONVENTION = "exp(-i omega t)"
DATA_FRAME = "BEM data frame: z up, x forward, y port, origin on the undisturbed free surface"
# the body-frame units of bem.py, with positions in the data frame (before to_body_frames)
UNITS = {**{k: v for k, v in BODY_FRAME_UNITS.items() if k != "mass"},
         "center_of_buoyancy": "m (data frame, z up)", "cog": "m (data frame, z up)",
         "reference_point": "m (data frame, z up)"}
# Defaults of clean(); documented there.
ASYM_TOL = 1e-3
DIAG_TOL = 1e-6
EIG_TOL = 1e-3
MAX_INTERP_RUN = 3
END_ZERO_TOL = 1e-2


class HydroCleaningWarning(UserWarning):
    """A reader changed data values (negative damping repaired, large asymmetry forced away)."""


# ----------------------------------------------------------------------------- names
def sanitize_name(name: str, fallback: str) -> str:
    """A body name usable in DOF and signal names: letters, digits and single underscores."""
    s = re.sub(r"[^0-9A-Za-z_]+", "_", str(name).strip())
    s = re.sub(r"_{2,}", "_", s).strip("_")
    return s or fallback


def body_name_list(found: list[str], n: int, body_names, path) -> tuple[list[str], list[str]]:
    """Final body names (``body_names`` if given, else ``found``), sanitised and distinct, plus notes."""
    notes = []
    if body_names is not None:
        names = [str(b) for b in body_names]
        if len(names) != n:
            raise HydroError(f"{path}: body_names has {len(names)} name(s) {names}; the file holds {n} "
                             "bod(y/ies): expected one name per body, in file order")
    else:
        names = list(found) if len(found) == n else [f"body{k + 1}" for k in range(n)]
        if len(found) != n:
            notes.append(f"body names not found for all {n} bodies in the file; named body1..body{n}")
    out = []
    for k, b in enumerate(names):
        s = sanitize_name(b, f"body{k + 1}")
        while s in out:
            s = f"{s}_{k + 1}"
        if s != b:
            notes.append(f"body name {b!r} sanitised to {s!r} (no dots, no '__')")
        out.append(s)
    return out, notes


def dof_names(bodies: list[str]) -> list[str]:
    return [f"{b}__{d}" for b in bodies for d in RIGID_DOFS]


# ----------------------------------------------------------------------------- layout
def build_dataset(*, bodies, dofs, omega, A, B, K, exc, headings, A0=None, Ainf=None, fk=None, diff=None,
                  volume, cob, ref, cog=None, awp=None, rho, g, depth, source, notes=()) -> xr.Dataset:
    """The data-frame dataset of the readers from arrays in force-first layout.

    Matrices are given as X[..., i_force, j_motion] (A, B: (nω, n, n); K, A0, Ainf: (n, n));
    wrenches as F[heading, ω, i] (complex, e^{-iωt}, per m of wave amplitude); points (nb, 3)
    in the data frame (z up). A0/Ainf None -> NaN. Values must already be dimensional SI.
    """
    n = len(dofs)
    nan = np.full((n, n), np.nan)
    f2m = lambda x: np.swapaxes(np.asarray(x, dtype=float), -1, -2)  # noqa: E731  force-first -> (rad, inf)
    data = {
        "added_mass": (("omega",) + MAT, f2m(A)),
        "radiation_damping": (("omega",) + MAT, f2m(B)),
        "added_mass_zero": (MAT, f2m(nan if A0 is None else A0)),
        "added_mass_inf": (MAT, f2m(nan if Ainf is None else Ainf)),
        "hydrostatic_stiffness": (MAT, f2m(K)),
        "excitation_force": (WRENCH, np.asarray(exc, dtype=complex)),
        "displaced_volume": (("body",), np.asarray(volume, dtype=float)),
        "center_of_buoyancy": (("body", "xyz"), np.asarray(cob, dtype=float)),
        "reference_point": (("body", "xyz"), np.asarray(ref, dtype=float)),
    }
    if fk is not None:
        data["froude_krylov_force"] = (WRENCH, np.asarray(fk, dtype=complex))
    if diff is not None:
        data["diffraction_force"] = (WRENCH, np.asarray(diff, dtype=complex))
    if cog is not None:
        data["cog"] = (("body", "xyz"), np.asarray(cog, dtype=float))
    if awp is not None:
        data["waterplane_area"] = (("body",), np.asarray(awp, dtype=float))
    ds = xr.Dataset(data, coords={"omega": np.asarray(omega, dtype=float), "radiating_dof": list(dofs),
                                  "influenced_dof": list(dofs), "wave_direction": np.asarray(headings, float),
                                  "body": list(bodies), "xyz": ["x", "y", "z"]})
    notes = list(notes)
    for name, arr in (("added_mass_zero", A0), ("added_mass_inf", Ainf)):
        if arr is None:
            ds[name].attrs["note"] = "NaN: not in the file"
            notes.append(f"{name}: not in the file, stored as NaN")
    return finish_attrs(ds, rho=rho, g=g, depth=depth, source=source, notes=notes)


def finish_attrs(ds, *, rho, g, depth, source, notes) -> xr.Dataset:
    for v, u in UNITS.items():
        if v in ds:
            ds[v].attrs["units"] = u
    ds["reference_point"].attrs["long_name"] = "point the body's matrices and wrenches refer to"
    ds["omega"].attrs.update(units="rad/s", long_name="wave angular frequency")
    ds["wave_direction"].attrs.update(units="rad", long_name="data-frame heading waves travel to, +x towards +y")
    ds.attrs.update({
        "rho": float(rho), "g": float(g), "depth": float(depth), "source": str(source),
        "time_convention": TIME_CONVENTION, "frame": DATA_FRAME, "matrix_layout": MATRIX_LAYOUT,
        "excitation_reference": "unit wave amplitude, elevation positive up, at the data-frame origin",
        "notes": list(notes),
    })
    return ds


# ----------------------------------------------------------------------------- helpers
def _fmt_w(w: float) -> str:
    if w == 0:
        return "ω = 0"
    if not np.isfinite(w):
        return f"ω = {w}"
    return f"ω = {w:.6g} rad/s (T = {2 * np.pi / w:.6g} s)"


def _kind_scales(dofs, diag_abs_max) -> np.ndarray:
    """Per-DOF scale s_k: the largest |X_kk| among DOFs of the same kind (translation / rotation)."""
    rot = np.array([split_dof(d)[1] in ("Roll", "Pitch", "Yaw") for d in dofs])
    d = np.asarray(diag_abs_max, dtype=float)
    s = np.zeros(len(dofs))
    for mask in (rot, ~rot):
        if mask.any():
            s[mask] = np.nanmax(d[mask]) if np.any(np.isfinite(d[mask])) else 0.0
    pos = s[s > 0]
    return np.where(s > 0, s, pos.max() if pos.size else 1.0)


def _force_first(da: xr.DataArray) -> np.ndarray:
    return da.transpose(..., "influenced_dof", "radiating_dof").values


def _set_force_first(ds, name, x):
    da = ds[name]
    new = da.transpose(..., "influenced_dof", "radiating_dof").copy(data=x).transpose(*da.dims)
    new.attrs = dict(da.attrs)
    ds[name] = new


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
                raise HydroError(f"{src}: duplicate frequency {_fmt_w(value)} ({hit.size} times)")
            a = ds["added_mass"].isel(omega=int(hit[0]))
            if target not in ds or not np.any(np.isfinite(ds[target].values)):
                ds[target] = a.drop_vars("omega").transpose(*MAT)
                notes.append(f"{target}: taken from the {_fmt_w(value)} entry of the frequency list")
            ds = ds.isel(omega=np.where(w != value)[0])
            w = np.asarray(ds["omega"].values, dtype=float)
    bad = ~np.isfinite(w) | (w <= 0)
    if bad.any():
        raise HydroError(f"{src}: frequency {w[bad][0]!r} rad/s is not finite and > 0; expected ω > 0 (rad/s)")
    if w.size == 0:
        raise HydroError(f"{src}: missing frequencies: no finite ω > 0 in the file")
    uniq, counts = np.unique(w, return_counts=True)
    if np.any(counts > 1):
        raise HydroError(f"{src}: duplicate frequency {_fmt_w(float(uniq[counts > 1][0]))} "
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
            at = f" at {_fmt_w(w)}" if w is not None else ""
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


def _symmetry(ds, src, record, notes, *, tol, force):
    """Symmetrise A-family and B; error (or forced symmetrisation) above ``tol``."""
    dofs = [str(d) for d in ds["radiating_dof"].values]
    families = {"added_mass": ("added_mass", "added_mass_zero", "added_mass_inf"),
                "radiation_damping": ("radiation_damping",)}
    for fam, names in families.items():
        mats = {v: _force_first(ds[v]) for v in names if v in ds and np.all(np.isfinite(ds[v].values))}
        diag = np.max([np.abs(np.diagonal(x, axis1=-2, axis2=-1)).reshape(-1, len(dofs)).max(0)
                       for x in mats.values()], axis=0)
        s = np.sqrt(_kind_scales(dofs, diag))
        for v, x in mats.items():
            S = x / np.outer(s, s)
            diff = np.abs(S - np.swapaxes(S, -1, -2))
            worst = float(diff.max()) if diff.size else 0.0
            if worst == 0.0:
                continue
            flat = np.unravel_index(int(np.argmax(diff)), diff.shape)
            i, j = flat[-2], flat[-1]
            w = float(ds["omega"].values[flat[0]]) if x.ndim == 3 else None
            where = (f"{dofs[i]} / {dofs[j]}" + (f" at {_fmt_w(w)}" if w is not None else ""))
            vals = (x[flat], x[flat[:-2] + (j, i)])
            info = {"max_relative_asymmetry": worst, "where": where, "values": [float(vals[0]), float(vals[1])]}
            if worst > tol:
                msg = (f"{src}: {v} is not symmetric: relative asymmetry {worst:.3g} > {tol:g} at {where} "
                       f"(X[force {dofs[i]}, motion {dofs[j]}] = {vals[0]:.6g}, transposed entry {vals[1]:.6g}); "
                       "expected reciprocity (X = Xᵀ)")
                if not force:
                    raise HydroError(msg + " — pass force_symmetric=True to symmetrise it anyway")
                warnings.warn(msg + "; symmetrised because force_symmetric=True", HydroCleaningWarning, stacklevel=4)
                info["forced"] = True
            _set_force_first(ds, v, 0.5 * (x + np.swapaxes(x, -1, -2)))
            record.setdefault("symmetrised", {})[v] = info
        done = [record["symmetrised"][v]["max_relative_asymmetry"] for v in names
                if v in record.get("symmetrised", {})]
        if done:
            notes.append(f"{fam} family symmetrised (X + Xᵀ)/2; largest relative asymmetry {max(done):.3g} "
                         "(scaled by the largest diagonal of the same DOF kind)")


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


def _negative_damping(ds, src, record, notes, *, diag_tol, eig_tol, max_run, end_zero_tol, mode):
    dofs = [str(d) for d in ds["radiating_dof"].values]
    w = np.asarray(ds["omega"].values, dtype=float)
    B = _force_first(ds["radiation_damping"]).copy()
    s = np.sqrt(_kind_scales(dofs, np.abs(np.diagonal(B, axis1=1, axis2=2)).max(0)))
    scale = np.outer(s, s)
    flags = _flag_damping(B / scale, diag_tol, eig_tol)
    bad = np.array([f[0] for f in flags])
    if not bad.any():
        return ds
    if mode == "error":
        k = int(np.argmax(bad))
        raise HydroError(f"{src}: negative radiation damping at {int(bad.sum())} frequencies, first {_fmt_w(w[k])} "
                         f"(DOFs {[dofs[i] for i in sorted(flags[k][1])]}, min scaled eigenvalue "
                         f"{flags[k][2]:.3g}); expected B(ω) positive semi-definite")
    n = len(w)
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
    changes = []
    for k0, k1 in runs:
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
                    f"{src}: negative radiation damping {where}: {_fmt_w(w[k0])} to {_fmt_w(w[k1])}, DOFs "
                    f"{[dofs[j] for j in off]}, min scaled eigenvalue {before:.3g}; expected B(ω) positive "
                    f"semi-definite. It {why} — pass negative_damping='project' to use the nearest positive "
                    "semi-definite matrix there, or fix the BEM run")
            for i in idx:
                B[i] = _nearest_psd(B[i], scale)
            off = list(range(len(dofs)))
            method = ("nearest positive semi-definite matrix (negative eigenvalues of the scaled B set to 0)"
                      if method is None else method + ", then nearest positive semi-definite matrix")
        changes.append({"omega": [float(w[i]) for i in idx], "dofs": [dofs[j] for j in off],
                        "method": method, "min_scaled_eigenvalue_before": before})
    _set_force_first(ds, "radiation_damping", B)
    record["negative_damping"] = changes
    nw = sum(len(c["omega"]) for c in changes)
    runs_txt = [f"{c['omega'][0]:.4g}" + (f"..{c['omega'][-1]:.4g}" if len(c["omega"]) > 1 else "") for c in changes]
    touched = sorted({d for c in changes for d in c["dofs"]}, key=dofs.index)
    kinds = {}
    for c in changes:
        key = c["method"].split(" (")[0].split(":")[0]
        kinds[key] = kinds.get(key, 0) + len(c["omega"])
    text = (f"negative radiation damping repaired at {nw} frequencies (ω = {', '.join(runs_txt)} rad/s; DOFs "
            f"{touched}; " + "; ".join(f"{k}: {v}" for k, v in kinds.items())
            + "); details in attrs['cleaning']['negative_damping']")
    notes.append(text)
    warnings.warn(f"{src}: {text}", HydroCleaningWarning, stacklevel=4)
    return ds


# ----------------------------------------------------------------------------- public
def clean(ds: xr.Dataset, *, source: str, asym_tol: float = ASYM_TOL, force_symmetric: bool = False,
          negative_damping: str = "repair", diag_tol: float = DIAG_TOL, eig_tol: float = EIG_TOL,
          max_interp_run: int = MAX_INTERP_RUN, end_zero_tol: float = END_ZERO_TOL, dofs=None,
          omega_range=None) -> xr.Dataset:
    """Check a data-frame dataset and repair what can be repaired, recording every change.

    Steps (each error is a HydroError naming ``source`` and the problem):

    1. Structure: the layout's variables and dimensions; DOF names ``<body>__<Dof>`` with a rigid
       Dof; the same DOFs radiating and influenced ("wrong DOF count" otherwise); every body listed.
       ``dofs`` (optional) keeps only those DOFs (bodies left without DOFs are dropped).
    2. Frequencies: ω = 0 / ∞ entries move to ``added_mass_zero`` / ``added_mass_inf``; the rest must
       be finite, > 0 and distinct (duplicates: error); unsorted ω (or headings) are sorted, with a note.
       ``omega_range = (lo, hi)`` (rad/s, optional) drops the frequencies outside it, e.g. those the
       BEM mesh cannot resolve, before the checks below.
    3. NaN/∞ in A, B, excitation, Froude-Krylov, diffraction, stiffness, volumes or points: error
       naming the variable and the first bad frequency. A(0)/A(∞) may be all NaN (absent).
    4. Symmetry of A(ω), A(0), A(∞), B(ω): relative asymmetry max|S - Sᵀ| of the scaled matrix
       (module docs). Up to ``asym_tol`` the matrix is replaced by (X + Xᵀ)/2 and the largest
       asymmetry is recorded; above it, error — unless ``force_symmetric`` (then warn and record).
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

    Returns a new dataset; ``attrs["notes"]`` lists every conversion and repair.
    """
    src = str(source)
    if negative_damping not in ("repair", "project", "error"):
        raise HydroError(f"{src}: negative_damping = {negative_damping!r}; expected 'repair', 'project' or 'error'")
    ds = ds.copy(deep=True)
    notes = list(ds.attrs.get("notes", []))
    record = dict(ds.attrs.get("cleaning", {}))
    ds = _check_structure(ds, src)
    if dofs is not None:
        ds = _select_dofs(ds, src, list(dofs), notes)
    ds = _check_omega(ds, src, notes)
    if omega_range is not None:
        ds = _crop(ds, src, omega_range, notes)
    ds = _check_finite(ds, src, notes)
    _symmetry(ds, src, record, notes, tol=float(asym_tol), force=bool(force_symmetric))
    ds = _negative_damping(ds, src, record, notes, diag_tol=float(diag_tol), eig_tol=float(eig_tol),
                           max_run=int(max_interp_run), end_zero_tol=float(end_zero_tol), mode=negative_damping)
    ds.attrs["notes"] = notes
    ds.attrs["cleaning"] = record
    ds.attrs.setdefault("source", src)
    return ds
