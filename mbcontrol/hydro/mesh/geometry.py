"""Bodies for the BEM solver and meshes of their immersed part.

Inputs are in the n-frame (NED: x forward, y starboard, z down, origin on the undisturbed
free surface). Capytaine works in a z-up frame (x forward, y port, z up) with the same origin;
a point maps between the two with diag(1, -1, -1). All lengths in m, masses in kg.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mbcontrol.errors import HydroError

from .revolution import check_profile, revolution_mesh

LOG = logging.getLogger(__name__)
RIGID_DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
GEOMETRY_TYPES = ("box", "cylinder", "sphere", "revolution", "mesh")
NED_TO_ZUP = np.diag([1.0, -1.0, -1.0])  # its own inverse


@dataclass(frozen=True)
class BemBody:
    """One rigid body for :func:`mbcontrol.hydro.compute`.

    Attributes
    ----------
    name : body name, used in DOF names ``<name>__<Dof>`` (no ``__`` or ``.`` inside).
    geometry : one of
        ``{"type": "box", "size": [Lx, Ly, Lz], "center": [x, y, z]}``,
        ``{"type": "cylinder", "radius": r, "length": L, "center": [...], "axis": "z"|"x"|"y"}``,
        ``{"type": "sphere", "radius": r, "center": [...]}``,
        ``{"type": "revolution", "profile": [[r, z], ...], "center": [...]}`` (a polyline from
        the top to the keel, z down from the centre, revolved about the vertical axis through
        the centre: :mod:`.revolution`),
        ``{"type": "mesh", "file": path, "axes": "z_up"|"ned"}``.
        Coordinates in the n-frame (NED) at rest, m; "center" is the geometric centre.
        Mesh files are read with ``capytaine.load_mesh`` (STL through meshio); their vertices
        are taken as z-up (x forward, y port, the convention of GDF/Nemoh/HAMS/STL files)
        unless ``"axes": "ned"``; an optional ``"center"`` (NED, m) places the mesh's own
        origin in the n-frame (a mesh drawn about its body's CoG, say), default the origin.
    cog : centre of gravity in the n-frame (NED), m.
    mass : kg; enters the hydrostatic stiffness (gravity term about the CoG).
    panel_size : target panel edge length, m.
    dofs : rigid DOFs to solve for, a subset of Surge, Sway, Heave, Roll, Pitch, Yaw. Empty: an
        obstacle (a structure fixed to ground), in the BEM without DOFs of its own; its mass is
        not used (0 allowed) and its panels are bisected to ``panel_size`` (:mod:`.obstacles`).
    """

    name: str
    geometry: dict
    cog: tuple
    mass: float
    panel_size: float
    dofs: tuple = field(default=RIGID_DOFS)


def _vec3(body: str, fieldname: str, value) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        v = np.array([])
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise HydroError(f"body '{body}': {fieldname} = {value!r}; expected 3 finite numbers (m, NED)")
    return v


def _positive(body: str, fieldname: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = float("nan")
    if not (math.isfinite(x) and x > 0):
        raise HydroError(f"body '{body}': {fieldname} = {value!r}; expected a finite number > 0")
    return x


def validate_body(body: BemBody) -> None:
    """Check every field of ``body``; raise HydroError naming the body and the field."""
    name = body.name
    if not isinstance(name, str) or not name or "__" in name or "." in name or name.strip() != name:
        raise HydroError(f"body name {name!r}: expected a non-empty string without '__', '.' or spaces at the ends")
    _vec3(name, "cog", body.cog)
    dofs = tuple(body.dofs)
    if dofs:                     # an obstacle (no DOFs) has no dynamics: its mass is not used
        _positive(name, "mass", body.mass)
    _positive(name, "panel_size", body.panel_size)
    if len(set(dofs)) != len(dofs) or not set(dofs) <= set(RIGID_DOFS):
        raise HydroError(f"body '{name}': dofs = {dofs!r}; expected distinct names among {RIGID_DOFS} "
                         "(none for an obstacle)")
    g = body.geometry
    if not isinstance(g, dict) or g.get("type") not in GEOMETRY_TYPES:
        got = g.get("type") if isinstance(g, dict) else g
        raise HydroError(f"body '{name}': geometry.type = {got!r}; expected one of {GEOMETRY_TYPES}")
    kind = g["type"]
    if kind == "box":
        size = _vec3(name, "geometry.size", g.get("size"))
        if np.any(size <= 0):
            raise HydroError(f"body '{name}': geometry.size = {list(size)}; expected three lengths > 0 (m)")
        _vec3(name, "geometry.center", g.get("center"))
    elif kind == "cylinder":
        _positive(name, "geometry.radius", g.get("radius"))
        _positive(name, "geometry.length", g.get("length"))
        _vec3(name, "geometry.center", g.get("center"))
        if g.get("axis", "z") not in ("x", "y", "z"):
            raise HydroError(f"body '{name}': geometry.axis = {g.get('axis')!r}; expected 'x', 'y' or 'z'")
    elif kind == "sphere":
        _positive(name, "geometry.radius", g.get("radius"))
        _vec3(name, "geometry.center", g.get("center"))
    elif kind == "revolution":
        _vec3(name, "geometry.center", g.get("center", (0.0, 0.0, 0.0)))
        check_profile(name, g)
    else:
        f = g.get("file")
        if not f or not Path(f).is_file():
            raise HydroError(f"body '{name}': geometry.file = {f!r}; expected an existing mesh file")
        if g.get("axes", "z_up") not in ("z_up", "ned"):
            raise HydroError(f"body '{name}': geometry.axes = {g.get('axes')!r}; expected 'z_up' or 'ned'")


def _n(length: float, h: float, even: bool = False, multiple: int = 1) -> int:
    """Number of panels along ``length`` for a target size ``h`` (at least 1, or 2 if even)."""
    n = max(1, math.ceil(length / h - 1e-9))
    step = 2 * multiple if even else multiple
    return max(step, step * math.ceil(n / step))


def _remove_waterplane_faces(mesh):
    """Drop horizontal faces lying on z = 0: they are a deck, not wetted hull."""
    hull, _deck = mesh.extract_lid(z=0.0)
    return hull


def hull_mesh(body: BemBody):
    """Mesh of the immersed hull of ``body`` in Capytaine's z-up frame (no lid).

    Returns ``(mesh, symmetric, waterplane)``: ``symmetric`` is True when the mesh is
    mirror-symmetric about the xz plane (y = 0), so the solver may use a ReflectionSymmetricMesh;
    ``waterplane`` is an exact lid mesh (box, vertical cylinder or revolution piercing the
    surface) or None.
    Raises HydroError if nothing of the body is below the free surface.
    """
    import capytaine as cpt

    validate_body(body)
    g, h = body.geometry, float(body.panel_size)
    kind, waterplane = g["type"], None
    if kind != "mesh":
        c = NED_TO_ZUP @ np.asarray(g.get("center", (0.0, 0.0, 0.0)), dtype=float)
    if kind == "box":
        lx, ly, lz = (float(s) for s in g["size"])
        bottom, top = c[2] - lz / 2, min(c[2] + lz / 2, 0.0)
        if top - bottom <= 1e-9 * lz:
            raise HydroError(f"body '{body.name}': geometry (box) lies entirely above the free surface "
                             f"(NED z range {-c[2] - lz / 2:g}..{-c[2] + lz / 2:g} m); expected part of it at z > 0")
        hi = top - bottom
        nx, ny = _n(lx, h), _n(ly, h, even=True)
        # Mesh only the wetted part: panel edges then sit exactly on the waterline.
        mesh = cpt.mesh_parallelepiped(
            size=(lx, ly, hi), center=(c[0], c[1], bottom + hi / 2), resolution=(nx, ny, _n(hi, h)),
            missing_sides={"top"} if c[2] + lz / 2 > 0 else set(), name=body.name)
        if c[2] + lz / 2 > 0:  # the whole waterplane, nodes matching the hull's waterline nodes
            waterplane = cpt.mesh_rectangle(size=(ly, lx), center=(c[0], c[1], 0.0), resolution=(ny, nx),
                                            normal=(0.0, 0.0, -1.0), name=f"lid of {body.name}")
    elif kind == "cylinder" and g.get("axis", "z") == "z":
        r, length = float(g["radius"]), float(g["length"])
        bottom, top = c[2] - length / 2, min(c[2] + length / 2, 0.0)
        if top - bottom <= 1e-9 * length:
            raise HydroError(f"body '{body.name}': geometry (vertical cylinder) lies entirely above the free surface; "
                             "expected part of it at NED z > 0")
        li = top - bottom
        nr, nt = _n(r, h), _n(2 * math.pi * r, h, even=True)
        mesh = cpt.mesh_vertical_cylinder(length=li, radius=r, center=(c[0], c[1], bottom + li / 2),
                                          resolution=(nr, nt, _n(li, h)), name=body.name)
        if c[2] + length / 2 > 0:
            mesh = _remove_waterplane_faces(mesh)
            # mesh_disk's rim nodes sit half a step from the cylinder's: rotate them onto each other
            waterplane = cpt.mesh_disk(radius=r, normal=(0.0, 0.0, -1.0), resolution=(nr, nt)).rotated_z(
                math.pi / nt).translated((c[0], c[1], 0.0), name=f"lid of {body.name}")
    elif kind == "cylinder":
        r, length = float(g["radius"]), float(g["length"])
        # ntheta a multiple of 4 puts a ring of nodes at z = 0 when the axis lies on the waterline.
        mesh = cpt.mesh_horizontal_cylinder(
            length=length, radius=r, center=(0.0, 0.0, 0.0),
            resolution=(_n(r, h), _n(2 * math.pi * r, h, multiple=4), _n(length, h)), name=body.name)
        if g["axis"] == "y":
            mesh = mesh.rotated_z(math.pi / 2)
        mesh = mesh.translated(c, name=body.name)
        if abs(c[2]) < r:  # waterplane: a rectangle spanning the hull's waterline nodes
            wl = mesh.immersed_part().vertices
            across = 0 if g["axis"] == "y" else 1  # horizontal direction normal to the axis
            half = np.abs(wl[np.abs(wl[:, 2]) < 1e-9, across] - c[across]).max()
            n_w, n_l = _n(2 * half, h, even=True), _n(length, h)
            size, res = ((length, 2 * half), (n_l, n_w)) if g["axis"] == "y" else ((2 * half, length), (n_w, n_l))
            waterplane = cpt.mesh_rectangle(size=size, center=(c[0], c[1], 0.0), resolution=res,
                                            normal=(0.0, 0.0, -1.0), name=f"lid of {body.name}")
    elif kind == "revolution":   # meshed wet part only; exact, volume-preserving waterplane lid
        mesh, waterplane = revolution_mesh(body.name, g, h)
    elif kind == "sphere":
        r = float(g["radius"])
        mesh = cpt.mesh_sphere(radius=r, center=tuple(c),
                               resolution=(_n(math.pi * r, h, even=True), _n(2 * math.pi * r, h, even=True)),
                               name=body.name)
    else:
        try:
            mesh = cpt.load_mesh(str(g["file"])).merged()
        except Exception as exc:
            raise HydroError(f"body '{body.name}': geometry.file = {g['file']!r} could not be read as a mesh "
                             f"({type(exc).__name__}: {exc})") from exc
        if g.get("axes", "z_up") == "ned":
            mesh = mesh.rotated_with_matrix(NED_TO_ZUP)  # a rotation (det +1): normals stay outward
        origin = NED_TO_ZUP @ np.asarray(g.get("center", (0.0, 0.0, 0.0)), dtype=float)
        if np.any(origin != 0.0):                        # a mesh drawn in its body's own frame
            mesh = mesh.translated(tuple(origin))
    mesh = mesh.immersed_part()
    if mesh.nb_faces == 0 or not mesh.volume > 0:
        raise HydroError(f"body '{body.name}': geometry ({kind}) has no immersed volume; "
                         "expected part of the body below the free surface (NED z > 0)")
    symmetric = kind != "mesh" and abs(c[1]) < 1e-12
    return mesh.copy(name=body.name), symmetric, waterplane


def lid_mesh(hull, panel_size: float, waterplane=None):
    """Lid on the interior waterplane (z = 0) of ``hull``, or None for a submerged body.

    The lid suppresses irregular frequencies (extended boundary condition). ``waterplane`` (exact,
    from :func:`hull_mesh`) is used when given; otherwise Capytaine's ``generate_lid`` covers the
    waterplane with panels of edge about ``panel_size`` that lie fully inside the waterline.
    """
    if hull.vertices[:, 2].max() < -1e-9:
        return None
    if waterplane is not None:
        return waterplane
    # generate_lid keeps only candidate panels fully inside the waterline; on a coarse hull that can
    # leave most of the waterplane open, so refine the lid (not the hull) until it covers half of it
    awp, lid = abs(hull.waterplane_area), None
    for k in range(3):
        lid = hull.generate_lid(z=0.0, faces_max_radius=panel_size / math.sqrt(2) / 2**k)
        if lid.nb_faces and lid.faces_areas.sum() >= 0.5 * awp:
            return lid
    LOG.warning("lid of %s covers %.0f %% of the waterplane only; irregular frequencies may remain",
                hull.name, 100 * (lid.faces_areas.sum() if lid.nb_faces else 0.0) / max(awp, 1e-300))
    return lid if lid.nb_faces > 0 else None


def mirror_symmetric(mesh):
    """ReflectionSymmetricMesh about the xz plane from a mesh that is symmetric about it."""
    import capytaine as cpt

    half = mesh.clipped(origin=(0.0, 0.0, 0.0), normal=(0.0, 1.0, 0.0))  # keeps y <= 0
    return cpt.ReflectionSymmetricMesh(half, plane="xOz", name=mesh.name)
