"""Hydrodynamics with interaction cut at a radius: each body solved among its neighbours.

A scene with ``[hydro] interaction_radius = R`` (m) couples two bodies only when their
geometry centres are within R of each other (horizontal distance). Body i's forces (its rows of
A(ω), B(ω), A(0), A(∞) and its excitation) come from one BEM solve of i together with every
body within R of it (its *cluster*); the couplings to bodies further away are zero. Between
no interaction (``interaction = false``, module isolated) and the full coupled solve, R trades
accuracy for a BEM whose size no longer grows with the farm:

- **Clusters solved once per shape.** A cluster is moved so that its body i sits at the origin
  and its bodies are named by their relative places, so every cluster with the same relative
  layout (a grid's interior, its edges, its corners) has the same cache key and is solved once;
  its excitation gains the incident wave's phase at body i's place (module isolated's shift).
  A 7 × 7 grid with R = 1.5 spacings is 9 distinct clusters of at most 9 bodies.
- **Reciprocity.** X_ij (from i's cluster) and X_ji (from j's) are solved with different
  neighbours and differ slightly; the model takes their mean, so A and B stay symmetric.
- **What it leaves out** is the waves that bodies further than R scatter and radiate; its size
  is :func:`cut_error` against the full solve (``benchmarks/interaction_cutoff.py``). A cut
  matrix B(ω) need not stay positive semi-definite (the couplings it drops are part of what
  makes it so), which the dataset records (``cut_min_damping_eig``) and the radiation fit's
  passivity enforcement then has to absorb.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ...errors import HydroError
from .solve import compute
from ..mesh.geometry import BemBody
from .isolated import merge, shifted

_PAIR = ("radiating_dof", "influenced_dof")
_RADIATION = ("added_mass", "radiation_damping", "added_mass_zero", "added_mass_inf")


def compute_within(bodies, radius: float, **kwargs) -> xr.Dataset:
    """:func:`mbcontrol.hydro.compute` once per distinct cluster (bodies within ``radius`` m of
    one body, cached on its own), assembled into one dataset of all ``bodies``: body i's rows
    from its own cluster, couplings beyond ``radius`` zero, radiation matrices symmetrised.
    Keyword arguments as compute's. attrs: interaction_radius (m), distinct_clusters,
    largest_cluster, cut_min_damping_eig (the least eigenvalue of B(ω) over all ω, over the
    largest: negative when the cut made the data non-passive)."""
    if not radius > 0:
        raise HydroError(f"compute_within: interaction_radius {radius!r} m; expected a positive length")
    if any(not b.dofs for b in bodies):
        raise HydroError("compute_within: [hydro] interaction_radius with obstacles; expected bodies "
                         "only (an obstacle would have to join every cluster it reaches)")
    centres = np.array([_centre(b) for b in bodies])
    solved, parts, clusters = {}, [], []
    for i, body in enumerate(bodies):
        near = [j for j in range(len(bodies)) if np.hypot(*(centres[j] - centres[i])) <= radius * (1 + 1e-9)]
        canonical, names = _canonical_cluster(bodies, near, centres[i])
        key = repr(canonical)
        if key not in solved:
            solved[key] = compute(canonical, **kwargs)
        ds = solved[key]
        own = [f"{names[i]}__{d}" for d in body.dofs]
        part = ds.sel(body=[names[i]], radiating_dof=own, influenced_dof=own)
        part.attrs.update({k: {names[i]: ds.attrs[k][names[i]]} for k in ("hull_panels", "lid_panels")
                           if k in ds.attrs})      # the float's own panels, not its neighbours'
        parts.append(shifted(part, body, *centres[i]))
        clusters.append((i, near, names, ds))
    out = merge(parts)
    for var in _RADIATION:
        out[var] = _with_couplings(out[var], bodies, clusters, var)
    B = out["radiation_damping"].transpose("omega", *_PAIR).values
    ev = np.linalg.eigvalsh(B)      # over the largest on all ω (near ω = 0, B is noise-sized)
    out.attrs.update(
        interaction=f"within {radius:g} m: each body solved with its neighbours (mbcontrol.hydro.bem.neighbours)",
        interaction_radius=float(radius), distinct_clusters=len(solved),
        largest_cluster=max(len(near) for _, near, _, _ in clusters),
        cut_min_damping_eig=float(ev[:, 0].min() / max(ev[:, -1].max(), 1e-300)),
        solve_seconds=float(sum(d.attrs.get("solve_seconds", 0.0) for d in solved.values())),
        cache_key=[d.attrs.get("cache_key") for d in solved.values()])
    return out


def _centre(body: BemBody) -> tuple[float, float]:
    c = body.geometry.get("center", (0.0, 0.0, 0.0))
    return float(c[0]), float(c[1])


def _canonical_cluster(bodies, near, origin):
    """(the cluster's bodies moved by -origin and named by their relative places, {index:
    name}): the same relative layout gives the same BemBodies, hence the same cache key."""
    moved = {}
    for j in near:
        b = bodies[j]
        g = dict(b.geometry)
        cx, cy, cz = (float(v) for v in g.get("center", (0.0, 0.0, 0.0)))
        g["center"] = [_round(cx - origin[0]), _round(cy - origin[1]), cz]
        cog = (_round(float(b.cog[0]) - origin[0]), _round(float(b.cog[1]) - origin[1]), float(b.cog[2]))
        moved[j] = (g, cog, b)
    order = sorted(near, key=lambda j: (moved[j][0]["center"][0], moved[j][0]["center"][1]))
    names = {j: f"n{k}" for k, j in enumerate(order)}
    canonical = [BemBody(name=names[j], geometry=moved[j][0], cog=moved[j][1], mass=float(moved[j][2].mass),
                         panel_size=float(moved[j][2].panel_size), dofs=tuple(moved[j][2].dofs))
                 for j in order]
    return canonical, names


def _round(x: float) -> float:
    """Positions to 1e-9 m, so float noise in a layout's arithmetic cannot split a cluster shape."""
    return float(np.round(x, 9)) + 0.0


def _with_couplings(da: xr.DataArray, bodies, clusters, var) -> xr.DataArray:
    """``da`` (block-diagonal, from merge) with every body's couplings to its cluster filled in
    (row i from i's cluster), then symmetrised: (X + Xᵀ) / 2."""
    da = da.transpose(..., *_PAIR)
    dofs = [str(d) for d in da["radiating_dof"].values]
    where = {d: k for k, d in enumerate(dofs)}
    data = da.values.copy()
    for i, near, names, ds in clusters:
        src = ds[var].transpose(..., *_PAIR)
        rows = [where[f"{bodies[i].name}__{d}"] for d in bodies[i].dofs]
        rows_c = [f"{names[i]}__{d}" for d in bodies[i].dofs]
        for j in near:
            if j == i:
                continue
            cols = [where[f"{bodies[j].name}__{d}"] for d in bodies[j].dofs]
            cols_c = [f"{names[j]}__{d}" for d in bodies[j].dofs]
            # layout (..., radiating = motion, influenced = force): motion j, force on i
            data[..., np.ix_(cols, rows)[0], np.ix_(cols, rows)[1]] = \
                src.sel(radiating_dof=cols_c, influenced_dof=rows_c).values
    data = 0.5 * (data + np.swapaxes(data, -1, -2))
    return da.copy(data=data)


def cut_error(full: xr.Dataset, cut: xr.Dataset, dofs=None) -> dict:
    """How far a cut dataset is from the full coupled one (both symmetrised), per quantity: the
    relative RMS over frequencies and entries sqrt(Σ|δX|²/Σ|X|²) of A(ω), B(ω), the radiation kernel
    K = B + jω(A - A∞) and the excitation (all headings), and the worst entry of K relative to
    the largest diagonal entry's modulus at that ω."""
    dofs = list(dofs) if dofs is not None else [str(d) for d in full["radiating_dof"].values]

    def mat(ds, v):     # symmetrised, as the radiation fit uses them
        x = ds[v].sel(radiating_dof=dofs, influenced_dof=dofs).transpose(..., *_PAIR).values
        return 0.5 * (x + np.swapaxes(x, -1, -2))

    w = full["omega"].values[:, None, None]
    K = {k: mat(ds, "radiation_damping") + 1j * w * (mat(ds, "added_mass") - mat(ds, "added_mass_inf")[None])
         for k, ds in (("full", full), ("cut", cut))}
    ref = np.abs(np.einsum("kii->ki", K["full"])).max(axis=1)[:, None, None]

    def rel(a, b):
        return float(np.sqrt(np.sum(np.abs(a - b) ** 2) / np.sum(np.abs(b) ** 2)))

    def exc(ds):
        return ds["excitation_force"].sel(influenced_dof=dofs).values

    return {"added_mass": rel(mat(cut, "added_mass"), mat(full, "added_mass")),
            "radiation_damping": rel(mat(cut, "radiation_damping"), mat(full, "radiation_damping")),
            "kernel": rel(K["cut"], K["full"]),
            "kernel_worst_entry": float(np.max(np.abs(K["cut"] - K["full"]) / ref)),
            "excitation": rel(exc(cut), exc(full))}
