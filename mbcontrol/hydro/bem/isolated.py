"""Hydrodynamics without interaction: each body solved alone, the results side by side.

A scene with ``[hydro] interaction = false`` models every body as if the others were absent:
radiation couples no two bodies (block-diagonal A, B, A∞, hydrostatics) and each body's
excitation is that of the isolated body at its own place in the wave (Capytaine solves it
there, so the phase of the incident wave along the array is exact). That is the usual
simplification for long chains (the cost of a coupled BEM grows with the cube of the panel
count, and a coupled radiation model with the square of the DOF count); what it leaves out
is the scattered and radiated waves of one body reaching the others, which matters most for
close neighbours (see hinged_barge for the coupled pair).

Identical bodies (same geometry, CoG relative to it, mass, panel size, DOFs, orientation:
everything but the horizontal position) are solved once, as one canonical body at the
origin (so the cache key is the shape's, wherever it sits): a body alone in a horizontally
uniform sea is translation-invariant, so its radiation is the same anywhere and its
excitation only gains the incident wave's phase at its place (:func:`shifted`).
"""
from __future__ import annotations

import json

import numpy as np
import xarray as xr

from ...errors import HydroError
from ...waves import wavenumber
from .solve import _geometry_for_key, compute
from ..mesh.geometry import BemBody

_PAIR = ("radiating_dof", "influenced_dof")
_CANONICAL = "body"     # the canonical body's name: DOF names do not key the cache per scene


def compute_isolated(bodies, **kwargs) -> xr.Dataset:
    """:func:`mbcontrol.hydro.compute` once per distinct shape (cached on its own), moved to
    each body's place by :func:`shifted`, merged by :func:`merge`. Keyword arguments as
    compute's (rho kg/m^3, g m/s^2, depth m, omegas rad/s, headings rad, cache_dir...).
    attrs distinct_shapes: the shapes solved (or read from the cache), one BEM run each."""
    solved, parts = {}, []
    for body in bodies:
        key, canonical, (dx, dy) = canonical_body(body)
        if key not in solved:
            solved[key] = compute([canonical], **kwargs)
        parts.append(shifted(solved[key], body, dx, dy))
    ds = merge(parts)
    seconds = sum(d.attrs.get("solve_seconds", 0.0) for d in solved.values())
    ds.attrs.update(distinct_shapes=len(solved), solve_seconds=float(seconds))
    return ds


def canonical_body(body: BemBody) -> tuple[str, BemBody, tuple[float, float]]:
    """(shape key, the body moved horizontally so its geometry's centre is on the z axis and
    renamed, the move undone: (dx, dy), m, NED). A mesh's centre defaults to its own origin."""
    g = dict(body.geometry)
    cx, cy, cz = (float(v) for v in g.get("center", (0.0, 0.0, 0.0)))
    g["center"] = [0.0, 0.0, cz]
    cog = (float(body.cog[0]) - cx, float(body.cog[1]) - cy, float(body.cog[2]))
    canonical = BemBody(name=_CANONICAL, geometry=g, cog=cog, mass=float(body.mass),
                        panel_size=float(body.panel_size), dofs=tuple(body.dofs))
    key = json.dumps({"geometry": _geometry_for_key(g), "cog": cog, "mass": canonical.mass,
                      "panel_size": canonical.panel_size, "dofs": list(canonical.dofs)},
                     sort_keys=True, default=str)
    return key, canonical, (cx, cy)


def shifted(ds: xr.Dataset, body: BemBody, dx: float, dy: float) -> xr.Dataset:
    """The one-body dataset ``ds`` (of :func:`canonical_body`) for ``body``, which is the same
    shape moved by (dx, dy) m (NED): names and CoG from ``body``; the excitation times the
    incident wave's phase there, exp(+i k (dx cos β + dy sin β)) (exp(-i ω t), elevation
    Re(a exp(i(k·x - ω t))) referred to the origin), k of the data's depth; the rest as is."""
    old = str(ds["body"].values[0])
    rename = {f"{old}__{d}": f"{body.name}__{d}" for d in body.dofs}
    out = ds.assign_coords(radiating_dof=[rename[str(d)] for d in ds["radiating_dof"].values],
                           influenced_dof=[rename[str(d)] for d in ds["influenced_dof"].values],
                           body=[body.name])
    depth, g = float(ds.attrs["depth"]), float(ds.attrs["g"])
    k = np.array([wavenumber(float(w), depth, g) for w in ds["omega"].values])
    beta = ds["wave_direction"].values
    phase = np.exp(1j * np.outer(dx * np.cos(beta) + dy * np.sin(beta), k))   # (heading, ω)
    phase = xr.DataArray(phase, dims=("wave_direction", "omega"),
                         coords={"wave_direction": beta, "omega": ds["omega"].values})
    for name in ("excitation_force", "froude_krylov_force", "diffraction_force"):
        out[name] = (ds[name].assign_coords(influenced_dof=out["influenced_dof"]) * phase
                     ).transpose(*ds[name].dims).assign_attrs(ds[name].attrs)
    out["cog"] = (("body", "xyz"), np.asarray(body.cog, float)[None, :])
    out["mass"] = (("body",), np.array([float(body.mass)]))
    out["center_of_buoyancy"] = (("body", "xyz"), ds["center_of_buoyancy"].values + [dx, dy, 0.0])
    for var in ("cog", "mass", "center_of_buoyancy"):
        out[var].attrs = ds[var].attrs
    for key in ("hull_panels", "lid_panels"):
        if key in ds.attrs:
            out.attrs[key] = {body.name: v for v in ds.attrs[key].values()}
    return out


def merge(parts: list[xr.Dataset]) -> xr.Dataset:
    """One dataset from per-body datasets on the same frequencies and headings: matrices
    block-diagonal (no coupling), DOF vectors and per-body variables concatenated."""
    first = parts[0]
    for p in parts[1:]:
        if not (np.array_equal(p["omega"], first["omega"])
                and np.array_equal(p["wave_direction"], first["wave_direction"])):
            raise HydroError("merge: the bodies were solved on different frequencies or headings")
    dofs = [str(d) for p in parts for d in p["radiating_dof"].values]
    out = {}
    for name, da in first.data_vars.items():
        if set(_PAIR) <= set(da.dims):
            out[name] = _block_diagonal([p[name] for p in parts], dofs)
        elif "influenced_dof" in da.dims:
            out[name] = xr.concat([p[name] for p in parts], dim="influenced_dof")
        elif "body" in da.dims:
            out[name] = xr.concat([p[name] for p in parts], dim="body")
    ds = xr.Dataset(out)
    ds.attrs = dict(first.attrs)
    for key in ("hull_panels", "lid_panels"):
        if key in first.attrs:
            ds.attrs[key] = {k: v for p in parts for k, v in p.attrs[key].items()}
    ds.attrs.update(
        interaction="none: each body solved alone (mbcontrol.hydro.bem.isolated)",
        omega_max_mesh=float(min(p.attrs.get("omega_max_mesh", np.inf) for p in parts)),
        solve_seconds=float(sum(p.attrs.get("solve_seconds", 0.0) for p in parts)),
        cache_key=[p.attrs.get("cache_key") for p in parts])
    return ds


def _block_diagonal(blocks: list[xr.DataArray], dofs: list[str]) -> xr.DataArray:
    first = blocks[0].transpose(..., *_PAIR)
    lead = first.shape[:-2]
    data = np.zeros(lead + (len(dofs), len(dofs)), dtype=first.dtype)
    k = 0
    for b in blocks:
        n = b.sizes["radiating_dof"]
        data[..., k:k + n, k:k + n] = b.transpose(..., *_PAIR).values
        k += n
    coords = {d: first[d] for d in first.dims[:-2]}
    coords.update(radiating_dof=dofs, influenced_dof=dofs)
    return xr.DataArray(data, dims=first.dims, coords=coords, attrs=first.attrs)
