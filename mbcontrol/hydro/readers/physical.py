"""Physical checks of BEM data, whatever made them: a reader (through :func:`clean`, after its
repairs), mbcontrol's own precomputed or cached NetCDF files and its Capytaine runs
(mbcontrol.hydro.model). Repairs belong to :func:`clean`; these checks only refuse what cannot
be true, with a HydroError naming the file, the entry, the frequency and the remedy.

What is checked, on the scaled matrices of module checks (S = D^{-1/2} X D^{-1/2}, D the largest
diagonal of the same DOF kind, so the tolerances are dimensionless):

- every value finite (A, B, A(0), A(∞) when present, stiffness, excitation, volumes);
- added mass: A_kk(∞) ≥ -``tol`` (A(∞) is the kinetic energy of the fluid with φ = 0 on the
  free surface: positive definite); A_kk(ω) ≥ -``tol`` at the lowest and the highest frequency.
  Between them a run of negative A_kk(ω) is accepted and reported as a resonance band: a
  narrow gap between bodies, a moonpool or a body submerged near the surface make A_kk(ω)
  dip below zero around their resonance (McIver & Evans 1984), as the catalogue's hinged
  barges do in surge (10.7-15 rad/s, down to -0.50 of the surge scale). A negated column, a
  sign error of a converter, is negative from the first frequency on: an error;
- damping: the smallest eigenvalue of the symmetric part of the scaled B(ω) ≥ -``eig_tol`` at
  every frequency up to the mesh's resolution limit (attrs ``omega_max_mesh`` when the data
  carry it; above it the data are known to be unresolved and no fit uses them): passivity, the
  radiated power ½ νᴴ B ν is never negative;
- hydrostatics: C33 = ρ g Awp ≥ 0 for every body with a heave DOF, and C33 against ρ g Awp to
  ``awp_tol`` (relative) when the data give the waterplane area apart from C33 (Capytaine's
  mesh hydrostatics; WAMIT's and BEMIO's Awp are C33/(ρ g) by construction); displaced
  volume ≥ 0; a centre of buoyancy of a displacing body not above the free surface.

Measured on the shipped data (scaled units): A_kk(ω) ≥ 0.024 everywhere except the resonance
bands of hinged_barge (surge, -0.50), raft3 (surge, -0.26) and flap_pair (pitch at 9 rad/s,
-0.047); A_kk(∞) ≥ 0.066; smallest damping eigenvalue below the mesh limit -0.0119 (raft3,
17.0 rad/s; next -0.0061 at 9.6 rad/s), every other file ≥ -8.2e-4 (flap14), the readers'
output after their repairs ≥ -7.4e-7 (sphere.out); C33 = ρ g Awp to 2e-16.
"""
from __future__ import annotations

import numpy as np

from ...errors import HydroError
from ..data.frames import split_dof
from .layout import fmt_omega, force_first, kind_scales

ADDED_MASS_TOL = 1e-3   # scaled: numerical noise of a zero added mass (sphere.out's yaw: 1e-10)
DAMPING_EIG_TOL = 2e-2  # scaled: above raft3's -0.0119 (gap modes, 17 rad/s); a negated B_kk gives -1
AWP_TOL = 1e-3          # relative: C33 and ρ g Awp come from the same mesh (measured equal to 2e-16)
COB_TOL = 1e-3          # relative to V^(1/3): a centre of buoyancy above the surface is impossible


def check_physical(ds, src: str, *, tol: float = ADDED_MASS_TOL, eig_tol: float = DAMPING_EIG_TOL,
                   awp_tol: float = AWP_TOL) -> dict:
    """Refuse data that cannot be true (module docs); return what was measured: the smallest
    scaled A_kk(ω) and A_kk(∞), the smallest scaled damping eigenvalue (and where), the largest
    relative C33 - ρ g Awp mismatch, and the accepted negative-added-mass resonance bands."""
    dofs = [str(d) for d in ds["radiating_dof"].values]
    w = np.asarray(ds["omega"].values, dtype=float)
    _finite(ds, src)
    summary = _added_mass(ds, src, dofs, w, tol)
    summary.update(_damping(ds, src, dofs, w, eig_tol))
    summary.update(_hydrostatics(ds, src, dofs, awp_tol))
    return summary


def _finite(ds, src):
    for name in ("added_mass", "radiation_damping", "excitation_force", "hydrostatic_stiffness",
                 "displaced_volume", "center_of_buoyancy", "added_mass_inf", "added_mass_zero"):
        if name not in ds:
            continue
        x = np.asarray(ds[name].values)
        partial = name in ("added_mass_inf", "added_mass_zero")   # all NaN: absent from the file
        if partial and not np.any(np.isfinite(x)):
            continue
        if not np.all(np.isfinite(x)):
            at = ""
            if "omega" in ds[name].dims:
                ax = ds[name].dims.index("omega")
                bad = np.any(np.moveaxis(~np.isfinite(x), ax, 0).reshape(x.shape[ax], -1), axis=1)
                at = f" at {fmt_omega(float(ds['omega'].values[int(np.argmax(bad))]))}"
            raise HydroError(f"{src}: {name} has NaN or infinite values{at}; expected finite numbers "
                             "— missing or corrupt data: regenerate the file or read the BEM output again")


def _entry(name, dof):
    return f"{name}[{dof}, {dof}]"


def _added_mass(ds, src, dofs, w, tol):
    A = force_first(ds["added_mass"])
    d = np.diagonal(A, axis1=-2, axis2=-1)                       # (ω, dof)
    scale = kind_scales(dofs, np.abs(d).max(axis=0))
    S = d / scale
    remedy = ("expected A_kk > 0 (added mass is the kinetic energy of the water the body moves): "
              "a sign or unit error in the file or its converter — fix the BEM run or its export")
    summary = {"added_mass_min_scaled": float(S.min()), "resonance_bands": []}
    for name in ("added_mass_inf", "added_mass_zero"):
        if name in ds and np.all(np.isfinite(ds[name].values)):
            Si = np.diagonal(force_first(ds[name])) / scale
            summary[f"{name}_min_scaled"] = float(Si.min())
            k = int(np.argmin(Si))
            if Si[k] < -tol:
                value = float(np.diagonal(force_first(ds[name]))[k])
                where = "ω = ∞" if name.endswith("inf") else "ω = 0"
                raise HydroError(f"{src}: {_entry(name, dofs[k])} = {value:.6g} at {where} is negative "
                                 f"({Si[k]:.3g} of the largest {_kind(dofs[k])} added mass); {remedy}")
    for j, dof in enumerate(dofs):
        neg = S[:, j] < -tol
        if not neg.any():
            continue
        k = int(np.argmax(neg))
        if neg[0] or neg[-1]:
            k = 0 if neg[0] else len(w) - 1
            end = "lowest" if neg[0] else "highest"
            raise HydroError(
                f"{src}: {_entry('added_mass', dof)} = {A[k, j, j]:.6g} at {fmt_omega(w[k])} (the {end} "
                f"frequency of the data) is negative ({S[k, j]:.3g} of the largest {_kind(dof)} added "
                f"mass); {remedy}. (A dip below zero between two frequencies where it is positive is "
                "accepted as a resonance: gap, moonpool, submerged body)")
        band = w[neg]
        summary["resonance_bands"].append({"entry": _entry("added_mass", dof), "omega": [float(band[0]),
                                           float(band[-1])], "min_scaled": float(S[neg, j].min())})
    return summary


def _kind(dof):
    return "rotational" if split_dof(dof)[1] in ("Roll", "Pitch", "Yaw") else "translational"


def _damping(ds, src, dofs, w, eig_tol):
    B = force_first(ds["radiation_damping"])
    s = np.sqrt(kind_scales(dofs, np.abs(np.diagonal(B, axis1=-2, axis2=-1)).max(axis=0)))
    S = B / np.outer(s, s)
    limit = float(ds.attrs.get("omega_max_mesh", np.inf))
    checked = np.where(w <= limit)[0]
    if checked.size == 0:
        return {"damping_min_scaled_eigenvalue": None}
    lam, vec = np.linalg.eigh(0.5 * (S[checked] + np.swapaxes(S[checked], -1, -2)))
    i = int(np.argmin(lam[:, 0]))
    k = int(checked[i])
    if lam[i, 0] < -eig_tol:
        j = int(np.argmax(vec[i, :, 0] ** 2))
        diag = [dofs[m] for m in range(len(dofs)) if S[k, m, m] < -eig_tol]
        what = (f"{_entry('radiation_damping', diag[0])} = {B[k, dofs.index(diag[0]), dofs.index(diag[0])]:.6g}"
                if diag else f"radiation_damping (eigenvector mostly {dofs[j]})")
        raise HydroError(
            f"{src}: {what} at {fmt_omega(w[k])} is not passive: smallest eigenvalue of the scaled damping "
            f"matrix {lam[i, 0]:.3g} < -{eig_tol:g}; expected B(ω) positive semi-definite (the radiated "
            "power is never negative) — a sign error or an irregular frequency: fix the BEM run (a lid), or "
            "read the file with source_options negative_damping = \"project\" or omega_range = [lo, hi]")
    return {"damping_min_scaled_eigenvalue": float(lam[i, 0]), "damping_min_at_omega": float(w[k]),
            "damping_checked_up_to": float(w[checked[-1]])}


def _up(ds) -> float:
    """+1 when z points up in the data's points (a reader's data frame), -1 in NED."""
    return 1.0 if "z up" in str(ds.attrs.get("frame", "")) else -1.0


def _hydrostatics(ds, src, dofs, awp_tol):
    K = force_first(ds["hydrostatic_stiffness"])
    rho, g = float(ds.attrs.get("rho", 1025.0)), float(ds.attrs.get("g", 9.81))
    worst = 0.0
    for body in [str(b) for b in ds["body"].values]:
        volume = float(ds["displaced_volume"].sel(body=body)) if "displaced_volume" in ds else np.nan
        length = abs(volume) ** (1 / 3) if np.isfinite(volume) else 0.0
        if volume < 0:
            raise HydroError(f"{src}: displaced_volume[{body}] = {volume:.6g} m^3 is negative; expected V ≥ 0 "
                             "— mesh normals pointing inwards: fix the mesh")
        if "center_of_buoyancy" in ds and volume > 0:
            height = _up(ds) * float(ds["center_of_buoyancy"].sel(body=body).sel(xyz="z"))
            if height > COB_TOL * length:
                raise HydroError(f"{src}: center_of_buoyancy[{body}] is {height:.4g} m above the free surface; "
                                 "expected it at or below the surface (it is the centroid of the displaced "
                                 "water) — a sign or frame error in the file")
        heave = f"{body}__Heave"
        if heave not in dofs:
            continue
        i = dofs.index(heave)
        c33 = float(K[i, i])
        if c33 < -1e-9 * rho * g * max(length, 1e-3) ** 2:
            raise HydroError(f"{src}: hydrostatic_stiffness[{heave}, {heave}] = {c33:.6g} N/m is negative; "
                             f"expected C33 = ρ g Awp ≥ 0 — a sign error in the file or its converter")
        if "waterplane_area" in ds:
            awp = float(ds["waterplane_area"].sel(body=body))
            ref = max(abs(c33), rho * g * abs(awp))
            mismatch = abs(c33 - rho * g * awp) / ref if ref > 0 else 0.0
            worst = max(worst, mismatch)
            if mismatch > awp_tol:
                raise HydroError(
                    f"{src}: hydrostatic_stiffness[{heave}, {heave}] = {c33:.6g} N/m but ρ g Awp = {rho:g} × {g:g} × "
                    f"{awp:.6g} m² = {rho * g * awp:.6g} N/m (waterplane_area[{body}]): they differ by "
                    f"{mismatch:.3g} > {awp_tol:g}; expected C33 = ρ g Awp — the file's ρ, g or mesh disagree")
    return {"c33_vs_rho_g_awp": worst}
