"""Hydrodynamics without interaction: each body solved alone, the results side by side.

A scene with ``[hydro] interaction = false`` models every body as if the others were absent:
radiation couples no two bodies (block-diagonal A, B, A∞, hydrostatics) and each body's
excitation is that of the isolated body at its own place in the wave (Capytaine solves it
there, so the phase of the incident wave along the array is exact). That is the usual
simplification for long chains (the cost of a coupled BEM grows with the cube of the panel
count, and a coupled radiation model with the square of the DOF count); what it leaves out
is the scattered and radiated waves of one body reaching the others, which matters most for
close neighbours (see hinged_barge for the coupled pair).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .bem import compute

_PAIR = ("radiating_dof", "influenced_dof")


def compute_isolated(bodies, **kwargs) -> xr.Dataset:
    """:func:`mbcontrol.hydro.compute` per body (each cached on its own), merged by :func:`merge`."""
    return merge([compute([body], **kwargs) for body in bodies])


def merge(parts: list[xr.Dataset]) -> xr.Dataset:
    """One dataset from per-body datasets on the same frequencies and headings: matrices
    block-diagonal (no coupling), DOF vectors and per-body variables concatenated."""
    first = parts[0]
    for p in parts[1:]:
        if not (np.array_equal(p["omega"], first["omega"])
                and np.array_equal(p["wave_direction"], first["wave_direction"])):
            raise ValueError("merge: the bodies were solved on different frequencies or headings")
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
        interaction="none: each body solved alone (mbcontrol.hydro.isolated)",
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
