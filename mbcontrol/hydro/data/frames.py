"""BEM data frame -> NED body frames at each CoG (ERRATA G10-G13, §4 "BEM -> body frame").

For body k with BEM reference point W_k (WAMIT body origin, Capytaine rotation centre) and
CoG c_k, both given in the n-frame (NED, m):

- T_k = blkdiag(R_k, R_k), R_k = diag(1, -1, -1) for z-up x-forward data (G10); identity for NED data.
- H(r) = [[I, S(r)ᵀ], [0, I]] with r_k = W_k - c_k in NED axes (G11, G13): ν_W = H(r) ν_c.
- matrices (added mass, damping, A(0), A(∞), K(t), stiffness of bodies in equilibrium):
  X^b_kl = H(r_k)ᵀ T_k X_kl T_lᵀ H(r_l)   (wrench-twist congruence, G12)
- excitation (a wrench per unit wave amplitude): τ^b_k = H(r_k)ᵀ T_k τ_k.

Because T and H are real, the same formulas hold for complex frequency-domain data; the time
convention is untouched. With z-up data the wave heading flips sign (y flips): a wave
travelling towards NED heading β is the BEM heading -β.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError

from ..mesh.geometry import NED_TO_ZUP, RIGID_DOFS

MATRIX_DIMS = ("radiating_dof", "influenced_dof")


def skew(a) -> np.ndarray:
    """S(a) with S(a) b = a × b."""
    a = np.asarray(a, dtype=float)
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def shift_matrix(r) -> np.ndarray:
    """Fossen's H(r) = [[I, S(r)ᵀ], [0, I]] (6×6): twist at a point r from the CoG twist."""
    H = np.eye(6)
    H[:3, 3:] = skew(r).T
    return H


def zup_to_ned(p) -> np.ndarray:
    """Coordinates of a point (or array of points, last axis 3) from z-up BEM axes to NED."""
    return np.asarray(p, dtype=float) @ NED_TO_ZUP.T


def split_dof(name: str) -> tuple[str, str]:
    """'barge1__Heave' -> ('barge1', 'Heave'); raises HydroError on other forms."""
    body, sep, dof = str(name).rpartition("__")
    if not sep or not body or dof not in RIGID_DOFS:
        raise HydroError(f"DOF name {name!r}: expected '<body>__<Dof>' with Dof in {RIGID_DOFS}")
    return body, dof


def dof_map(dofs, refs: dict, cogs: dict, z_up: bool = True) -> np.ndarray:
    """The n×n map M = 𝓗ᵀ𝓣 restricted to the DOF list ``dofs`` (τ^b = M τ, X^b = M X Mᵀ).

    Each body must carry all 6 DOFs unless its r_k = 0: then 𝓗ᵀ𝓣 is diagonal and any
    subset of DOFs maps on its own.
    """
    dofs = [str(d) for d in dofs]
    R = NED_TO_ZUP if z_up else np.eye(3)
    T6 = np.kron(np.eye(2), R)
    idx = {d: i for i, d in enumerate(dofs)}
    M = np.zeros((len(dofs), len(dofs)))
    bodies: dict[str, list[str]] = {}
    for d in dofs:
        b, dof = split_dof(d)
        bodies.setdefault(b, []).append(dof)
    for b, present in bodies.items():
        if b not in refs or b not in cogs:
            raise HydroError(f"to_body_frames: no reference point or CoG given for body '{b}' "
                             f"(refs has {sorted(refs)}, cogs has {sorted(cogs)})")
        r = np.asarray(refs[b], dtype=float) - np.asarray(cogs[b], dtype=float)
        G = shift_matrix(r).T @ T6  # 6×6 block of 𝓗ᵀ𝓣
        full = [RIGID_DOFS.index(p) for p in present]
        absent = [i for i in range(6) if i not in full]
        if np.any(G[np.ix_(full, absent)] != 0):  # a kept DOF would need a dropped one
            raise HydroError(f"to_body_frames: body '{b}' has reference point {refs[b]} != CoG {cogs[b]} "
                             f"but only DOFs {present}; expected all 6 rigid DOFs to shift the reference point")
        for i in full:
            for j in full:
                M[idx[f"{b}__{RIGID_DOFS[i]}"], idx[f"{b}__{RIGID_DOFS[j]}"]] = G[i, j]
    return M


def _wrap_angle(a):
    return (np.asarray(a, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def to_body_frames(ds_data: xr.Dataset, refs: dict, cogs: dict, z_up: bool = True) -> xr.Dataset:
    """Map a hydrodynamic dataset from the BEM data frame to NED body frames at each CoG.

    Parameters
    ----------
    ds_data : dataset with coords ``radiating_dof``/``influenced_dof`` named ``<body>__<Dof>``.
        Every variable that has both DOF dims is a matrix (X^b = 𝓗ᵀ𝓣 X 𝓣ᵀ𝓗, whatever the order
        of the two dims); every variable with ``influenced_dof`` only is a wrench (τ^b = 𝓗ᵀ𝓣 τ).
        A variable ``center_of_buoyancy`` (body, xyz) is a point and is mapped to NED coordinates.
    refs, cogs : body name -> reference point W_k and CoG c_k, both in n-frame (NED) coordinates, m.
    z_up : True if the data axes are z-up (x forward, y port), as in Capytaine and WAMIT.
        Then R_k = diag(1, -1, -1), and ``wave_direction`` β becomes -β (wrapped to [-π, π)).

    Returns a new dataset; attrs gain ``frame = "NED body frames at CoG"``.
    """
    for dim in MATRIX_DIMS:
        if dim not in ds_data.dims:
            raise HydroError(f"to_body_frames: dataset has no '{dim}' dimension; expected Capytaine-like layout")
    rad = [str(d) for d in ds_data["radiating_dof"].values]
    inf = [str(d) for d in ds_data["influenced_dof"].values]
    Mr, Mi = dof_map(rad, refs, cogs, z_up), dof_map(inf, refs, cogs, z_up)
    out = ds_data.copy()
    for name, da in ds_data.data_vars.items():
        dims = da.dims
        if "radiating_dof" in dims and "influenced_dof" in dims:
            # X^b[i_inf, j_rad] = Σ Mi[i,a] X[a,b] Mr[j,b]
            x = da.transpose(..., "influenced_dof", "radiating_dof").values
            xb = np.einsum("ia,...ab,jb->...ij", Mi, x, Mr)
            new = da.transpose(..., "influenced_dof", "radiating_dof").copy(data=xb).transpose(*dims)
        elif "influenced_dof" in dims:
            x = np.moveaxis(da.values, dims.index("influenced_dof"), -1)
            new = da.copy(data=np.moveaxis(x @ Mi.T, -1, dims.index("influenced_dof")))
        elif "radiating_dof" in dims:
            x = np.moveaxis(da.values, dims.index("radiating_dof"), -1)
            new = da.copy(data=np.moveaxis(x @ Mr.T, -1, dims.index("radiating_dof")))
        elif name == "center_of_buoyancy" and z_up:
            new = da.copy(data=zup_to_ned(da.transpose(..., "xyz").values)).transpose(*dims)
        else:
            continue
        new.attrs = dict(da.attrs)
        out[name] = new
    if z_up and "wave_direction" in out.coords:
        out = out.assign_coords(wave_direction=_wrap_angle(-out["wave_direction"].values))
        out["wave_direction"].attrs = dict(ds_data["wave_direction"].attrs)
        out = out.sortby("wave_direction")
    out.attrs = dict(ds_data.attrs)
    out.attrs["frame"] = "NED body frames at CoG"
    return out
