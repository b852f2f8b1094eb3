"""Bodies of revolution and immersed volumes of primitives, in closed form (no mesher).

A revolution profile is a polyline of ``(r, z)`` points in the body frame (NED: z positive
down, m), from the top to the keel, revolved about the body's z axis through the geometry's
``center``. Both ends are closed to the axis by flat discs when their radius is not 0 (a deck
on top, a flat keel below). The BEM mesher (:mod:`mbcontrol.hydro.mesh.revolution`) and
``mass = "displaced"`` use the same immersed profile from :func:`immersed_profile`, so the
mass and the mesh's buoyancy agree.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import SceneError
from .checks import _REQUIRED   # the scene readers' own marker of a required key
from .units import UnitError, to_si

# mass = "displaced" needs the immersed volume the BEM mesh will have: a box's mesh is exact,
# a revolution's is made volume-exact (mbcontrol.hydro.mesh.revolution); the faceted cylinders and
# spheres of the other primitives hold a few per mille less than their closed form
DISPLACED_KINDS = ("box", "revolution")


def profile_problem(profile) -> tuple[str, str] | None:
    """(field, what was expected) for the first fault of a profile, or None if it is valid.

    Valid: a list of at least 2 ``[r, z]`` pairs of finite numbers (m), r >= 0, z
    non-decreasing from top to keel, no two consecutive points equal, r > 0 for every point
    between the ends (an inner point on the axis would pinch the body in two), some height, no
    horizontal stretch that turns back on itself.
    """
    if not isinstance(profile, (list, tuple)) or len(profile) < 2:
        return "profile", (f"expected a list of at least 2 [r, z] points (m, z down) from the top "
                           f"to the keel, got {profile!r}")
    for i, point in enumerate(profile):
        if (not isinstance(point, (list, tuple)) or len(point) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                           and math.isfinite(v) for v in point)):
            return f"profile[{i}]", f"expected [r, z], two finite numbers (m), got {point!r}"
    r = np.array([float(p[0]) for p in profile])
    z = np.array([float(p[1]) for p in profile])
    for i in range(len(r)):
        if r[i] < 0:
            return f"profile[{i}]", f"r = {r[i]:g}; expected r >= 0 (m, the distance from the axis)"
        if 0 < i < len(r) - 1 and r[i] == 0:
            return f"profile[{i}]", ("r = 0 between the ends; expected r > 0 (only the top and keel "
                                     "points may lie on the axis)")
        if i and z[i] < z[i - 1]:
            return f"profile[{i}]", (f"z = {z[i]:g} above the previous point's {z[i - 1]:g}; expected "
                                     "z non-decreasing from the top to the keel (m, NED: z down)")
        if i and r[i] == r[i - 1] and z[i] == z[i - 1]:
            return f"profile[{i}]", f"repeats the previous point {list(profile[i])}; expected distinct points"
    if z[-1] == z[0]:
        return "profile", f"all points at z = {z[0]:g}; expected a body with height (keel below the top)"
    # a horizontal stretch that turns back (with the discs closing the ends) would be a fin of
    # zero thickness: panels on top of each other
    rc = np.concatenate([[0.0] if r[0] > 0 else [], r, [0.0] if r[-1] > 0 else []])
    zc = np.concatenate([z[:1] if r[0] > 0 else [], z, z[-1:] if r[-1] > 0 else []])
    for j in range(2, len(rc)):
        if zc[j] == zc[j - 1] == zc[j - 2] and (rc[j] - rc[j - 1]) * (rc[j - 1] - rc[j - 2]) < 0:
            i = min(max(j - (1 if r[0] > 0 else 0) - 1, 0), len(r) - 1)
            return f"profile[{i}]", (f"the profile turns back on itself at z = {zc[j]:g} (with the flat discs "
                                     "that close an end off the axis); expected a horizontal stretch to run "
                                     "one way")
    if not r.max() > 0:
        return "profile", "every point is on the axis (r = 0); expected a body with some r > 0"
    return None


def closed_profile(profile, depth: float = 0.0) -> np.ndarray:
    """(n, 2) array of (r, z) with both ends closed to the axis, z shifted by ``depth`` (m,
    the NED depth of the geometry's centre)."""
    p = np.array(profile, dtype=float).reshape(-1, 2)
    if p[0, 0] > 0:
        p = np.vstack([[0.0, p[0, 1]], p])
    if p[-1, 0] > 0:
        p = np.vstack([p, [0.0, p[-1, 1]]])
    return p + np.array([0.0, depth])


def immersed_profile(profile, depth: float = 0.0) -> tuple[np.ndarray, float | None]:
    """(the part of the closed profile at z >= 0, n-frame depth, as an (n, 2) array of (r, z);
    the waterline radius, m, or None for a submerged body or one that meets the surface on
    its axis). Empty (0, 2) when nothing is below the free surface. ``depth``: NED z of the
    geometry's centre, m. A horizontal stretch on z = 0 is deck, not hull: it is dropped."""
    p = closed_profile(profile, depth)
    if p[-1, 1] <= 0:
        return np.zeros((0, 2)), None
    if p[0, 1] > 0:
        return p, None
    k = int(np.nonzero(p[:, 1] <= 0)[0][-1])          # last point at or above the surface
    (r0, z0), (r1, z1) = p[k], p[k + 1]
    r_wl = r0 if z0 == 0 else r0 + (r1 - r0) * (0 - z0) / (z1 - z0)
    out = np.vstack([[r_wl, 0.0], p[k + 1:]])
    return out, (float(r_wl) if r_wl > 0 else None)


def revolution_volume(profile, depth: float = 0.0) -> float:
    """Immersed volume of a body of revolution, m^3: a sum of frusta, pi dz (r1^2 + r1 r2 +
    r2^2) / 3 per segment of the immersed profile."""
    p, _ = immersed_profile(profile, depth)
    if len(p) < 2:
        return 0.0
    r1, r2, dz = p[:-1, 0], p[1:, 0], np.diff(p[:, 1])
    return float(np.sum(math.pi * dz * (r1 * r1 + r1 * r2 + r2 * r2) / 3.0))


def immersed_volume(geometry) -> float:
    """Volume below the free surface (z > 0, NED) of a scene Geometry at rest, m^3.

    Raises ValueError for kinds whose BEM mesh does not hold their closed-form volume
    (see DISPLACED_KINDS): a mass from it would not float on that mesh's buoyancy.
    """
    kind = geometry.kind
    if kind == "box":
        (lx, ly, lz), cz = geometry.size, geometry.center[2]
        wet = (cz + lz / 2) - max(cz - lz / 2, 0.0)     # the depth range below z = 0
        return float(lx * ly * max(wet, 0.0))
    if kind == "revolution":
        return revolution_volume(geometry.profile, geometry.center[2])
    hint = (" (a vertical cylinder of radius R from freeboard f to draft d is type = "
            "\"revolution\", profile = [[R, -f], [R, d], [0, d]])" if kind == "cylinder" else "")
    raise SceneError(f"mass = \"displaced\" needs a geometry whose mesh holds its exact volume, "
                     f"type {' or '.join(DISPLACED_KINDS)}; got type = \"{kind}\"{hint}, or give the mass in kg")


def read_profile(r, owner: str) -> tuple[tuple[float, float], ...]:
    """``profile`` of a revolution geometry table (a scene Reader): [[r, z], ...], numbers in m
    or length strings ("60 mm"), ``{expr}`` already substituted. A SceneError names the file,
    the field (the point) and ``owner`` ("body 'float'")."""
    value = r._get("profile", _REQUIRED, dimension="length", shape="[[r, z], ...] from top to keel")
    if not isinstance(value, list) or len(value) < 2:
        r.fail("profile", f"{owner}: expected a list of at least 2 [r, z] points (m, z down) from "
                          f"the top to the keel, got {value!r}")
    points = []
    for i, point in enumerate(value):
        if not isinstance(point, list) or len(point) != 2:
            r.fail(f"profile[{i}]", f"{owner}: expected [r, z], two numbers (m), got {point!r}")
        try:
            points.append(tuple(to_si(v, "length") for v in point))
        except UnitError as exc:
            r.fail(f"profile[{i}]", f"{owner}: {exc} (SI unit m)")
    problem = profile_problem(points)
    if problem is not None:
        r.fail(problem[0], f"{owner}: {problem[1]}")
    return tuple(points)


DISPLACED = ("displaced", "equilibrium")     # "equilibrium": WEC-Sim's word for the same rule


def displaced_mass(r, geometry, rho: float, supplied: bool = False) -> float:
    """``mass`` of a body table (a scene Reader), kg: a number (or "3 t"), or "displaced" (alias
    "equilibrium"): rho (kg/m^3) x the immersed volume of ``geometry`` at rest, so that the body
    floats there. Without a geometry, and with BEM data the scene supplies (``supplied``: a
    [hydro] source or file), NaN: the mass is rho x the displaced volume those data state for
    the body, taken when they are read (mbcontrol.hydro.with_displaced_masses)."""
    if r.data.get("mass") not in DISPLACED:
        return r.positive("mass", "mass")
    r._get("mass", _REQUIRED, dimension="mass", shape="number")
    if geometry is None and supplied:
        return math.nan
    if geometry is None:
        r.fail("mass", f"\"{r.data['mass']}\" needs the body's displaced volume: from its "
                       "[body.geometry] (rho x its immersed volume) or from the BEM data of "
                       "[hydro] source (a WAMIT .out, BEMIO .h5 or Capytaine .nc file, which states "
                       "each body's volume); expected one of them, or the mass in kg")
    try:
        volume = immersed_volume(geometry)
    except ValueError as exc:
        r.fail("mass", str(exc))
    if not volume > 0:
        r.fail("mass", "\"displaced\": the geometry has no volume below the free surface at rest "
                       "(NED z > 0); expected a body that floats or is submerged, or the mass in kg")
    return rho * volume
