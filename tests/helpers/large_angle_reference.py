"""Independent references for the large-angle hydrostatics tests: clipped convex hulls for boxes,
slices for cylinders, the spherical cap in closed form, poses and drafts."""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from mbcontrol.hydro.mesh.large_angle import buoyancy

RHO, G = 1025.0, 9.81
BOX = {"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.0, 0.0, 0.0]}
VCYL = {"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.0, 0.0, 0.0], "axis": "z"}
HCYL = {"type": "cylinder", "radius": 1.0, "length": 3.0, "center": [0.0, 0.0, 0.0], "axis": "x"}
# every primitive and pose family, for the checks that hold for any geometry
ALL = [BOX, VCYL, HCYL, {**HCYL, "axis": "y"}, {"type": "sphere", "radius": 1.0, "center": [0.2, 0.0, 0.1]},
       {"type": "box", "size": [4.0, 2.0, 0.5], "center": [1.0, 0.0, 0.1]}]


# ------------------------------------------------------------------ independent references
def posed_centre(geometry, cog_rest, R, r_cog):
    """Geometric centre of the posed primitive, n-frame (m)."""
    return np.asarray(r_cog, float) + R @ (np.asarray(geometry["center"], float) - np.asarray(cog_rest, float))


def clipped_hull(corners, edges):
    """(V, centroid) of the convex polyhedron with these corners (n-frame) and edges, ∩ {z >= 0}.

    Vertices of the wet part: corners with z >= 0 plus edge crossings of z = 0; volume by
    scipy's ConvexHull, centroid by tetrahedra fanned from an interior point.
    """
    pts = [p for p in corners if p[2] >= 0]
    for i, j in edges:
        za, zb = corners[i, 2], corners[j, 2]
        if za * zb < 0:
            pts.append(corners[i] + za / (za - zb) * (corners[j] - corners[i]))
    if len(pts) < 4:
        return 0.0, None
    pts = np.array(pts)
    try:
        hull = ConvexHull(pts)
    except Exception:                                      # flat (coplanar) wet part
        return 0.0, None
    inner = pts.mean(axis=0)
    vol, mom = 0.0, np.zeros(3)
    for simplex in hull.simplices:
        a, b, d = pts[simplex]
        v = abs(np.linalg.det(np.array([a - inner, b - inner, d - inner]))) / 6
        vol += v
        mom += v * (inner + a + b + d) / 4
    return hull.volume, mom / vol


def box_reference(geometry, cog_rest, R, r_cog):
    """(V, centre of buoyancy) of box ∩ {z >= 0} by convex-polyhedron clipping."""
    half = np.asarray(geometry["size"], float) / 2
    c = posed_centre(geometry, cog_rest, R, r_cog)
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(signs[a] != signs[b]) == 1]
    V, cb = clipped_hull(c + (signs * half) @ R.T, edges)
    return V, (c if cb is None else cb)


def prism_reference(geometry, cog_rest, R, r_cog, m):
    """(V, centre of buoyancy) of an m-sided prism of the same area as a cylinder, clipped."""
    r, length = float(geometry["radius"]), float(geometry["length"])
    rm = r * math.sqrt((2 * math.pi / m) / math.sin(2 * math.pi / m))  # same section area
    t = 2 * math.pi * np.arange(m) / m
    ring = np.stack([rm * np.cos(t), rm * np.sin(t)], axis=1)
    body = np.vstack([np.column_stack([ring, np.full(m, e * length / 2)]) for e in (-1, 1)])
    axis = geometry.get("axis", "z")
    body = body[:, {"z": [0, 1, 2], "x": [2, 0, 1], "y": [1, 2, 0]}[axis]]  # axis column last -> axis
    c = posed_centre(geometry, cog_rest, R, r_cog)
    edges = [(k, (k + 1) % m) for k in range(m)] + [(m + k, m + (k + 1) % m) for k in range(m)] + \
            [(k, m + k) for k in range(m)]
    V, cb = clipped_hull(c + body @ R.T, edges)
    return V, (c if cb is None else cb)


def cylinder_reference(geometry, cog_rest, R, r_cog):
    """(V, centre of buoyancy) of a posed cylinder: circular-segment slices integrated along the axis."""
    r, length = float(geometry["radius"]), float(geometry["length"])
    axis = {"x": 0, "y": 1, "z": 2}[geometry.get("axis", "z")]
    a = R[:, axis]
    c = posed_centre(geometry, cog_rest, R, r_cog)
    gp = math.sqrt(max(0.0, 1.0 - a[2] ** 2))               # |grad z| within a section plane
    if gp < 1e-12:                                         # vertical axis: sections wholly wet or dry
        lo, hi = -length / 2, length / 2
        wet = (max(lo, -c[2] / a[2]), hi) if a[2] > 0 else (lo, min(hi, -c[2] / a[2]))
        wl = max(0.0, wet[1] - wet[0])
        return math.pi * r * r * wl, c + a * (0.5 * (wet[0] + wet[1]) if wl > 0 else 0.0)
    d = (np.array([0.0, 0.0, 1.0]) - a[2] * a) / gp        # in-plane direction of increasing depth

    def xi(s):
        return min(r, max(-r, -(c[2] + s * a[2]) / gp))

    def area(s):
        x = xi(s)
        return r * r * math.acos(x / r) - x * math.sqrt(r * r - x * x)

    def first(s):                                          # ∫ ξ dA over the wet segment
        x = xi(s)
        return 2.0 / 3.0 * (r * r - x * x) ** 1.5

    pts = [] if abs(a[2]) < 1e-12 else [(-c[2] + k * r * gp) / a[2] for k in (-1, 1)]
    pts = [p for p in pts if -length / 2 < p < length / 2] or None
    opts = dict(points=pts, epsabs=1e-13, epsrel=1e-12, limit=200)
    V = quad(area, -length / 2, length / 2, **opts)[0]
    if V <= 0:
        return 0.0, c
    ms = quad(lambda s: s * area(s), -length / 2, length / 2, **opts)[0]
    md = quad(first, -length / 2, length / 2, **opts)[0]
    return V, c + (ms * a + md * d) / V


def sphere_reference(radius, zc):
    """(V, depth of the centre of buoyancy) of a sphere centred at depth zc, by disk slices."""
    lo, hi = max(0.0, zc - radius), max(0.0, zc + radius)
    if hi <= lo:
        return 0.0, zc
    area = lambda z: math.pi * (radius**2 - (z - zc) ** 2)  # noqa: E731
    V = quad(area, lo, hi, epsabs=1e-14)[0]
    return V, quad(lambda z: z * area(z), lo, hi, epsabs=1e-14)[0] / V


def reference(geometry, cog_rest, R, r_cog):
    return (box_reference if geometry["type"] == "box" else cylinder_reference)(geometry, cog_rest, R, r_cog)


def total_volume(geometry):
    if geometry["type"] == "box":
        return float(np.prod(geometry["size"]))
    if geometry["type"] == "sphere":
        return 4 / 3 * math.pi * geometry["radius"] ** 3
    return math.pi * geometry["radius"] ** 2 * geometry["length"]


def size(geometry):
    """Characteristic size (largest dimension), m."""
    if geometry["type"] == "box":
        return float(max(geometry["size"]))
    return max(2 * geometry["radius"], geometry.get("length", 0.0))


def draft_for_fraction(geometry, R, fraction):
    """CoG depth (CoG at the geometric centre) giving a wet fraction of the volume, by bisection."""
    vol, lo, hi = total_volume(geometry), -size(geometry), size(geometry)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if reference(geometry, geometry["center"], R, [0, 0, mid])[0] < fraction * vol:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def pose(roll=0.0, pitch=0.0, yaw=0.0):
    """R = Rz(yaw) Ry(pitch) Rx(roll) (body -> n-frame), angles in rad; numpy."""
    return Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_matrix()


def evaluate(geometry, cog, R, r_cog, **kw):
    return buoyancy(geometry, cog, R, r_cog, RHO, G, **kw)
