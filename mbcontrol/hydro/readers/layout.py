"""The data-frame layout every reader builds (before `clean` checks it): names, dimensions,
units and attributes, as `mbcontrol.hydro.bem.solve.compute` assembles them before the map to body
frames."""
from __future__ import annotations

import re

import numpy as np
import xarray as xr

from ...errors import HydroError
from ..data.dataset import BODY_FRAME_UNITS
from ..data.frames import split_dof
from ..mesh.geometry import RIGID_DOFS

MAT = ("radiating_dof", "influenced_dof")


WRENCH = ("wave_direction", "omega", "influenced_dof")


MATRIX_LAYOUT = "X[radiating_dof, influenced_dof]; force_i = -sum_j X[j, i] * motion_j"


TIME_CONVENTION = "exp(-i omega t)"


DATA_FRAME = "BEM data frame: z up, x forward, y port, origin on the undisturbed free surface"


# the body-frame units of bem.py, with positions in the data frame (before to_body_frames)
UNITS = {**{k: v for k, v in BODY_FRAME_UNITS.items() if k != "mass"},
         "center_of_buoyancy": "m (data frame, z up)", "cog": "m (data frame, z up)",
         "reference_point": "m (data frame, z up)"}


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
def fmt_omega(w: float) -> str:
    if w == 0:
        return "ω = 0"
    if not np.isfinite(w):
        return f"ω = {w}"
    return f"ω = {w:.6g} rad/s (T = {2 * np.pi / w:.6g} s)"


def kind_scales(dofs, diag_abs_max) -> np.ndarray:
    """Per-DOF scale s_k: the largest |X_kk| among DOFs of the same kind (translation / rotation)."""
    rot = np.array([split_dof(d)[1] in ("Roll", "Pitch", "Yaw") for d in dofs])
    d = np.asarray(diag_abs_max, dtype=float)
    s = np.zeros(len(dofs))
    for mask in (rot, ~rot):
        if mask.any():
            s[mask] = np.nanmax(d[mask]) if np.any(np.isfinite(d[mask])) else 0.0
    pos = s[s > 0]
    return np.where(s > 0, s, pos.max() if pos.size else 1.0)


def force_first(da: xr.DataArray) -> np.ndarray:
    return da.transpose(..., "influenced_dof", "radiating_dof").values


def set_force_first(ds, name, x):
    da = ds[name]
    new = da.transpose(..., "influenced_dof", "radiating_dof").copy(data=x).transpose(*da.dims)
    new.attrs = dict(da.attrs)
    ds[name] = new


class HydroCleaningWarning(UserWarning):
    """A reader changed data values (negative damping repaired, large asymmetry forced away)."""
