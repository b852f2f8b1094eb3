"""Reader of BEMIO HDF5 files (WEC-Sim's hydrodynamic data layout).

Format facts used here (WEC-Sim BEMIO writers; checked against wavestar.h5):

- MATLAB writes column-major, so h5py sees every array with its dimensions reversed; the writers
  permute first, so that h5py reads ``bodyK/hydro_coeffs/added_mass/all`` as (6, 6N, Nω) with
  [i, j, k] = A(i of body K: the force, j: the motion of any body, ω_k); the same holds for
  ``radiation_damping/all``, ``added_mass/inf_freq`` (6, 6N) and ``excitation/re|im`` (6, Nβ, Nω).
- Values are normalised as WAMIT's: A/ρ, B/(ρω), C/(ρg), X/(ρg) (per m of wave amplitude),
  with ρ, g, ω from ``simulation_parameters``. Phases follow WAMIT's e^{+iωt} convention, so the
  excitation is conjugated here for e^{-iωt}.
- ``linear_restoring_stiffness``: older writers store C (so h5py sees Cᵀ), newer ones Cᵀ (h5py
  sees C). For WAMIT data only C(4,6), C(5,6) are one-sided (C(6,4) = C(6,5) = 0), which fixes
  the orientation; a symmetric matrix needs no choice.
- ``properties/cg`` is the point the body's data refer to (WAMIT's body origin XBODY for
  WAMIT-derived files); ``cb`` is in global coordinates; ``water_depth`` is a number or the
  string 'infinite'. A(0) is not stored.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from mbcontrol.errors import HydroError

from .checks import clean
from .layout import body_name_list, build_dataset, dof_names


def _scalar(f, key, path, default=None):
    if key not in f:
        if default is not None:
            return default
        raise HydroError(f"{path}: missing dataset '{key}'; expected a BEMIO hydro file")
    v = f[key][()]
    if isinstance(v, bytes):
        return v.decode(errors="replace")
    arr = np.asarray(v)
    if arr.dtype.kind in "SO":
        return arr.reshape(-1)[0].decode(errors="replace") if isinstance(arr.reshape(-1)[0], bytes) else str(arr)
    return float(arr.reshape(-1)[0])


def _array(f, key, path, shape=None):
    if key not in f:
        raise HydroError(f"{path}: missing dataset '{key}'; expected a BEMIO hydro file")
    a = np.asarray(f[key][()], dtype=float)
    if shape is not None and a.shape != shape:
        raise HydroError(f"{path}: wrong DOF count: '{key}' has shape {a.shape}; expected {shape} "
                         "(6 rigid DOFs per body, all bodies, all frequencies)")
    return a


def _orient_stiffness(C: np.ndarray, notes: list, name: str) -> np.ndarray:
    """Return C force-first: WAMIT's one-sided C(4,6)/C(5,6) must sit above the diagonal."""
    upper = abs(C[3, 5]) + abs(C[4, 5])
    lower = abs(C[5, 3]) + abs(C[5, 4])
    if lower > 0 and upper == 0:
        notes.append(f"body {name}: linear_restoring_stiffness stored transposed (older BEMIO writer); transposed")
        return C.T
    return C


def _body_excitation(f, hc: str, src: str, rows: slice, rho: float, g: float, targets: dict) -> set:
    """One body's excitation parts (total, Froude-Krylov, scattering: `targets`, (Nβ, Nω, n)),
    dimensional and conjugated for e^{-iωt}, into its rows; the optional parts the file lacks
    (absent or nan)."""
    lacking = set()
    for key, target in targets.items():
        nh, nw = target.shape[:2]
        if f"{hc}/{key}/re" not in f:
            if key == "excitation":
                raise HydroError(f"{src}: missing '{hc}/excitation/re'; expected excitation data")
            lacking.add(key)
            continue
        re_ = _array(f, f"{hc}/{key}/re", src, (6, nh, nw))
        im_ = _array(f, f"{hc}/{key}/im", src, (6, nh, nw))
        if key != "excitation" and np.all(np.isnan(re_)):
            lacking.add(key)
            continue
        # (6, Nβ, Nω) -> (Nβ, Nω, 6); conjugate for e^{-iωt}
        target[:, :, rows] = np.transpose(re_ - 1j * im_, (1, 2, 0)) * rho * g
    return lacking


def read_bemio(path, *, body_names=None, **clean_kw):
    """Read a BEMIO ``.h5`` file into the data-frame dataset (dimensional, e^{-iωt}, z up).

    ``body_names`` overrides the names stored in ``bodyK/properties/name`` (file order).
    ``**clean_kw`` are options of :func:`mbcontrol.hydro.readers.clean`.
    """
    import h5py

    path = Path(path)
    src = f"BEMIO {path}"
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a BEMIO .h5 file)")
    try:
        f = h5py.File(path, "r")
    except Exception as exc:  # h5py raises OSError subclasses with HDF5 messages
        raise HydroError(f"{src}: unreadable as HDF5 ({type(exc).__name__}: {exc}); expected a BEMIO .h5 file") from exc
    with f:
        groups = sorted((k for k in f.keys() if re.fullmatch(r"body\d+", k)), key=lambda k: int(k[4:]))
        if not groups:
            raise HydroError(f"{src}: no 'body1' group; expected a BEMIO hydro file")
        if [int(k[4:]) for k in groups] != list(range(1, len(groups) + 1)):
            raise HydroError(f"{src}: body groups {groups}; expected body1..bodyN without gaps")
        nb = len(groups)
        n = 6 * nb
        rho = _scalar(f, "simulation_parameters/rho", src)
        g = _scalar(f, "simulation_parameters/g", src)
        depth = _scalar(f, "simulation_parameters/water_depth", src)
        depth = math.inf if isinstance(depth, str) and "inf" in depth.lower() else float(depth)
        w = _array(f, "simulation_parameters/w", src).reshape(-1)
        nw = w.size
        heads = np.atleast_1d(_array(f, "simulation_parameters/wave_dir", src).reshape(-1))
        nh = heads.size
        code = _scalar(f, "bem_data/code", src, default="unknown")
        notes = [f"BEMIO file from {code}; values multiplied by rho (A), rho*omega (B), rho*g (C, excitation)",
                 "excitation conjugated: BEMIO stores WAMIT's exp(+i omega t) phases",
                 "BEMIO radiation IRF and state-space fits in the file are not read"]
        found, A, B, Ainf, K = [], np.zeros((nw, n, n)), np.zeros((nw, n, n)), np.zeros((n, n)), np.zeros((n, n))
        exc = np.zeros((nh, nw, n), dtype=complex)
        fk = np.zeros((nh, nw, n), dtype=complex)
        sc = np.zeros((nh, nw, n), dtype=complex)
        have_fk = have_sc = True
        vol, cob, ref = [], [], []
        for k, grp in enumerate(groups):
            p = f"{grp}/properties"
            hc = f"{grp}/hydro_coeffs"
            found.append(_scalar(f, f"{p}/name", src, default=grp))
            dof = _scalar(f, f"{p}/dof", src, default=6.0)
            if int(dof) != 6:
                raise HydroError(f"{src}: wrong DOF count: {grp} has dof = {dof}; expected 6 rigid-body DOFs "
                                 "(generalised modes are not supported)")
            rows = slice(6 * k, 6 * k + 6)
            a = _array(f, f"{hc}/added_mass/all", src, (6, n, nw))
            b = _array(f, f"{hc}/radiation_damping/all", src, (6, n, nw))
            A[:, rows, :] = np.moveaxis(a, -1, 0) * rho
            B[:, rows, :] = np.moveaxis(b, -1, 0) * rho * w[:, None, None]
            Ainf[rows, :] = _array(f, f"{hc}/added_mass/inf_freq", src, (6, n)) * rho
            C = _array(f, f"{hc}/linear_restoring_stiffness", src, (6, 6))
            K[rows, rows] = _orient_stiffness(C, notes, found[-1]) * rho * g
            lacking = _body_excitation(f, hc, src, rows, rho, g, {
                "excitation": exc, "excitation/froude-krylov": fk, "excitation/scattering": sc})
            have_fk = have_fk and "excitation/froude-krylov" not in lacking
            have_sc = have_sc and "excitation/scattering" not in lacking
            ref.append(_array(f, f"{p}/cg", src).reshape(-1)[:3])
            cob.append(_array(f, f"{p}/cb", src).reshape(-1)[:3])
            vol.append(float(_array(f, f"{p}/disp_vol", src).reshape(-1)[0]))
    names, name_notes = body_name_list(found, nb, body_names, path)
    notes += name_notes
    notes.append("reference_point = BEMIO properties/cg (the point the data refer to); also stored as cog")
    notes.append("waterplane_area = linear_restoring_stiffness(3,3) (normalised by rho g)")
    if not (have_fk and have_sc):
        notes.append("no Froude-Krylov / scattering parts in the file (absent or NaN)")
    awp = [K[6 * k + 2, 6 * k + 2] / (rho * g) for k in range(nb)]
    ds = build_dataset(bodies=names, dofs=dof_names(names), omega=w, A=A, B=B, K=K, exc=exc,
                       headings=np.radians(heads), A0=None, Ainf=Ainf, fk=fk if have_fk and have_sc else None,
                       diff=sc if have_fk and have_sc else None, volume=vol, cob=np.array(cob), ref=np.array(ref),
                       cog=np.array(ref), awp=awp, rho=rho, g=g, depth=depth, source=src, notes=notes)
    ds.attrs["original_time_convention"] = "exp(+i omega t) (BEMIO/WAMIT); excitation conjugated"
    ds.attrs["bem_code"] = code
    return clean(ds, source=src, **clean_kw)
