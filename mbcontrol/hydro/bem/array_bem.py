"""BEM of an array that uses the layout's mirror planes (issue 25).

Capytaine solves a ``ReflectionSymmetricMesh`` with half the influence matrix and two half-size
solves, and a nested one (both vertical planes) with a quarter and four. A body's own mesh is
rarely symmetric about the array's planes, but the array is: in a centred grid every float has a
mirror image. :func:`symmetric_array_body` builds one FloatingBody whose hull is the quarter (or
half) of the array's panels, reflected, with each body's DOFs defined on its own faces
(``DofOnSubmesh``), so the solver sees the symmetry of the whole layout.

It applies only when it is exact: every moving body's mesh, reflected in a plane, coincides panel
for panel with a body's mesh (itself, for a body on the plane), no fixed obstacles, and each
face is owned by exactly one body. Otherwise it returns None and the bodies are solved as they
are. Frames: Capytaine's z-up, planes through the origin ("xOz": y = 0, "yOz": x = 0).
"""
from __future__ import annotations

import numpy as np

from ..mesh.geometry import NED_TO_ZUP, hull_mesh, lid_mesh

MATCH_TOL = 1e-9    # m per m of the array's extent: reflected panel centres must coincide
AXES = {"xOz": 1, "yOz": 0}   # the coordinate a plane's reflection flips


def _centres(mesh):
    return np.asarray(mesh.faces_centers, dtype=float)


def _same_panels(a, b, tol) -> bool:
    """True if the two centre sets are equal as sets (sorted lexicographically, rounded)."""
    if a.shape != b.shape:
        return False
    ka, kb = np.lexsort(np.round(a / tol).T), np.lexsort(np.round(b / tol).T)
    return bool(np.allclose(a[ka], b[kb], atol=10 * tol, rtol=0))


def _mirror_planes(bodies, hulls, extent):
    """The planes ("xOz", "yOz") the whole set of hulls is symmetric about, panel for panel."""
    planes = []
    for plane, axis in AXES.items():
        ok = True
        for i, (b, h) in enumerate(zip(bodies, hulls)):
            c = _centres(h).copy()
            c[:, axis] *= -1
            if not any(_same_panels(c, _centres(h2), MATCH_TOL * extent) and bodies[j].dofs == b.dofs
                       for j, h2 in enumerate(hulls)):
                ok = False
                break
        if ok:
            planes.append(plane)
    return planes


def _fundamental_part(mesh, centre, planes, extent):
    """The body's panels in the fundamental domain (coordinate <= 0 for every plane), or None if
    its centre lies beyond a plane; a body on a plane is clipped to its half."""
    for plane in planes:
        axis = AXES[plane]
        if centre[axis] > MATCH_TOL * extent:
            return None
        if abs(centre[axis]) <= MATCH_TOL * extent and mesh is not None:
            normal = np.zeros(3)
            normal[axis] = 1.0
            mesh = mesh.clipped(origin=(0.0, 0.0, 0.0), normal=tuple(normal))   # keeps <= 0
    return mesh


def symmetric_array_body(bodies, lid: bool):
    """(FloatingBody of all ``bodies`` on the array's mirror planes, planes used) or None.

    bodies : the BemBodies (all moving: an obstacle among them returns None). The body's DOFs are
    named ``<body>__<dof>`` in the order of the bodies and of Capytaine's rigid DOFs."""
    import capytaine as cpt
    from capytaine.bodies.dofs import DofOnSubmesh, RotationDof, TranslationDof

    if len(bodies) < 2 or any(not b.dofs for b in bodies) or any(b.geometry["type"] == "mesh" for b in bodies):
        return None
    built = [hull_mesh(b) for b in bodies]
    hulls = [h for h, _, _ in built]
    centres = [NED_TO_ZUP @ np.asarray(b.cog, dtype=float) for b in bodies]
    allc = np.vstack([_centres(h) for h in hulls])
    extent = float(np.ptp(allc, axis=0).max()) or 1.0
    planes = _mirror_planes(bodies, hulls, extent)
    if not planes:
        return None
    parts, lids = [], []
    for b, (hull, _, waterplane), c in zip(bodies, built, centres):
        mc = np.mean(_centres(hull), axis=0)           # the mesh's own centre decides its side
        part = _fundamental_part(hull, mc, planes, extent)
        if part is None:
            continue
        parts.append(part)
        if lid:
            lm = lid_mesh(hull, b.panel_size, waterplane)
            lm = _fundamental_part(lm, mc, planes, extent) if lm is not None else None
            if lm is not None and lm.nb_faces:
                lids.append(lm)

    def reflected(meshes):
        m = meshes[0].join_meshes(*meshes[1:]) if len(meshes) > 1 else meshes[0]
        for plane in sorted(planes, key=lambda p: p != "yOz"):     # x = 0 inside, y = 0 outside
            m = cpt.ReflectionSymmetricMesh(half=m, plane=plane)
        return m
    mesh = reflected(parts)
    lid_full = reflected(lids) if lids else None
    if mesh.nb_faces != sum(h.nb_faces for h in hulls):
        return None                                    # clipping cut panels: not the same mesh
    owner = _owners(_centres(mesh), hulls, extent)
    if owner is None:
        return None
    dofs = {}
    for k, (b, c) in enumerate(zip(bodies, centres)):
        mask = owner == k
        for d in ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"):
            if d not in b.dofs:
                continue
            axis = np.eye(3)[("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw").index(d) % 3]
            base = TranslationDof(direction=axis) if d in ("Surge", "Sway", "Heave") else \
                RotationDof(rotation_center=c, direction=axis)
            dofs[f"{b.name}__{d}"] = DofOnSubmesh(base, mask)
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid_full, dofs=dofs, name="array")
    return body, planes


def _owners(face_centres, hulls, extent):
    """Index of the hull each face belongs to (its centre inside that hull's bounding box), or
    None if a face has no owner or more than one, or a hull's count differs."""
    tol = 1e-6 * extent
    inside = np.zeros((face_centres.shape[0], len(hulls)), bool)
    for k, h in enumerate(hulls):
        v = np.asarray(h.vertices, dtype=float)
        lo, hi = v.min(axis=0) - tol, v.max(axis=0) + tol
        inside[:, k] = np.all((face_centres >= lo) & (face_centres <= hi), axis=1)
    if np.any(inside.sum(axis=1) != 1):
        return None
    owner = np.argmax(inside, axis=1)
    if any(np.count_nonzero(owner == k) != h.nb_faces for k, h in enumerate(hulls)):
        return None
    return owner
