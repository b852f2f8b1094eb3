"""Tests of mbcontrol.hydro.mesh.large_angle: nonlinear hydrostatic restoring of primitives (the
references are in tests/helpers/large_angle_reference.py; stiffness and potential in
test_large_angle_potential.py).

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

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.large_angle_reference import (ALL, BOX, HCYL, RHO, VCYL, G, cylinder_reference,
                                   draft_for_fraction, evaluate, pose, prism_reference, reference,
                                   size, sphere_reference, total_volume)
from mbcontrol.errors import HydroError
from mbcontrol.hydro.mesh.large_angle import DEFAULT_N


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
