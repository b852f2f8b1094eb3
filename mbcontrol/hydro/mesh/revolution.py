"""Panel meshes of bodies of revolution (``geometry = {type = "revolution", profile = ...}``).

The immersed part of the profile (:func:`mbcontrol.scene.immersed_profile`, NED, m) is cut
into segments of about the panel size and revolved in ``n`` steps about the vertical axis
through the geometry's centre, in Capytaine's z-up frame. The radii of the nodes are scaled by
``sqrt((2 pi / n) / sin(2 pi / n))``: the n-gon then has the area of the circle, so the mesh
holds the profile's exact volume and waterplane area (pi r^2 per ring, frusta in between)
whatever ``n``, and ``mass = "displaced"`` (rho x the closed-form volume) floats on the
mesh's own buoyancy. An inscribed n-gon would lose (2 pi / n)^2 / 6 of both: 2.5 % at n = 16.
"""
from __future__ import annotations

import math

import numpy as np

from mbcontrol.errors import HydroError
from mbcontrol.scene import immersed_profile, profile_problem


def check_profile(name: str, geometry: dict) -> None:
    """Raise HydroError naming the body and the field when the profile is not valid."""
    problem = profile_problem(geometry.get("profile"))
    if problem is not None:
        raise HydroError(f"body '{name}': geometry.{problem[0]}: {problem[1]}")


def azimuthal_panels(r_max: float, h: float) -> int:
    """Panels around the axis for panel size ``h``: a multiple of 4 (at least 8), so nodes lie
    on both vertical mirror planes (x = 0 and y = 0) and the mesh splits cleanly on them."""
    n = max(8, math.ceil(2 * math.pi * r_max / h - 1e-9))
    return 4 * math.ceil(n / 4)


def equal_area_scale(n: int) -> float:
    """Radius factor that gives a regular n-gon the area of its circle (> 1)."""
    t = 2 * math.pi / n
    return math.sqrt(t / math.sin(t))


def _subdivide(points: np.ndarray, h: float) -> np.ndarray:
    """The polyline ``points`` (r, z) with each segment cut into pieces of at most about ``h``."""
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:]):
        k = max(1, math.ceil(float(np.hypot(*(b - a))) / h - 1e-9))
        out.append(a + (b - a) * (np.arange(1, k + 1)[:, None] / k))
    return np.vstack(out)


def _revolve(rz_up: np.ndarray, n: int, centre_xy, name: str, flip: bool = False):
    """Capytaine Mesh of the polyline ``rz_up`` (r, z z-up) revolved in ``n`` steps. Walking the
    polyline downwards gives outward normals; ``flip`` reverses them. Panels touching the axis
    are triangles."""
    import capytaine as cpt

    theta = 2 * math.pi * np.arange(n) / n
    scale = equal_area_scale(n)
    vertices, index = [], []
    for r, z in rz_up:                  # one vertex on the axis, n on a ring elsewhere
        start = len(vertices)
        if r == 0:
            vertices.append((centre_xy[0], centre_xy[1], z))
            index.append([start] * n)
        else:
            ring = scale * r
            vertices += [(centre_xy[0] + ring * c, centre_xy[1] + ring * s, z)
                         for c, s in zip(np.cos(theta), np.sin(theta))]
            index.append(list(range(start, start + n)))
    faces = []
    for upper, lower in zip(index[:-1], index[1:]):
        for j in range(n):
            k = (j + 1) % n
            quad = [upper[j], lower[j], lower[k], upper[k]]
            if flip:
                quad = quad[::-1]
            face = [v for i, v in enumerate(quad) if v not in quad[:i]]   # drop an axis repeat
            if len(face) >= 3:
                faces.append(face)
    return cpt.Mesh(np.array(vertices), faces, name=name)


def revolution_mesh(name: str, geometry: dict, panel_size: float):
    """(hull mesh of the immersed part, z-up; exact waterplane lid or None) of a revolution
    geometry dict (``profile`` [[r, z], ...] in m, NED, about ``center``). Raises HydroError if
    nothing is below the free surface."""
    check_profile(name, geometry)
    c = np.asarray(geometry.get("center", (0.0, 0.0, 0.0)), dtype=float)
    wet, r_wl = immersed_profile(geometry["profile"], float(c[2]))
    if len(wet) < 2 or not np.any(np.diff(wet[:, 1]) > 0):
        raise HydroError(f"body '{name}': geometry (revolution) lies entirely above the free surface "
                         f"(profile z + center z <= 0 everywhere); expected part of it at NED z > 0")
    h, axis = float(panel_size), (c[0], -c[1])                  # the axis in z-up x, y (y to port)
    n = azimuthal_panels(float(wet[:, 0].max()), h)
    nodes = _subdivide(wet, h) * np.array([1.0, -1.0])          # NED depth -> z-up height
    hull = _revolve(nodes, n, axis, name)
    lid = None
    if r_wl is not None:                # the waterplane disc, rings on the hull's waterline nodes
        disc = _subdivide(np.array([[0.0, 0.0], [r_wl, 0.0]]), h)
        lid = _revolve(disc, n, axis, f"lid of {name}", flip=True)   # normal down, as the others
    return hull, lid
