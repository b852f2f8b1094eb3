"""Tests of mbcontrol.hydro.mesh.panels: closed panel surfaces and the pressure wrench over them.

References are independent of the panel rules under test:
- sphere: the spherical cap in closed form, V = pi h^2 (3R - h) / 3, and the fact that pressure
  forces on a sphere pass through its centre;
- boxes: mbcontrol.hydro.mesh.large_angle.buoyancy with n = 64 (fibres; exact to round-off for an
  upright box, ~2e-4 of the force at 30 deg heel);
- closed surfaces: closed-form volumes and areas, and Archimedes (rho g V, at the centroid) for a
  fully submerged body, which every rule here gets to round-off;
- mesh files: the same identities, and Capytaine's exact clipping of the faceted polyhedron;
- CasADi: the numpy evaluation of the same panels.
Tolerances quote the measured value in a comment. Frames: NED, water at z > 0.
"""
from __future__ import annotations

import math
import warnings

import casadi as ca
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mbcontrol.errors import HydroError
from mbcontrol.hydro.mesh.large_angle import buoyancy
from mbcontrol.hydro.mesh.panels import Panels, body_panels, hydrostatic_pressure, pressure_wrench

RHO, G = 1025.0, 9.81
P_CALM = hydrostatic_pressure(RHO, G)
OBLIQUE = np.array([1.0, 0.6, 0.0]) / math.hypot(1.0, 0.6)     # a heel axis off the symmetry planes
PROFILE = [[1.0, -1.0], [1.0, 0.5], [0.3, 1.5]]                 # vertical wall, cone, flat keel
# (geometry, exact volume m^3, exact area m^2, centroid relative to "center" m)
BODIES = {
    "box": ({"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.0, 0.0, 0.0]}, 2.0, 10.0, 0.0),
    "barge": ({"type": "box", "size": [4.0, 2.0, 0.5], "center": [1.0, 0.0, 0.1]}, 4.0, 22.0, 0.0),
    "vcyl": ({"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.0, 0.0, 0.0]},
             2 * math.pi, 6 * math.pi, 0.0),
    "hcyl_x": ({"type": "cylinder", "radius": 1.0, "length": 3.0, "axis": "x", "center": [0.0, 0.0, 0.0]},
               3 * math.pi, 8 * math.pi, 0.0),
    "hcyl_y": ({"type": "cylinder", "radius": 1.0, "length": 3.0, "axis": "y", "center": [0.0, 0.5, 0.0]},
               3 * math.pi, 8 * math.pi, 0.0),
    "sphere": ({"type": "sphere", "radius": 5.0, "center": [0.0, 0.0, 0.0]}, 500 * math.pi / 3,
               100 * math.pi, 0.0),
    "revolution": ({"type": "revolution", "profile": PROFILE, "center": [0.0, 0.0, 0.2]}, None, None, None),
    "spindle": ({"type": "revolution", "profile": [[0.0, -1.0], [1.0, 0.0], [0.0, 1.0]],
                 "center": [0.0, 0.0, 0.0]}, 2 * math.pi / 3, 2 * math.pi * math.sqrt(2), 0.0),
}


def revolution_reference(profile):
    """(volume, lateral + disk area, centroid z) of the closed revolved profile, by 3-point Gauss
    per segment (exact: the integrands are polynomials of degree <= 3 in z)."""
    p = np.asarray(profile, float)
    p = np.vstack([[0.0, p[0, 1]], p, [0.0, p[-1, 1]]])
    x, w = np.polynomial.legendre.leggauss(3)
    vol = mom = area = 0.0
    for (ra, za), (rb, zb) in zip(p[:-1], p[1:]):
        area += math.pi * (ra + rb) * math.hypot(rb - ra, zb - za)
        z = 0.5 * (za + zb) + 0.5 * (zb - za) * x
        r = ra + (rb - ra) * (z - za) / (zb - za) if zb != za else np.zeros(3)
        vol += 0.5 * (zb - za) * np.sum(w * math.pi * r**2)
        mom += 0.5 * (zb - za) * np.sum(w * math.pi * r**2 * z)
    return vol, area, mom / vol


def reference(name):
    geo, vol, area, centroid = BODIES[name]
    if vol is None:
        vol, area, zc = revolution_reference(geo["profile"])
        centroid = np.array([0.0, 0.0, zc])
    return geo, vol, area, np.asarray(geo["center"], float) + centroid


def pose(heel_deg, axis=OBLIQUE, yaw_deg=0.0):
    return (Rotation.from_rotvec(math.radians(yaw_deg) * np.array([0, 0, 1.0])).as_matrix()
            @ Rotation.from_rotvec(math.radians(heel_deg) * np.asarray(axis)).as_matrix())


# ------------------------------------------------------------------ closed surfaces
@pytest.mark.parametrize("name", list(BODIES))
def test_closed_surface_identities(name):
    geo, vol, area, _ = reference(name)
    panels = body_panels(geo, [0.1, -0.2, 0.3])
    assert isinstance(panels, Panels) and panels.points.shape == panels.normals.shape == (3, panels.n)
    assert 400 <= panels.n <= 1000                       # the default's rule (measured 580-750)
    # exact by construction: measured <= 5e-17 of the area, 2.2e-16 of the volume
    assert np.abs(panels.normals.sum(axis=1)).max() <= 1e-14 * area
    assert panels.volume == pytest.approx(vol, rel=1e-13)
    assert np.linalg.norm(panels.normals, axis=0).sum() == pytest.approx(area, rel=1e-13)
    second = panels.points @ panels.normals.T            # int x n^T dA = V I on a closed surface
    assert second == pytest.approx(vol * np.eye(3), abs=1e-12 * vol)


@pytest.mark.parametrize("name", list(BODIES))
@pytest.mark.parametrize("eta", [0.0, 0.7])
def test_fully_submerged_is_archimedes(name, eta):
    """A linear pressure field: every rule gives rho g V at the centroid to round-off (the
    moment to ~1e-5 m of lever on the sloping stretch of the revolution profile)."""
    geo, vol, _, centroid = reference(name)
    cog = np.array([0.3, -0.2, 0.4])
    panels = body_panels(geo, cog)
    R, r_cog = pose(37.0, [0.3, -0.5, 0.2], yaw_deg=20.0), np.array([1.0, 2.0, 25.0])
    force, moment = pressure_wrench(panels, R, r_cog, hydrostatic_pressure(RHO, G, eta))
    weight = RHO * G * vol
    assert force == pytest.approx([0.0, 0.0, -weight], abs=1e-12 * weight)   # measured 4e-15
    lever = R @ (centroid - cog)
    tol = 1e-5 if name == "revolution" else 1e-12    # measured 3.1e-6 (revolution), 2e-14 others
    assert moment == pytest.approx(np.cross(lever, force), abs=tol * weight)


@pytest.mark.parametrize("name", ["box", "hcyl_x", "hcyl_y", "vcyl", "revolution", "sphere"])
def test_symmetric_bodies_at_rest_feel_no_side_force(name):
    """The stagger keeps the mirror symmetries: an upright body symmetric about its CoG's
    vertical planes has no horizontal force and no moment at rest (a horizontal cylinder
    needs an even number of cells along it, which body_panels gives it)."""
    geo, vol, _, _ = reference(name)
    cog = np.asarray(geo["center"], float)
    panels = body_panels(geo, cog)
    force, moment = pressure_wrench(panels, np.eye(3), cog + [0.0, 0.0, 0.13], P_CALM)
    scale = RHO * G * vol
    assert np.abs(force[:2]).max() <= 1e-12 * scale and np.abs(moment).max() <= 1e-12 * scale


# ------------------------------------------------------------------ sphere: exact cap
def cap_volume(radius, depth):
    h = min(max(radius + depth, 0.0), 2 * radius)
    return math.pi * h * h * (3 * radius - h) / 3


@pytest.mark.parametrize("heel", [0.0, 10.0, 30.0, 60.0])
@pytest.mark.parametrize("depth", [-3.0, -1.5, 0.0, 1.5, 3.0])
def test_sphere_force_is_the_cap_buoyancy(heel, depth):
    geo, radius = BODIES["sphere"][0], 5.0
    cog = np.array([0.4, -0.3, 0.8])                     # off the centre: the moment has a lever
    panels = body_panels(geo, cog)
    R = pose(heel)
    r_cog = np.array([3.0, -1.0, depth]) + R @ cog       # puts the centre at depth `depth`
    force, moment = pressure_wrench(panels, R, r_cog, P_CALM)
    exact = RHO * G * cap_volume(radius, depth)
    # default panels (584 points): measured worst 1.7e-3 over these 20 poses
    assert force == pytest.approx([0.0, 0.0, -exact], abs=3e-3 * exact)
    # each point lies on the sphere with a radial normal: the moment about the centre is 0 to
    # round-off, so about the CoG it is (centre - CoG) x force (measured 1e-16 of |F| R)
    centre = np.array([3.0, -1.0, depth])
    assert moment == pytest.approx(np.cross(centre - r_cog, force), abs=1e-12 * exact * radius)


def test_sphere_dry_and_submerged_limits():
    geo = BODIES["sphere"][0]
    panels = body_panels(geo, [0.0, 0.0, 0.0], panel_size=2.0)
    force, moment = pressure_wrench(panels, pose(20.0), [0.0, 0.0, -5.01], P_CALM)
    assert np.all(force == 0.0) and np.all(moment == 0.0)
    force, _ = pressure_wrench(panels, pose(20.0), [0.0, 0.0, 5.01], P_CALM)
    assert force[2] == pytest.approx(-RHO * G * 500 * math.pi / 3, rel=1e-13)


def test_sphere_error_falls_with_the_panel_size():
    """Second order, irregular: measured 1.1e-2 (104 points), 5.9e-3 (352), 8.4e-4 (1208)."""
    geo = BODIES["sphere"][0]

    def worst(panels):
        return max(abs(pressure_wrench(panels, pose(heel), [0.0, 0.0, d], P_CALM)[0][2]
                       / (RHO * G * cap_volume(5.0, d)) + 1)
                   for heel in (0.0, 30.0) for d in (-3.0, 0.0, 3.0))
    errors = [worst(body_panels(geo, [0, 0, 0], panel_size=h)) for h in (2.2, 1.1, 0.55)]
    assert errors[2] < errors[0] / 8 and errors[2] < 1.5e-3
    # subdivide s on a primitive is panel_size / s: the same points
    a = body_panels(geo, [0, 0, 0], panel_size=2.2, subdivide=2)
    b = body_panels(geo, [0, 0, 0], panel_size=1.1)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.normals, b.normals)


# ------------------------------------------------------------------ boxes: large_angle
@pytest.mark.parametrize("name", ["box", "barge"])
@pytest.mark.parametrize("heel", [0.0, 10.0, 30.0])
@pytest.mark.parametrize("fraction", [0.3, 0.5, 0.7])
def test_box_against_large_angle(name, heel, fraction):
    geo = BODIES[name][0]
    cog = np.asarray(geo["center"], float) + [0.1, -0.05, 0.1]
    panels = body_panels(geo, cog)
    R = pose(heel, [1.0, 0.0, 0.0] if name == "barge" else OBLIQUE, yaw_deg=15.0)
    lz = geo["size"][2]
    r_cog = np.array([0.5, 0.2, (fraction - 0.5) * lz]) + R @ (cog - geo["center"])
    force, moment = pressure_wrench(panels, R, r_cog, P_CALM)
    ref = buoyancy(geo, cog, R, r_cog, RHO, G, n=64)
    F = abs(ref["force"][2])
    length = max(geo["size"])
    if heel == 0.0:            # both exact: the bottom carries the whole vertical force
        assert force == pytest.approx(ref["force"], abs=1e-12 * F)
        assert moment == pytest.approx(ref["moment"], abs=1e-12 * F * length)
    else:                      # measured worst over these poses 6.6e-4 (force), 4.1e-4 F L (moment)
        assert force == pytest.approx(ref["force"], abs=1.5e-3 * F)
        assert moment == pytest.approx(ref["moment"], abs=1e-3 * F * length)


# ------------------------------------------------------------------ CasADi
@pytest.mark.parametrize("name", ["barge", "hcyl_x", "revolution"])
def test_casadi_equals_numpy(name):
    geo = BODIES[name][0]
    panels = body_panels(geo, np.asarray(geo["center"], float) + [0.1, 0.0, 0.2], panel_size=0.4)
    Rs, rs, eta = ca.SX.sym("R", 3, 3), ca.SX.sym("r", 3), ca.SX.sym("eta")
    def wave(x, y, z):                                   # a level eta and a sloping factor
        return hydrostatic_pressure(RHO, G, eta)(x, y, z) * (1 + 0.05 * x - 0.03 * y)
    for pressure, args in ((P_CALM, []), (wave, [eta])):
        out = pressure_wrench(panels, Rs, rs, pressure)
        assert all(isinstance(o, ca.SX) and o.shape == (3, 1) for o in out)
        fun = ca.Function("fk", [Rs, rs, *args], list(out))
        for heel, depth in ((0.0, 0.1), (25.0, -0.2), (70.0, 0.3)):
            R, r = pose(heel), np.array([0.3, -0.4, depth])
            level = [0.15] if args else []
            numeric = pressure_wrench(panels, R, r, (lambda x, y, z: RHO * G * np.maximum(z + 0.15, 0)
                                                     * (1 + 0.05 * x - 0.03 * y)) if args else P_CALM)
            symbolic = fun(R, r, *level)
            for a, b in zip(symbolic, numeric):
                assert np.asarray(a).ravel() == pytest.approx(b, rel=1e-12, abs=1e-12 * np.abs(b).max())


def test_compiled_function_matches_numpy():
    from mbcontrol.sim.compiled import compile_function

    geo = BODIES["box"][0]
    panels = body_panels(geo, [0.0, 0.0, 0.1], panel_size=0.5)
    Rs, rs = ca.SX.sym("R", 3, 3), ca.SX.sym("r", 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)       # no compiler: interpreted, still correct
        fun = compile_function(ca.Function("panels_test_fk", [Rs, rs],
                                           list(pressure_wrench(panels, Rs, rs, P_CALM))))
    R, r = pose(20.0), np.array([0.0, 0.0, 0.2])
    for a, b in zip(fun(R, r), pressure_wrench(panels, R, r, P_CALM)):
        assert np.asarray(a).ravel() == pytest.approx(b, rel=1e-12, abs=1e-9)


def test_hydrostatic_pressure_numpy_and_casadi():
    p = hydrostatic_pressure(RHO, G, eta=0.5)
    z = np.array([-1.0, -0.5, 0.0, 2.0])
    assert p(0 * z, 0 * z, z) == pytest.approx(RHO * G * np.array([0.0, 0.0, 0.5, 2.5]))
    zs = ca.SX.sym("z", 1, 4)
    out = p(0, 0, zs)
    assert isinstance(out, ca.SX)
    assert np.asarray(ca.Function("p", [zs], [out])(z.reshape(1, 4))).ravel() == pytest.approx(p(0, 0, z))


# ------------------------------------------------------------------ mesh files
def write_obj(path, vertices, faces):
    with open(path, "w") as fh:
        fh.writelines(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in vertices)
        fh.writelines("f " + " ".join(str(i + 1) for i in face) + "\n" for face in faces)
    return str(path)


def box_mesh(lx, ly, lz, n=3):
    """A closed box of quads, z-up file convention, outward normals, centred on the origin."""
    vertices, faces, index = [], [], {}
    grid = [np.linspace(-s / 2, s / 2, n + 1) for s in (lx, ly, lz)]
    for axis in range(3):
        a, b = [(axis + 1) % 3, (axis + 2) % 3]
        for sign in (-1, 1):
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        v = [0.0, 0.0, 0.0]
                        v[axis], v[a], v[b] = sign * (lx, ly, lz)[axis] / 2, grid[a][i + di], grid[b][j + dj]
                        key = tuple(np.round(v, 12))
                        if key not in index:
                            index[key] = len(vertices)
                            vertices.append(v)
                        quad.append(index[key])
                    faces.append(quad if sign > 0 else quad[::-1])
    return vertices, faces


def test_mesh_file_is_a_closed_body_in_ned(tmp_path):
    vertices, faces = box_mesh(2.0, 1.0, 0.5)
    name = write_obj(tmp_path / "box.obj", vertices, faces)
    # z-up file, drawn 0.2 m above its origin: in NED its centre is 0.2 m above "center"
    shifted = [(x, y, z + 0.2) for x, y, z in vertices]
    geo = {"type": "mesh", "file": write_obj(tmp_path / "up.obj", shifted, faces), "center": [1.0, 0.0, 0.3]}
    panels = body_panels(geo, [1.0, 0.0, 0.1])
    assert panels.volume == pytest.approx(1.0, rel=1e-13)
    assert np.abs(panels.normals.sum(axis=1)).max() < 1e-13
    areas = np.linalg.norm(panels.normals, axis=0)
    centroid = panels.points @ areas / areas.sum()         # of the surface: the box's centre too
    assert centroid == pytest.approx([0.0, 0.0, 0.0], abs=1e-12)   # box centre (1, 0, 0.1) = the CoG
    # fully submerged at a heel: Archimedes at the centroid, force and moment (edge-midpoint rule)
    R, r_cog = pose(40.0), np.array([0.0, 0.0, 10.0])
    cog = np.array([0.2, 0.1, 0.0])
    panels = body_panels({"type": "mesh", "file": name, "axes": "ned"}, cog)
    force, moment = pressure_wrench(panels, R, r_cog, P_CALM)
    assert force == pytest.approx([0.0, 0.0, -RHO * G], abs=1e-12 * RHO * G)
    assert moment == pytest.approx(np.cross(R @ -cog, force), abs=1e-12 * RHO * G)
    # the same box as a primitive, half immersed at a heel: two rules, one answer (measured
    # 7.7e-5 apart; 7.5e-4 with the mesh's own 162 points, s = 1)
    prim = body_panels({"type": "box", "size": [2.0, 1.0, 0.5], "center": [0.0, 0.0, 0.0]}, cog)
    fine = body_panels({"type": "mesh", "file": name, "axes": "ned"}, cog, subdivide=4)
    R = pose(15.0)
    r_cog = R @ cog + [0.0, 0.0, 0.05]                    # the box centre 5 cm deep
    f1, f2 = pressure_wrench(prim, R, r_cog, P_CALM)[0], pressure_wrench(fine, R, r_cog, P_CALM)[0]
    assert f1 == pytest.approx(f2, abs=5e-4 * abs(f1[2]))


def test_mesh_subdivision_converges_to_the_polyhedron(tmp_path):
    """A faceted UV sphere: subdivide resolves the waterline on the same facets; the reference
    is Capytaine's exact clipping of the polyhedron (measured 7.3e-4, 3.2e-4, 2.5e-5)."""
    import capytaine as cpt

    mesh = cpt.mesh_sphere(radius=5.0, resolution=(8, 16))
    faces = [[int(i) for i in dict.fromkeys(f)] for f in mesh.faces]
    name = write_obj(tmp_path / "uv.obj", mesh.vertices, faces)
    errors = []
    for s in (1, 2, 3):
        panels = body_panels({"type": "mesh", "file": name}, [0, 0, 0], subdivide=s)
        worst = 0.0
        for heel, d in ((0.0, 1.5), (30.0, -1.5), (60.0, 0.0)):
            R = pose(heel)
            zup = np.diag([1.0, -1, -1])
            vol = mesh.rotated_with_matrix(zup @ R @ zup).translated((0, 0, -d)).immersed_part().volume
            force = pressure_wrench(panels, R, [0.0, 0.0, d], P_CALM)[0]
            worst = max(worst, abs(force[2] / (RHO * G * vol) + 1))
        errors.append(worst)
    assert errors[2] < errors[1] < errors[0] < 2e-3


def test_open_mesh_is_refused_naming_the_file(tmp_path):
    vertices, faces = box_mesh(2.0, 1.0, 1.0)
    top = [f for f in faces if not all(vertices[i][2] > 0.49 for i in f)]    # the deck removed
    name = write_obj(tmp_path / "wetted_only.obj", vertices, top)
    with pytest.raises(HydroError, match=r"wetted_only\.obj.*whole hull.*above and below the waterline"):
        body_panels({"type": "mesh", "file": name}, [0, 0, 0])
    # an open tube has sum(n) = 0: the second-moment check catches it
    tube = [f for f in faces if not all(abs(vertices[i][0]) > 0.99 for i in f)]
    with pytest.raises(HydroError, match="tube.obj.*not a closed surface"):
        body_panels({"type": "mesh", "file": write_obj(tmp_path / "tube.obj", vertices, tube)}, [0, 0, 0])
    inward = write_obj(tmp_path / "inward.obj", vertices, [f[::-1] for f in faces])
    with pytest.raises(HydroError, match="inward.obj.*inward"):
        body_panels({"type": "mesh", "file": inward}, [0, 0, 0])
    with pytest.raises(HydroError, match="missing.stl"):
        body_panels({"type": "mesh", "file": str(tmp_path / "missing.stl")}, [0, 0, 0])


def test_shipped_stl_meshes_are_closed():
    from pathlib import Path

    root = Path(__file__).resolve().parents[3] / "models"
    for stem in ("oswec_flap", "oswec_base"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)      # meshio's STL size probe
            panels = body_panels({"type": "mesh", "file": str(root / f"{stem}.stl")}, [0, 0, 0])
        assert panels.volume > 0


@pytest.mark.parametrize("geometry, kwargs, match", [
    ({"type": "cone"}, {}, "geometry.type"),
    ({"type": "box", "size": [1.0, -1.0, 1.0], "center": [0, 0, 0]}, {}, "size finite > 0"),
    ({"type": "cylinder", "radius": 1.0, "length": 1.0, "axis": "w", "center": [0, 0, 0]}, {}, "axis"),
    ({"type": "sphere", "center": [0, 0, 0]}, {}, "BemBody.geometry"),
    ({"type": "revolution", "profile": [[1.0, 0.0]]}, {}, "profile"),
    ({"type": "sphere", "radius": 1.0, "center": [0, 0, 0]}, {"subdivide": 0}, "subdivide"),
    ({"type": "sphere", "radius": 1.0, "center": [0, 0, 0]}, {"panel_size": -0.1}, "panel_size"),
])
def test_bad_input_is_a_hydro_error(geometry, kwargs, match):
    with pytest.raises(HydroError, match=match):
        body_panels(geometry, [0, 0, 0], **kwargs)
