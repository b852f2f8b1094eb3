"""Tests of mbcontrol.hydro.large_angle: nonlinear hydrostatic restoring of primitives.

References are independent of the fibre quadrature under test:
- sphere: slice integrals of disks (scipy quad), not the cap formulas;
- box: the convex polyhedron box ∩ {z >= 0} (corners inside plus edge crossings), volume from
  scipy's ConvexHull, centroid from tetrahedra fanned from an interior point;
- cylinder: slices across the axis, each an exact circular segment (area and first moment in
  closed form), integrated along the axis with scipy quad; itself checked against the clipped
  convex polyhedron of an m-sided prism of the same section area (agreement 1e-10) and against
  the volume of Capytaine's ``immersed_part`` of a panel mesh (those checks matter because the
  horizontal-cylinder model uses the same segment formula, with Gauss nodes along the axis);
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
from mbcontrol.hydro.large_angle import DEFAULT_N, buoyancy, potential

RHO, G = 1025.0, 9.81
BOX = {"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.0, 0.0, 0.0]}
VCYL = {"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.0, 0.0, 0.0], "axis": "z"}
HCYL = {"type": "cylinder", "radius": 1.0, "length": 3.0, "center": [0.0, 0.0, 0.0], "axis": "x"}


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


# ------------------------------------------------------------------ sphere: exact formulas
@pytest.mark.parametrize("zc", [-1.5, -1.0, -0.7, -0.2, 0.0, 0.3, 0.99, 1.0, 2.5])
def test_sphere_cap_volume_and_centroid(zc):
    r, cog = 1.0, np.array([0.1, -0.2, 0.3])               # CoG off the sphere centre
    geo = {"type": "sphere", "radius": r, "center": [0.0, 0.0, 0.0]}
    R = pose(0.4, -0.3, 1.0)
    r_cog = np.array([5.0, 2.0, 0.0]) + R @ cog            # puts the sphere centre at (5, 2, 0) ...
    r_cog[2] += zc                                         # ... then at depth zc
    out = evaluate(geo, cog, R, r_cog)
    Vr, zb = sphere_reference(r, zc)
    # slice quad reference is exact to ~1e-15; the cap formulas agree to round-off (measured 8.9e-16)
    assert out["volume"] == pytest.approx(Vr, abs=1e-12)
    assert out["force"] == pytest.approx([0.0, 0.0, -RHO * G * Vr], abs=1e-8)
    if Vr > 0:
        centre = np.array([5.0, 2.0, zb])
        assert out["centre"] == pytest.approx(centre, abs=1e-12)
        lever = centre - r_cog
        assert out["moment"] == pytest.approx(np.cross(lever, out["force"]), abs=1e-8)
    else:                                                  # dry: no force, centre reported at the CoG
        assert out["centre"] == pytest.approx(r_cog, abs=1e-12)
        assert np.all(out["moment"] == 0.0)


# ------------------------------------------------------------------ box and cylinder accuracy
def random_poses(geometry, count, max_heel_deg, seed):
    """Random (R, r_cog) with heel <= max_heel_deg and 5-95 % of the volume wet."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        axis = rng.normal(size=3)
        axis[2] = 0.0                                      # heel axis horizontal ...
        R = Rotation.from_rotvec(math.radians(rng.uniform(0, max_heel_deg)) * axis / np.linalg.norm(axis))
        R = (Rotation.from_euler("z", rng.uniform(-math.pi, math.pi)) * R).as_matrix()  # ... any yaw
        fraction = rng.uniform(0.05, 0.95)
        out.append((R, np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), 0.0]), fraction))
    return out


def check_against_reference(geometry, count, max_heel, seed, tol_v, tol_c, n=DEFAULT_N):
    cog = np.asarray(geometry["center"], float) + np.array([0.1, -0.05, 0.2])  # CoG off centre
    worst_v = worst_c = 0.0
    for R, shift, fraction in random_poses(geometry, count, max_heel, seed):
        z = draft_for_fraction(geometry, R, fraction)      # centre depth for that wet fraction
        r_cog = shift + np.array([0, 0, z]) + R @ (cog - np.asarray(geometry["center"], float))
        Vr, cr = reference(geometry, cog, R, r_cog)
        out = evaluate(geometry, cog, R, r_cog, n=n)
        worst_v = max(worst_v, abs(out["volume"] - Vr) / total_volume(geometry))
        worst_c = max(worst_c, np.linalg.norm(out["centre"] - cr) / size(geometry))
        assert out["force"] == pytest.approx([0, 0, -RHO * G * out["volume"]], rel=1e-14)
        assert out["moment"] == pytest.approx(np.cross(out["centre"] - r_cog, out["force"]),
                                              abs=1e-9 * RHO * G * total_volume(geometry) * size(geometry))
    assert worst_v < tol_v and worst_c < tol_c, (worst_v, worst_c)


@pytest.mark.parametrize("geometry", [BOX, {"type": "box", "size": [4.0, 2.0, 0.5], "center": [1.0, 0.0, 0.1]}],
                         ids=["box2x1x1", "barge4x2x05"])
def test_box_against_convex_polyhedron(geometry):
    # heel <= 30 deg, default n, 12 random poses (5-95 % wet): |dV|/V_total measured 4.9e-5 (2x1x1)
    # and 2.8e-4 (flat barge: the wet band across its 0.5 m depth is narrow); |centre error|/size
    # 4.7e-4 and 6.3e-4 (largest at 5 % wet, where the first-moment error is divided by a small V)
    tol = (1.5e-4, 1e-3) if geometry is BOX else (8e-4, 1.5e-3)
    check_against_reference(geometry, 12, 30, seed=1, tol_v=tol[0], tol_c=tol[1])


def test_box_any_orientation_converges():
    # any heel up to 90 deg, n = 48: measured |dV|/V_total 8.4e-5, centre 1.3e-4 (heel near 90 deg
    # makes the fibres nearly horizontal, where the error falls like 1/n only)
    check_against_reference(BOX, 10, 90, seed=2, tol_v=3e-4, tol_c=4e-4, n=48)


def test_vertical_cylinder_against_slices():
    # heel <= 30 deg, default n: measured |dV|/V_total 7.4e-7, centre 5.7e-7
    check_against_reference(VCYL, 10, 30, seed=3, tol_v=3e-6, tol_c=2e-6)


@pytest.mark.parametrize("axis", ["x", "y"])
def test_horizontal_cylinder_against_slices(axis):
    # heel <= 30 deg, default n (32 segment slices): measured |dV|/V_total 2.0e-6 (x), 1.9e-7 (y);
    # centre 1.6e-6, 1.4e-7
    check_against_reference({**HCYL, "axis": axis}, 10, 30, seed=4, tol_v=6e-6, tol_c=5e-6)


@pytest.mark.parametrize("geometry", [BOX, VCYL, HCYL], ids=["box", "vcyl", "hcyl"])
def test_fully_immersed_and_dry_are_exact(geometry):
    cog = np.array(geometry["center"], float)
    for R in (np.eye(3), pose(0.3, 0.5, 0.2), pose(math.pi / 2, 0.0, 0.0)):
        wet = evaluate(geometry, cog, R, [0.0, 0.0, 10.0])
        dry = evaluate(geometry, cog, R, [0.0, 0.0, -10.0])
        # every fibre or slice wholly wet or dry: exact up to round-off (measured 4e-16)
        assert wet["volume"] == pytest.approx(total_volume(geometry), rel=1e-13)
        assert wet["centre"] == pytest.approx([0.0, 0.0, 10.0], abs=1e-12)
        assert abs(dry["volume"]) < 1e-15 * total_volume(geometry)
        assert np.all(np.abs(dry["force"]) < 1e-9) and np.all(np.abs(dry["moment"]) < 1e-9)


@pytest.mark.parametrize("axis", ["x", "z"])
def test_cylinder_reference_matches_polygonal_prism(axis):
    """The segment-slice reference against convex-polyhedron clipping of a 360-sided prism."""
    geo = {**HCYL, "axis": axis}
    for R, zc in ((pose(0.3, 0.4, 0.1), 0.2), (pose(0.0, 0.2, 0.0), -0.5), (pose(1.2, 0.3, 0.0), 0.1)):
        Vr, cr = cylinder_reference(geo, [0, 0, 0], R, [0, 0, zc])
        Vp, cp = prism_reference(geo, [0, 0, 0], R, [0, 0, zc], 360)
        # the area-matched prism converges like m^-4; measured |dV|/V_total <= 1.4e-10 and
        # |dc| <= 3.4e-10 m at m = 360 (1e-12 at m = 720)
        assert abs(Vp - Vr) < 5e-10 * total_volume(geo)
        assert np.linalg.norm(cp - cr) < 1e-9


def test_cylinder_reference_matches_capytaine():
    """The segment-slice reference volume against Capytaine's immersed_part of a panel mesh."""
    cpt = pytest.importorskip("capytaine")
    D = np.diag([1.0, -1.0, -1.0])                          # NED <-> Capytaine z-up
    m = 64
    # a polygon with m sides has area sin(2pi/m)/(2pi/m) of the circle's: inflate to match it
    r_mesh = HCYL["radius"] * math.sqrt((2 * math.pi / m) / math.sin(2 * math.pi / m))
    mesh0 = cpt.mesh_horizontal_cylinder(length=HCYL["length"], radius=r_mesh, center=(0, 0, 0),
                                         resolution=(2, m, 8))
    R, r_cog = pose(0.3, 0.4, 0.1), np.array([0.0, 0.0, 0.2])
    verts = (np.asarray(mesh0.vertices) @ D) @ R.T + r_cog   # body (NED) -> posed NED
    mesh = cpt.Mesh(vertices=verts @ D, faces=np.asarray(mesh0.faces)).immersed_part()
    Vr, cr = cylinder_reference(HCYL, [0, 0, 0], R, r_cog)
    # volume: measured |dV|/V 4.7e-8 (a polyhedron's volume is exact in Capytaine). Capytaine's
    # centre of buoyancy integrates x^2 over each flat panel with one point: measured 1.6e-3 m
    assert mesh.volume == pytest.approx(Vr, rel=2e-7)
    assert D @ np.asarray(mesh.center_of_buoyancy) == pytest.approx(cr, abs=4e-3)


# ------------------------------------------------------------------ small-angle consistency
def sym_pose():
    """SX symbols q = (heave, roll, pitch) and R = Ry(pitch) Rx(roll): rotation about the CoG."""
    q = ca.SX.sym("q", 3)
    cr, sr, cp, sp = ca.cos(q[1]), ca.sin(q[1]), ca.cos(q[2]), ca.sin(q[2])
    Rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, cr, -sr), ca.horzcat(0, sr, cr))
    Ry = ca.vertcat(ca.horzcat(cp, 0, sp), ca.horzcat(0, 1, 0), ca.horzcat(-sp, 0, cp))
    return q, ca.mtimes(Ry, Rx)


def linear_stiffness(A, x0, y0, ixx, iyy, V, zB, cog):
    """Buoyancy-only stiffness K = -d(F_z, M_x, M_y)/d(heave, roll, pitch) at rest, NED, about the CoG.

    Waterplane of area A, centroid (x0, y0), central second moments ixx = ∫(x-x0)^2 dA,
    iyy = ∫(y-y0)^2 dA (no product term for these symmetric shapes). Derivation: a waterplane
    point moves down by dz + roll (y - yG) - pitch (x - xG), adding that much wet volume; the
    wet volume already there turns with the body (roll: y -> y - roll (z - zG)). Hence
    K33 = rho g A, K34 = rho g A (y0 - yG), K35 = -rho g A (x0 - xG),
    K44 = rho g [iyy + A (y0 - yG)^2 + V (zG - zB)], K55 = rho g [ixx + A (x0 - xG)^2 + V (zG - zB)],
    K45 = -rho g A (x0 - xG)(y0 - yG); in z-up terms K44 = rho g (I_wp + V (z_B - z_G)), as usual.
    """
    dx, dy, dz = x0 - cog[0], y0 - cog[1], cog[2] - zB
    return RHO * G * np.array([[A, A * dy, -A * dx],
                               [A * dy, iyy + A * dy**2 + V * dz, -A * dx * dy],
                               [-A * dx, -A * dx * dy, ixx + A * dx**2 + V * dz]])


def stiffness_cases():
    box = {"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.3, -0.2, 0.1]}
    vcyl = {"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.2, 0.1, 0.3], "axis": "z"}
    sph = {"type": "sphere", "radius": 1.0, "center": [0.1, 0.2, 0.3]}
    out = [("box", box, [0.1, 0.05, -0.2], 4 * 1.0 * 0.5, (0.3, -0.2), 2.0**3 * 1.0 / 12, 2.0 * 1.0**3 / 12)]
    out.append(("vcyl", vcyl, [0.0, 0.0, 0.0], math.pi, (0.2, 0.1), math.pi / 4, math.pi / 4))
    b = math.sqrt(1 - 0.4**2)                              # half-width of the waterline
    for axis in ("x", "y"):
        h = {**HCYL, "center": [0.0, 0.1, 0.4], "axis": axis}
        lx, ly = (3.0, 2 * b) if axis == "x" else (2 * b, 3.0)
        out.append((f"hcyl-{axis}", h, [0.2, 0.0, 0.0], lx * ly, (0.0, 0.1), ly * lx**3 / 12, lx * ly**3 / 12))
    a = math.sqrt(1 - 0.3**2)
    out.append(("sphere", sph, [0.0, 0.0, 0.5], math.pi * a * a, (0.1, 0.2), math.pi * a**4 / 4, math.pi * a**4 / 4))
    return out


@pytest.mark.parametrize("case", stiffness_cases(), ids=lambda c: c[0])
def test_small_angle_stiffness(case):
    name, geo, cog, A, (x0, y0), ixx, iyy = case
    cog = np.asarray(cog, float)
    if geo["type"] == "sphere":
        V, zB = sphere_reference(1.0, geo["center"][2])
    else:
        V, cB = reference(geo, cog, np.eye(3), cog)
        zB = cB[2]
    K = linear_stiffness(A, x0, y0, ixx, iyy, V, zB, cog)
    q, R = sym_pose()
    out = buoyancy(geo, cog, R, cog + ca.vertcat(0, 0, q[0]), RHO, G)
    wrench = ca.vertcat(out["force"], out["moment"])
    J = ca.Function("J", [q], [ca.jacobian(wrench, q)])(np.zeros(3)).full()
    scale = RHO * G * max(A * size(geo) ** 2, V * size(geo))
    # at rest every fibre crosses the waterline (slices and cap are exact): the Jacobian is exact,
    # measured |K + J|/scale <= 2.0e-16 over the five cases
    assert np.abs(-J[[2, 3, 4], :] - K).max() < 1e-12 * scale, (-J[[2, 3, 4], :], K)
    assert np.abs(J[[0, 1, 5], :]).max() == 0.0            # no surge/sway force or yaw moment


# ------------------------------------------------------------------ conservativeness
def skew(v):
    return ca.vertcat(ca.horzcat(0, -v[2], v[1]), ca.horzcat(v[2], 0, -v[0]), ca.horzcat(-v[1], v[0], 0))


ALL = [BOX, VCYL, HCYL, {**HCYL, "axis": "y"}, {"type": "sphere", "radius": 1.0, "center": [0.2, 0.0, 0.1]},
       {"type": "box", "size": [4.0, 2.0, 0.5], "center": [1.0, 0.0, 0.1]}]


@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_wrench_is_minus_gradient_of_potential(geometry):
    """(force, moment) = -dU/d(translation, small rotation about n-frame axes through the CoG)."""
    cog = np.asarray(geometry["center"], float) + np.array([0.1, -0.1, 0.05])
    r, eps = ca.SX.sym("r", 3), ca.SX.sym("eps", 3)
    rng = np.random.default_rng(7)
    for heel in (0.0, 0.3, 0.8, 1.3, math.pi / 2):
        R0 = pose(heel * rng.uniform(-1, 1), heel * rng.uniform(-1, 1), rng.uniform(-3, 3))
        R = ca.mtimes(ca.DM.eye(3) + skew(eps), ca.DM(R0))
        U = potential(geometry, cog, R, r, RHO, G)
        grad = ca.Function("g", [r, eps], [ca.gradient(U, ca.vertcat(r, eps))])
        r0 = np.array([0.5, -0.3, rng.uniform(-0.3, 0.3)])
        out = evaluate(geometry, cog, R0, r0)
        g = grad(r0, np.zeros(3)).full().ravel()
        scale = RHO * G * total_volume(geometry) * size(geometry)
        # exact identity of the discrete model: measured |dU + wrench| / scale <= 4.1e-16
        assert np.abs(g + np.concatenate([out["force"], out["moment"]])).max() < 1e-12 * scale, heel
        assert out["potential"] == pytest.approx(float(potential(geometry, cog, R0, r0, RHO, G)), rel=1e-14)


@pytest.mark.parametrize("geometry", [BOX, HCYL], ids=["box", "hcyl"])
def test_closed_loop_work_vanishes(geometry):
    """Work of the wrench around a large closed loop in (heave, roll, pitch) is ~0."""
    cog = np.asarray(geometry["center"], float) + np.array([0.0, 0.0, 0.1])
    N = 1500
    t = np.linspace(0.0, 2 * math.pi, N + 1)
    z, roll, pitch = 0.2 * np.sin(t), 0.7 * np.sin(t + 1.0), 0.5 * np.sin(2 * t)
    Rs = [pose(a, b) for a, b in zip(roll, pitch)]
    work = total = 0.0
    for k in range(N):
        # midpoint rule; the rotation increment as a rotation vector in the n-frame
        Rm = Rotation.from_matrix(Rs[k]) * Rotation.from_rotvec(0.5 * (Rotation.from_matrix(Rs[k]).inv()
                                                                      * Rotation.from_matrix(Rs[k + 1])).as_rotvec())
        dtheta = (Rotation.from_matrix(Rs[k + 1]) * Rotation.from_matrix(Rs[k]).inv()).as_rotvec()
        out = evaluate(geometry, cog, Rm.as_matrix(), [0.0, 0.0, 0.5 * (z[k] + z[k + 1])])
        dw = out["force"][2] * (z[k + 1] - z[k]) + out["moment"] @ dtheta
        work += dw
        total += abs(dw)
    # midpoint rule, 1500 steps: measured |loop work| / sum |dW| 3.5e-8 (box) and 1.1e-9 (hcyl),
    # falling with the step (2.1e-7 and 6.9e-9 at 500 steps): truncation error, not a leak
    assert abs(work) < 2e-6 * total, (work, total)


# ------------------------------------------------------------------ CasADi builds
@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_casadi_function_matches_numpy(geometry):
    cog = np.asarray(geometry["center"], float) + np.array([0.05, 0.1, -0.1])
    for kind in (ca.SX, ca.MX):
        R, r, rho, g = kind.sym("R", 3, 3), kind.sym("r", 3), kind.sym("rho"), kind.sym("g")
        out = buoyancy(geometry, cog, R, r, rho, g)
        names = ["force", "moment", "volume", "centre", "potential"]
        f = ca.Function("f", [R, r, rho, g], [out[k] for k in names])
        assert not f.has_free()
        for R0, r0 in ((pose(0.2, -0.4, 0.7), [1.0, 2.0, 0.1]), (pose(1.4, 0.1, 0.0), [0.0, 0.0, -0.2]),
                       (np.eye(3), [0.0, 0.0, 5.0]), (pose(0.0, math.pi / 2, 0.0), [0.0, 0.0, 0.0])):
            ref = evaluate(geometry, cog, R0, r0)
            got = f(R0, r0, RHO, G)
            for k, v in zip(names, got):
                # same arithmetic in another order: measured relative difference <= 5.7e-15
                assert np.asarray(v.full()).ravel() == pytest.approx(np.ravel(ref[k]), rel=1e-12, abs=1e-9), k


@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_jacobian_is_finite_everywhere(geometry):
    """No inf * 0 in AD: dry, wet, horizontal fibres (90 deg heel), an upright horizontal-cylinder axis."""
    q, R = sym_pose()
    cog = np.asarray(geometry["center"], float)
    x = ca.SX.sym("x", 3)
    out = buoyancy(geometry, cog, R, x, RHO, G)
    J = ca.Function("J", [q, x], [ca.jacobian(ca.vertcat(out["force"], out["moment"]), ca.vertcat(q, x))])
    for angles in ((0, 0, 0), (0, math.pi / 2, 0), (0, 0, math.pi / 2), (0, 0.3, 0.2)):
        for depth in (-5.0, 0.0, 0.05, 5.0):
            assert np.all(np.isfinite(J(angles, [0.0, 0.0, depth]).full()))


# ------------------------------------------------------------------ wave level, bad input
def test_uniform_wave_level_equals_lifted_body():
    R, r0, e = pose(0.3, 0.2, 0.5), np.array([0.1, 0.2, 0.3]), 0.25
    for geo in ALL:
        cog = np.asarray(geo["center"], float)
        a = evaluate(geo, cog, R, r0, eta=e)                # surface raised by e ...
        b = evaluate(geo, cog, R, r0 + [0, 0, e])          # ... = body lowered by e
        c = evaluate(geo, cog, R, r0, eta=lambda x, y: e + 0 * x)
        for k in ("force", "moment", "volume", "potential"):
            assert np.ravel(a[k]) == pytest.approx(np.ravel(b[k]), rel=1e-12, abs=1e-9), k
            assert np.ravel(c[k]) == pytest.approx(np.ravel(a[k]), rel=1e-12, abs=1e-9), k
        assert a["centre"] == pytest.approx(b["centre"] - [0, 0, e], abs=1e-12)


@pytest.mark.parametrize("geometry, n", [
    ({"type": "mesh", "file": "x.gdf"}, 4),
    ({"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0, 0, 0], "axis": "w"}, 4),
    ({"type": "sphere", "radius": -1.0, "center": [0, 0, 0]}, 4),
    ({"type": "box", "size": [1.0, 1.0], "center": [0, 0, 0]}, 4),
    (BOX, 0),
])
def test_bad_input_raises(geometry, n):
    with pytest.raises(HydroError):
        evaluate(geometry, [0, 0, 0], np.eye(3), [0, 0, 0], n=n)
