"""Meshes of obstacles: fixed structures (a flap's base, a breakwater, a tank wall) that the BEM
sees but that have no DOFs of their own.

An obstacle scatters the incident wave and the waves the moving bodies radiate, so it changes
their excitation and radiation; it never adds states to a plant. Three things differ from a
moving body's hull (all in Capytaine's z-up frame, lengths in m):

- fixed structures come as coarse CAD exports (WEC-Sim's OSWEC base is 12 triangles 18 m
  long): their panels are bisected down to the scene's panel size (:func:`refine`), since a
  constant-panel BEM enforces the boundary condition at one point per panel;
- faces lying on the sea bed are dropped (:func:`drop_seabed_faces`): the finite-depth Green
  function already makes the sea bed a wall, and panels on it would double it;
- where an obstacle and a moving body touch, :func:`remove_contact_faces` looks at every face
  whose collocation point (its centre) lies on a facing panel of the other mesh. Coincident
  faces (a flat-bottomed flap on its base: opposite normals) are wetted on neither side and
  are removed from both, leaving one closed surface instead of two coincident sheets (a
  singular BEM system). At a line contact (a rounded bottom on a flat base, as WEC-Sim's
  OSWEC) a panel whose centre falls on the contact line makes Capytaine's Green function
  return NaN; it is wetted on both sides of the line, so it is bisected (its children's
  centres lie off the line) rather than removed, which would open a leak under the body.
"""
from __future__ import annotations

import numpy as np

from mbcontrol.errors import HydroError


def _triangles(mesh, keep):
    """Faces of ``mesh`` not in ``keep`` as triangles (n, 3, 3); quads split along 0-2."""
    v, out = mesh.vertices, []
    for i, f in enumerate(mesh.faces):
        if keep[i]:
            continue
        out.append(v[[f[0], f[1], f[2]]])
        if f[3] != f[2]:                   # a quad (triangles repeat their last vertex)
            out.append(v[[f[0], f[2], f[3]]])
    return np.array(out).reshape(-1, 3, 3)


def _edges(tris):
    """Edge lengths (n, 3): edge k runs from vertex k to vertex k+1."""
    return np.linalg.norm(np.roll(tris, -1, axis=1) - tris, axis=2)


def refine(mesh, panel_size: float, name=None):
    """``mesh`` with every face that has an edge longer than √2 ``panel_size`` (m: the diagonal
    of a square panel) split by longest-edge bisection into triangles; smaller faces are kept.

    Bisection keeps each child's normal and leaves hanging nodes, which a constant-panel BEM
    does not need to avoid; unlike a uniform split it does not keep a CAD sliver's aspect ratio.
    """
    panel_size = np.sqrt(2.0) * panel_size
    fv = mesh.vertices[mesh.faces]                          # (n, 4, 3)
    size = np.linalg.norm(np.roll(fv, -1, axis=1) - fv, axis=2).max(axis=1)
    keep = size <= panel_size
    tris, done = _triangles(mesh, keep), []
    while len(tris):
        small = _edges(tris).max(axis=1) <= panel_size
        done.append(tris[small])
        tris = _bisect(tris[~small])
    return _rebuild(mesh, keep, done, name)


def _bisect(tris):
    """Each triangle (n, 3, 3) split in two at the midpoint of its longest edge (2n, 3, 3)."""
    k = _edges(tris).argmax(axis=1)
    # rotate each triangle so its longest edge runs from vertex 0 to vertex 1
    tris = np.take_along_axis(tris, (np.arange(3)[None, :] + k[:, None])[:, :, None] % 3, axis=1)
    mid = 0.5 * (tris[:, 0] + tris[:, 1])
    return np.concatenate([np.stack([tris[:, 0], mid, tris[:, 2]], axis=1),
                           np.stack([mid, tris[:, 1], tris[:, 2]], axis=1)])


def _rebuild(mesh, keep, done, name=None):
    """A Mesh of the faces of ``mesh`` flagged in ``keep`` and the triangles in ``done``."""
    import capytaine as cpt

    faces = [list(f) for f in mesh.faces[keep]]
    faces = [f[:3] if f[3] == f[2] else f for f in faces]
    verts = [mesh.vertices]
    n0 = len(mesh.vertices)
    for t in (np.concatenate(done) if done else np.zeros((0, 3, 3))):
        faces.append([n0, n0 + 1, n0 + 2])
        verts.append(t)
        n0 += 3
    return cpt.Mesh(np.concatenate(verts), faces, name=name or mesh.name)


def drop_seabed_faces(mesh, depth: float, name: str):
    """``mesh`` without the faces lying on the sea bed (z = -depth, m); error if any part of it
    lies below the sea bed."""
    tol = 1e-6 * max(depth, 1.0)
    if mesh.vertices[:, 2].min() < -depth - tol:
        raise HydroError(f"obstacle '{name}': geometry reaches below the sea bed (depth {depth} m, "
                         f"lowest point {-mesh.vertices[:, 2].min():.4g} m); expected it within the water")
    z = mesh.vertices[mesh.faces][:, :, 2]
    on_bed = np.all(np.abs(z + depth) <= tol, axis=1)
    if not on_bed.any():
        return mesh
    if on_bed.all():
        raise HydroError(f"obstacle '{name}': every face lies on the sea bed; expected a structure "
                         "standing in the water")
    return mesh.extract_faces(np.flatnonzero(~on_bed), name=mesh.name)


def _inside(points, mesh, tol):
    """For each point (n, 3): whether it lies on a face of ``mesh`` (within ``tol`` of the face's
    plane, inside its edges). Also returns that face's normal (zeros where none)."""
    fv = mesh.vertices[mesh.faces]                          # (m, 4, 3), triangles repeat a vertex
    nrm, ctr = mesh.faces_normals, mesh.faces_centers
    d = points[:, None, :] - ctr[None, :, :]                # (n, m, 3)
    near = np.abs(np.einsum("nmk,mk->nm", d, nrm)) <= tol
    ok = near.copy()
    for k in range(4):
        a, b = fv[:, k], fv[:, (k + 1) % 4]
        cross = np.cross((b - a)[None], points[:, None, :] - a[None])
        ok &= np.einsum("nmk,mk->nm", cross, nrm) >= -tol * np.linalg.norm(b - a, axis=1)[None]
    hit = ok.any(axis=1)
    normal = np.where(hit[:, None], nrm[ok.argmax(axis=1)], 0.0)
    return hit, normal


def _contacts(moving, obstacles, tol):
    """Per mesh (moving, then obstacles): masks of coincident and of touching faces."""
    meshes = moving + obstacles
    coincident = [np.zeros(m.nb_faces, bool) for m in meshes]
    touching = [np.zeros(m.nb_faces, bool) for m in meshes]
    for i, m in enumerate(moving):
        for j, o in enumerate(obstacles, start=len(moving)):
            for k, (m1, m2) in ((i, (m, o)), (j, (o, m))):
                hit, normal = _inside(m1.faces_centers, m2, tol)
                cos = np.einsum("nk,nk->n", normal, m1.faces_normals)
                coincident[k] |= hit & (cos < -0.99)
                touching[k] |= hit & (cos < 0.0) & (cos >= -0.99)
    return coincident, touching


def remove_contact_faces(moving, obstacles, tol: float, rounds: int = 6):
    """Where obstacles touch moving bodies: coincident faces removed from both, faces whose
    centre lies on a facing panel at an angle (a line contact) bisected until none does.

    ``moving``, ``obstacles``: lists of capytaine Meshes; ``tol``: m. Returns the two lists and
    the number of faces removed per mesh (same order); faces still touching after ``rounds``
    bisections are removed too.
    """
    moving, obstacles = list(moving), list(obstacles)
    n = len(moving)
    for _ in range(rounds):
        _, touching = _contacts(moving, obstacles, tol)
        if not any(t.any() for t in touching):
            break
        meshes = [m if not t.any() else _rebuild(m, ~t, [_bisect(_triangles(m, ~t))])
                  for m, t in zip(moving + obstacles, touching)]
        moving, obstacles = meshes[:n], meshes[n:]
    coincident, touching = _contacts(moving, obstacles, tol)
    drops = [c | t for c, t in zip(coincident, touching)]
    drop_m, drop_o = drops[:n], drops[n:]
    out = []
    for meshes, drops in ((moving, drop_m), (obstacles, drop_o)):
        kept = []
        for m, d in zip(meshes, drops):
            if d.all():
                raise HydroError(f"body '{m.name}': every face touches another body; expected a wetted surface")
            kept.append(m.extract_faces(np.flatnonzero(~d), name=m.name) if d.any() else m)
        out.append(kept)
    return out[0], out[1], [int(d.sum()) for d in drop_m + drop_o]
