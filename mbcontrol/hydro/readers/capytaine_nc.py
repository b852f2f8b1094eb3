"""Reader of Capytaine netCDF datasets (``capytaine.export_dataset``) and of mbcontrol's own files.

Capytaine facts used here (capytaine.io.xarray, 2.x-3.x):

- complex variables are stored with a leading ``complex = ['re', 'im']`` dimension;
- ``added_mass``/``radiation_damping`` have dims (ω, influenced_dof, radiating_dof), i.e. the
  force first; ``hydrostatic_stiffness`` (influenced_dof, radiating_dof); ``excitation_force``,
  ``Froude_Krylov_force``, ``diffraction_force`` (ω, wave_direction, influenced_dof), e^{-iωt};
- ``g``, ``rho``, ``water_depth``, ``forward_speed`` become dimensions when they take several values;
- DOFs of a single FloatingBody are plain (``Heave``); of a Multibody ``<body>__<Dof>``;
- ``rotation_center`` and ``center_of_mass`` are coordinates (body, space_coordinate) or
  (space_coordinate) for one body; ω = 0 and ω = ∞ may appear in the ω coordinate.

A file written by :func:`mbcontrol.hydro.write_netcdf_atomic` is read with
:func:`mbcontrol.hydro.read_netcdf`. If it is in NED body frames at the CoG (the output of
:func:`mbcontrol.hydro.compute`), it is mapped back to the data frame: with r = 0 the map of
:func:`~mbcontrol.hydro.to_body_frames` is its own inverse, and ``reference_point`` = the CoG.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError
from mbcontrol.hydro.data import netcdf
from mbcontrol.hydro.data.frames import to_body_frames, zup_to_ned
from mbcontrol.hydro.mesh.geometry import RIGID_DOFS

from .checks import clean
from .layout import body_name_list, build_dataset, finish_attrs

_FREQ_DIMS = ("omega", "freq", "period", "wavenumber", "wavelength")


def _open(path: Path, src: str) -> xr.Dataset:
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected a Capytaine or mbcontrol netCDF dataset)")
    try:
        with xr.open_dataset(path) as raw:
            return raw.load()
    except Exception as exc:  # netCDF4 / HDF5 / scipy raise unrelated types
        raise HydroError(f"{src}: unreadable as netCDF ({type(exc).__name__}: {exc}); "
                         "expected a dataset written by capytaine.export_dataset or mbcontrol") from exc


def _merge_complex(ds: xr.Dataset) -> xr.Dataset:
    if "complex" not in ds.dims:
        return ds
    out = ds.copy()
    for v in list(out.data_vars):
        if "complex" in out[v].dims:
            da = out[v]
            out[v] = da.sel(complex="re", drop=True) + 1j * da.sel(complex="im", drop=True)
            out[v].attrs = dict(da.attrs)
    return out.drop_vars("complex", errors="ignore")


def _single(ds: xr.Dataset, name: str, src: str, default=None) -> float:
    if name not in ds.coords and name not in ds:
        if default is not None:
            return default
        raise HydroError(f"{src}: no '{name}' in the dataset; expected Capytaine's {name} coordinate")
    v = np.asarray(ds[name].values, dtype=float).reshape(-1)
    if v.size != 1:
        raise HydroError(f"{src}: {v.size} values of {name} {v.tolist()}; expected one (select one first)")
    return float(v[0])


def _from_mbcontrol(path: Path, src: str, body_names) -> xr.Dataset:
    ds = netcdf.read_netcdf(path)
    frame = str(ds.attrs.get("frame", ""))
    notes = list(ds.attrs.get("notes", []))
    if frame.startswith("NED body frames"):
        if "cog" not in ds:
            raise HydroError(f"{src}: dataset in NED body frames without a 'cog' variable; "
                             "expected the output of mbcontrol.hydro.compute")
        bodies = [str(b) for b in ds["body"].values]
        cogs = {b: np.asarray(ds["cog"].sel(body=b).values, dtype=float) for b in bodies}
        data = to_body_frames(ds, refs=cogs, cogs=cogs, z_up=True)  # r = 0: its own inverse
        data["cog"] = (("body", "xyz"), zup_to_ned(ds["cog"].transpose("body", "xyz").values))
        data["reference_point"] = data["cog"].copy()
        notes.append("mbcontrol dataset in NED body frames at the CoG mapped back to the z-up data frame "
                     "(exact inverse, r = 0); reference_point = the CoG of the file")
    else:
        data = ds
        if "reference_point" not in data:
            raise HydroError(f"{src}: mbcontrol dataset without 'reference_point' and not in NED body frames "
                             f"(frame = {frame!r}); expected a reader output or a compute() output")
    if body_names is not None:
        old = [str(b) for b in data["body"].values]
        new, name_notes = body_name_list(old, len(old), body_names, path)
        notes += name_notes
        ren = {f"{o}__{d}": f"{nn}__{d}" for o, nn in zip(old, new) for d in RIGID_DOFS}
        rename = lambda dofs: [ren.get(str(d), str(d)) for d in dofs]  # noqa: E731
        data = data.assign_coords(body=new, radiating_dof=rename(data["radiating_dof"].values),
                                  influenced_dof=rename(data["influenced_dof"].values))
    attrs = dict(data.attrs)
    data = finish_attrs(data, rho=attrs.get("rho", np.nan), g=attrs.get("g", np.nan),
                        depth=attrs.get("depth", np.nan), source=src, notes=notes)
    data.attrs["original_source"] = str(attrs.get("source", ""))
    for k in ("rho", "g", "depth"):
        if not np.isfinite(data.attrs[k]) and not (k == "depth" and data.attrs[k] == math.inf):
            raise HydroError(f"{src}: attribute {k} = {attrs.get(k)!r}; expected a number")
    return data


def _split(dof: str, single: str | None, src: str) -> tuple[str, str]:
    body, sep, name = str(dof).rpartition("__")
    if not sep:
        if single is None:
            raise HydroError(f"{src}: DOF {dof!r} without a body prefix in a multibody dataset")
        body, name = single, str(dof)
    if name not in RIGID_DOFS:
        raise HydroError(f"{src}: DOF {dof!r} is not a rigid-body DOF {RIGID_DOFS}; generalised modes "
                         "are not supported")
    return body, name


def _per_body(ds, name, bodies, single, src):
    """(nb, 3) array of a point coordinate, or None."""
    if name not in ds.coords and name not in ds:
        return None
    da = ds[name]
    if "body" in da.dims:
        order = [str(b) for b in da["body"].values]
        return np.array([da.sel(body=b).transpose("space_coordinate").values if b in order else [np.nan] * 3
                         for b in bodies], dtype=float)
    if len(bodies) == 1:
        return np.asarray(da.transpose("space_coordinate").values, dtype=float)[None, :]
    return None


def _one_condition(ds: xr.Dataset, src: str) -> xr.Dataset:
    """The results checked for radiation and diffraction, on an omega dimension, at one g, rho,
    depth and (zero) speed."""
    for v in ("added_mass", "radiation_damping"):
        if v not in ds:
            raise HydroError(f"{src}: no '{v}' variable; expected radiation results (capytaine.export_dataset)")
    if "excitation_force" not in ds:
        raise HydroError(f"{src}: no 'excitation_force' variable; expected diffraction results as well")
    freq = [d for d in _FREQ_DIMS if d in ds["added_mass"].dims]
    if not freq:
        raise HydroError(f"{src}: added_mass has no frequency dimension; expected one of {_FREQ_DIMS}")
    if freq[0] != "omega":
        if "omega" not in ds.coords:
            raise HydroError(f"{src}: frequencies given as '{freq[0]}' without an 'omega' coordinate")
        ds = ds.swap_dims({freq[0]: "omega"})
    for d in ("g", "rho", "water_depth", "forward_speed"):
        if d in ds.dims:
            if ds.sizes[d] != 1:
                raise HydroError(f"{src}: {ds.sizes[d]} values of {d}; expected one (select one first)")
            ds = ds.isel({d: 0})
    return ds


def _body_points(ds, file_bodies, names, single, src, *, rho, parsed, order, notes):
    """(centres of buoyancy, of mass (or None), reference points, displaced volumes m^3) per
    body; a body without a rotation_center and with translation DOFs only refers to its centre
    of mass (noted)."""
    cob = _per_body(ds, "center_of_buoyancy", file_bodies, single, src)
    rc = _per_body(ds, "rotation_center", file_bodies, single, src)
    com = _per_body(ds, "center_of_mass", file_bodies, single, src)
    if cob is None:
        raise HydroError(f"{src}: no 'center_of_buoyancy'; expected Capytaine hydrostatics in the dataset")
    if "disp_mass" in ds:
        vol = np.atleast_1d(np.asarray(ds["disp_mass"].values, dtype=float)).reshape(-1) / rho
    else:
        raise HydroError(f"{src}: no 'disp_mass'; expected Capytaine hydrostatics in the dataset")
    ref = np.zeros((len(file_bodies), 3)) if rc is None else rc.copy()
    for k, b in enumerate(file_bodies):
        if not np.all(np.isfinite(ref[k])):
            has_rot = any(parsed[d][0] == b and parsed[d][1] in ("Roll", "Pitch", "Yaw") for d in order)
            if has_rot:
                raise HydroError(f"{src}: body {b!r} has rotation DOFs but no rotation_center; expected it")
            ref[k] = com[k] if com is not None and np.all(np.isfinite(com[k])) else 0.0
            notes.append(f"body {names[k]}: no rotation_center (translation DOFs only); reference_point set to "
                         f"{ref[k].tolist()}, which does not change translation-only data")
    return cob, com, ref, vol


def read_capytaine(path, *, body_names=None, **clean_kw) -> xr.Dataset:
    """Read a Capytaine netCDF dataset (or an mbcontrol one) into the data-frame dataset.

    ``body_names`` (one per body, in the file's order) replace the names in the file.
    ``**clean_kw`` are options of :func:`mbcontrol.hydro.readers.clean`.
    """
    path = Path(path)
    src = f"Capytaine {path}"
    raw = _open(path, src)
    if "mbc_encoded_attrs" in raw.attrs or "matrix_layout" in raw.attrs:
        return clean(_from_mbcontrol(path, f"mbcontrol {path}", body_names), source=f"mbcontrol {path}", **clean_kw)
    ds = _one_condition(_merge_complex(raw), src)
    rho, g = _single(ds, "rho", src), _single(ds, "g", src)
    depth = _single(ds, "water_depth", src)
    if _single(ds, "forward_speed", src, default=0.0) != 0.0:
        raise HydroError(f"{src}: forward_speed != 0; expected zero-speed data")
    notes = []
    rad = [str(d) for d in ds["radiating_dof"].values]
    inf = [str(d) for d in ds["influenced_dof"].values]
    multi = any("__" in d for d in rad + inf)
    single = None
    if not multi:
        single = str(np.asarray(ds["body"].values).reshape(-1)[0]) if "body" in ds.coords else "body1"
    parsed = {d: _split(d, single, src) for d in set(rad) | set(inf)}
    file_bodies = list(dict.fromkeys(parsed[d][0] for d in inf + rad))
    if "body" in ds.coords and np.asarray(ds["body"].values).ndim == 1:
        listed = [str(b) for b in ds["body"].values]
        file_bodies = [b for b in listed if b in file_bodies] + [b for b in file_bodies if b not in listed]
    names, name_notes = body_name_list(file_bodies, len(file_bodies), body_names, path)
    notes += name_notes
    rename = dict(zip(file_bodies, names))
    keep = [d for d in inf if d in rad]
    dropped = [d for d in inf if d not in rad]
    if dropped:
        notes.append(f"influenced DOFs without radiation data dropped: {dropped}")
    order = sorted(keep, key=lambda d: (file_bodies.index(parsed[d][0]), RIGID_DOFS.index(parsed[d][1])))
    dofs = [f"{rename[parsed[d][0]]}__{parsed[d][1]}" for d in order]

    w = np.asarray(ds["omega"].values, dtype=float)
    sel = dict(influenced_dof=order, radiating_dof=order)
    Afull = ds["added_mass"].sel(**sel).transpose("omega", "influenced_dof", "radiating_dof").values
    Bfull = ds["radiation_damping"].sel(**sel).transpose("omega", "influenced_dof", "radiating_dof").values
    fin = np.isfinite(w) & (w > 0)
    A0 = Afull[np.where(w == 0)[0][0]] if np.any(w == 0) else None
    Ainf = Afull[np.where(np.isinf(w))[0][0]] if np.any(np.isinf(w)) else None
    for label, arr in (("ω = 0", A0), ("ω = ∞", Ainf)):
        if arr is not None:
            notes.append(f"added mass at {label} taken from the file's {label} entry")

    def wrench(v):
        da = ds[v].sel(influenced_dof=order)
        if "wave_direction" not in da.dims:
            da = da.expand_dims("wave_direction")
        return da.transpose("wave_direction", "omega", "influenced_dof").values[:, fin, :]

    heads = np.atleast_1d(np.asarray(ds["wave_direction"].values, dtype=float))
    exc = wrench("excitation_force")
    fk = wrench("Froude_Krylov_force") if "Froude_Krylov_force" in ds else None
    diff = wrench("diffraction_force") if "diffraction_force" in ds else None
    if "hydrostatic_stiffness" in ds:
        K = ds["hydrostatic_stiffness"].sel(**sel).transpose("influenced_dof", "radiating_dof").values
    else:
        raise HydroError(f"{src}: no 'hydrostatic_stiffness'; expected Capytaine hydrostatics in the dataset "
                         "(give the body a center_of_mass before solving)")
    cob, com, ref, vol = _body_points(ds, file_bodies, names, single, src, rho=rho, parsed=parsed,
                                      order=order, notes=notes)
    notes.append("reference_point = Capytaine rotation_center of each body; cog = center_of_mass")
    ds_out = build_dataset(bodies=names, dofs=dofs, omega=w[fin], A=Afull[fin], B=Bfull[fin], K=K, exc=exc,
                           headings=heads, A0=A0, Ainf=Ainf, fk=fk, diff=diff, volume=vol, cob=cob, ref=ref,
                           cog=com if com is not None and np.all(np.isfinite(com)) else None,
                           rho=rho, g=g, depth=depth, source=src, notes=notes)
    ds_out.attrs["capytaine_version"] = str(raw.attrs.get("capytaine_version", ""))
    return clean(ds_out, source=src, **clean_kw)
