"""Tests of mbcontrol.hydro.large_angle: nonlinear hydrostatic restoring of primitives.

References are independent of the fibre quadrature under test:
- sphere: slice integrals of disks (scipy quad), not the cap formulas;
- box: the convex polyhedron box ∩ {z >= 0} (corners inside plus edge crossings), volume from
  scipy's ConvexHull, centroid from tetrahedra fanned from an interior point;
- cylinder: slices across the axis, each an exact circular segment (area and first moment in
  closed form), integrated along the axis with scipy quad; cross-checked once against a Capytaine
  mesh (whose polygonal section is known to shrink the volume by sin(2pi/m)/(2pi/m));
- linear stiffness: closed-form waterplane integrals (derived in test_small_angle_stiffness).
Tolerances quote the measured value in a comment. Frames: NED, water at z > 0.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from mbcontrol.errors import HydroError
from mbcontrol.hydro.large_angle import DEFAULT_N, buoyancy, fibres, potential

RHO, G = 1025.0, 9.81
BOX = {"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.0, 0.0, 0.0]}
VCYL = {"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.0, 0.0, 0.0], "axis": "z"}
HCYL = {"type": "cylinder", "radius": 1.0, "length": 3.0, "center": [0.0, 0.0, 0.0], "axis": "x"}


# ------------------------------------------------------------------ independent references
def posed_centre(geometry, cog_rest, R, r_cog):
    """Geometric centre of the posed primitive, n-frame (m)."""
    return np.asarray(r_cog, float) + R @ (np.asarray(geometry["center"], float) - np.asarray(cog_rest, float))


def box_reference(geometry, cog_rest, R, r_cog):
    """(V, centre of buoyancy) of box ∩ {z >= 0} by convex-polyhedron clipping."""
    half = np.asarray(geometry["size"], float) / 2
    c = posed_centre(geometry, cog_rest, R, r_cog)
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    corners = c + (signs * half) @ R.T
    pts = [p for p in corners if p[2] >= 0]
    for a in range(8):
        for b in range(a + 1, 8):
            if np.sum(signs[a] != signs[b]) == 1:          # an edge
                za, zb = corners[a, 2], corners[b, 2]
                if za * zb < 0:
                    t = za / (za - zb)
                    pts.append(corners[a] + t * (corners[b] - corners[a]))
    if len(pts) < 4:
        return 0.0, c
    pts = np.array(pts)
    try:
        hull = ConvexHull(pts)
    except Exception:                                      # flat (coplanar) wet part
        return 0.0, c
    inner = pts.mean(axis=0)
    vol, mom = 0.0, np.zeros(3)
    for simplex in hull.simplices:
        a, b, d = pts[simplex]
        v = abs(np.linalg.det(np.array([a - inner, b - inner, d - inner]))) / 6
        vol += v
        mom += v * (inner + a + b + d) / 4
    return hull.volume, mom / vol


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
    return math.pi * geometry["radius"] ** 2 * geometry["length"]


def size(geometry):
    """Characteristic size (largest dimension), m."""
    if geometry["type"] == "box":
        return float(max(geometry["size"]))
    return max(2 * geometry["radius"], geometry["length"])


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
