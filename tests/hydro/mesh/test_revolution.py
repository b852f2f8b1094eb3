"""Bodies of revolution (geometry type "revolution") and mass = "displaced".

Closed forms are derived here, independently of mbcontrol.scene.shapes: a vertical cylinder
and Sandia's WaveBot (WecOptTool's `geom.WaveBot` numbers: r1 = 0.88 m, r2 = 0.35 m, h1 = 0.17
m of cylinder of which 0.01 m freeboard, h2 = 0.37 m of cone frustum). WecOptTool's own WaveBot
mesh is made with gmsh/pygmsh, which are not installed offline: that comparison is left out.
"""
import math
import re
import tomllib
import warnings
from pathlib import Path

import capytaine as cpt
import numpy as np
import pytest

from mbcontrol.errors import HydroError, LinearizationError, SceneError
from mbcontrol.hydro import BemBody, compute, hull_mesh, load_hydro_data
from mbcontrol.hydro.model import HydroModel
from mbcontrol.hydro.fit.radiation import RadiationModel
from mbcontrol.hydro.mesh.revolution import azimuthal_panels
from mbcontrol.scene import load_scene, parse_scene

RHO, G = 1025.0, 9.81
R, FREEBOARD, DRAFT = 1.0, 0.2, 0.5
CYLINDER = [[R, -FREEBOARD], [R, DRAFT], [0.0, DRAFT]]
R1, R2, H1, H2, FB = 0.88, 0.35, 0.17, 0.37, 0.01
WAVEBOT = [[R1, -FB], [R1, H1 - FB], [R2, H1 - FB + H2], [0.0, H1 - FB + H2]]


def frusta(sections):
    """(volume m^3, NED depth of its centroid m, waterline radius m) of stacked frusta
    [(z_top, z_bottom, r_top, r_bottom)], from pi h (a^2 + ab + b^2) / 3 and the frustum's
    centroid h (a^2 + 2ab + 3b^2) / (4 (a^2 + ab + b^2)) below its top."""
    vol = moment = 0.0
    for z0, z1, a, b in sections:
        h, s = z1 - z0, a * a + a * b + b * b
        v = math.pi * h * s / 3
        vol, moment = vol + v, moment + v * (z0 + h * (a * a + 2 * a * b + 3 * b * b) / (4 * s))
    return vol, moment / vol, sections[0][2]


CLOSED = {"cylinder": (CYLINDER, frusta([(0.0, DRAFT, R, R)])),
          "wavebot": (WAVEBOT, frusta([(0.0, H1 - FB, R1, R1), (H1 - FB, H1 - FB + H2, R1, R2)]))}


@pytest.mark.parametrize("case", sorted(CLOSED))
def test_hydrostatics_match_closed_forms(case):
    """Volume, waterplane area, heave and roll/pitch stiffness of the mesh Capytaine sees
    (its hydrostatics, GL2 quadrature as mbcontrol.hydro.bem.solve uses) against closed forms."""
    profile, (vol, z_b, r_wl) = CLOSED[case]
    z_g = 0.1                                       # CoG 0.1 m below the waterline (NED)
    body = BemBody("float", {"type": "revolution", "profile": profile}, (0.0, 0.0, z_g), RHO * vol, 0.1)
    hull, symmetric, lid = hull_mesh(body)
    # the n-gon's radii are scaled to its circle's area: volume, waterplane area and centre of
    # buoyancy are exact for any n (each slice is pi r^2), to rounding
    assert hull.volume == pytest.approx(vol, rel=1e-12)
    assert hull.waterplane_area == pytest.approx(math.pi * r_wl ** 2, rel=1e-12)
    assert lid.faces_areas.sum() == pytest.approx(math.pi * r_wl ** 2, rel=1e-12)
    assert symmetric and np.all(lid.faces_normals[:, 2] < 0)      # mirrorable; lid faces down
    fb = cpt.FloatingBody(mesh=hull.with_quadrature("Gauss-Legendre 2"), center_of_mass=(0, 0, -z_g),
                          mass=RHO * vol, dofs=cpt.rigid_body_dofs(rotation_center=(0, 0, -z_g)))
    assert fb.center_of_buoyancy[2] == pytest.approx(-z_b, rel=1e-12)
    K = fb.compute_hydrostatic_stiffness(rho=RHO, g=G)
    assert float(K.sel(influenced_dof="Heave", radiating_dof="Heave")) == pytest.approx(
        RHO * G * math.pi * r_wl ** 2, rel=1e-12)
    # roll/pitch: rho g (I_wp - V (z_B - z_G)), m = rho V, NED depths. The n-gon's second moment
    # differs from pi r^4 / 4 by O((2 pi / n)^4): 1.3e-4 at n = 16, the coarsest here (n = 56, 64
    # at 0.1 m panels: < 1e-6); everything else is exact
    n = azimuthal_panels(r_wl, 0.1)
    k44 = RHO * G * (math.pi * r_wl ** 4 / 4 - vol * (z_b - z_g))
    for dof in ("Roll", "Pitch"):
        assert float(K.sel(influenced_dof=dof, radiating_dof=dof)) == pytest.approx(k44, rel=2e-4 * 16 ** 4 / n ** 4)
    # the lid's rim nodes are the hull's waterline nodes (no gap for the irregular-frequency fix)
    rim = hull.vertices[np.abs(hull.vertices[:, 2]) < 1e-12]
    lid_rim = lid.vertices[np.isclose(np.hypot(*lid.vertices[:, :2].T), np.hypot(*rim[:, :2].T).max())]
    assert len(rim) == len(lid_rim) == n and np.allclose(np.sort(rim, axis=0), np.sort(lid_rim, axis=0))


def test_submerged_offset_and_clipped_shapes():
    """A submerged body is closed by flat discs; a centre moves it; a cone cut by the surface
    keeps exactly its frustum below z = 0; the mesh splits on both mirror planes."""
    capsule = {"type": "revolution", "profile": [[0.5, 0.0], [0.5, 1.0]], "center": [2.0, -1.0, 1.5]}
    hull, symmetric, lid = hull_mesh(BemBody("sub", capsule, (2.0, -1.0, 2.0), 1.0, 0.2))
    assert hull.volume == pytest.approx(math.pi * 0.25, rel=1e-12) and lid is None and not symmetric
    assert hull.center_of_buoyancy == pytest.approx((2.0, 1.0, -2.0))   # z-up: y and z flip
    cone = {"type": "revolution", "profile": [[0.0, -1.0], [1.0, 1.0]]}  # apex 1 m above water
    hull, symmetric, lid = hull_mesh(BemBody("cone", cone, (0, 0, 0.5), 1.0, 0.2))
    assert hull.volume == pytest.approx(math.pi * 1.0 * (0.25 + 0.5 + 1.0) / 3, rel=1e-12)
    assert lid.faces_areas.sum() == pytest.approx(math.pi * 0.25, rel=1e-12)
    half = hull.clipped(origin=(0, 0, 0), normal=(0, 1, 0))
    assert symmetric and 2 * half.nb_faces == hull.nb_faces      # no panel cut by y = 0


def test_bem_matches_the_cylinder_primitive():
    """Heave added mass and damping of the cylinder as a profile against the same hull as a
    cylinder primitive. Both are 32-gons at 0.25 m panels; the primitive's is inscribed (0.64 %
    less volume, (2 pi / 32)^2 / 6), the profile's has the circle's area, so expect them apart by
    about 1 % (measured 1.0 % in A33, 1.2 % in B33), well within 3 %."""
    vol = math.pi * R * R * DRAFT
    omegas = [0.5, 2.0]
    out = {}
    for name, geometry in (("revolution", {"type": "revolution", "profile": CYLINDER}),
                           ("cylinder", {"type": "cylinder", "radius": R, "length": FREEBOARD + DRAFT,
                                         "center": [0.0, 0.0, (DRAFT - FREEBOARD) / 2]})):
        body = BemBody("float", geometry, (0.0, 0.0, 0.1), RHO * vol, 0.25, ("Heave",))
        ds = compute([body], rho=RHO, g=G, depth=np.inf, omegas=omegas, progress=False)
        out[name] = ds.sel(radiating_dof="float__Heave", influenced_dof="float__Heave")
        assert ds.attrs["mirror_symmetry_used"] and ds.attrs["lid_panels"]["float"] > 0
    rev, cyl = out["revolution"], out["cylinder"]
    for var in ("added_mass", "radiation_damping"):
        np.testing.assert_allclose(rev[var].values, cyl[var].values, rtol=0.03)
        assert np.all(rev[var].values > cyl[var].values)   # the larger (circle-area) hull
    # through compute's frames and netCDF layout: K33 = rho g A_wp exactly, V = pi R^2 d
    assert float(rev["hydrostatic_stiffness"]) == pytest.approx(RHO * G * math.pi * R * R, rel=1e-12)
    assert float(rev["displaced_volume"].squeeze()) == pytest.approx(vol, rel=1e-12)


SCENE = """
name = "wavebot"
[parameters]
r1 = 0.88
r2 = 0.35
draft = 0.16
h2 = 0.37
[water]
rho = 1025.0
[[body]]
name = "float"
mass = "displaced"
inertia = [100.0, 100.0, 150.0]
cog = [0.0, 0.0, 0.1]
[body.geometry]
type = "revolution"
profile = [["{r1}", "-10 mm"], ["{r1}", "{draft}"], ["{r2}", "{draft + h2}"], [0, "{draft + h2}"]]
[[joint]]
name = "heave"
type = "prismatic"
parent = "ground"
child = "float"
axis = [0.0, 0.0, 1.0]
point = [0.0, 0.0, 0.1]
[hydro]
panel_size = 0.3
omega = [1.0]
lid = false
"""


def test_displaced_mass_follows_parameters_and_floats(tmp_path):
    """mass = "displaced" is rho x the closed-form immersed volume, follows {expr} parameters,
    equals rho x the BEM mesh's volume, and the plant rests in equilibrium (linearize accepts
    rest; build_plant raises no not-an-equilibrium warning)."""
    from mbcontrol.analysis import linearize
    from mbcontrol.plant import build_plant

    path = tmp_path / "wavebot.toml"
    path.write_text(SCENE)
    scene = load_scene(path)
    vol = CLOSED["wavebot"][1][0]
    assert scene.bodies[0].mass == pytest.approx(RHO * vol, rel=1e-12)
    deeper = load_scene(path, {"draft": 0.26})           # 0.1 m more of the r1 cylinder
    assert deeper.bodies[0].mass == pytest.approx(RHO * (vol + math.pi * R1 ** 2 * 0.1), rel=1e-12)
    assert deeper.digest() != scene.digest()
    # a box's mesh is exact too: 2 x 1 m, 0.3 m of its 0.5 m height below the surface
    box = SCENE.replace(SCENE[SCENE.index('type = "revolution"'):SCENE.index("[[joint]]")],
                        'type = "box"\nsize = [2.0, 1.0, 0.5]\ncenter = [0.0, 0.0, 0.05]\n')
    (tmp_path / "box.toml").write_text(box)
    assert load_scene(tmp_path / "box.toml").bodies[0].mass == pytest.approx(RHO * 2.0 * 1.0 * 0.3, rel=1e-12)
    dofs = ["float__Heave"]
    source, data = load_hydro_data(scene, dofs)
    assert RHO * float(data["displaced_volume"].sel(body="float")) == pytest.approx(
        scene.bodies[0].mass, rel=1e-12)
    # statics only: a radiation model of no states (the plant is built without radiation)
    none = RadiationModel(A=np.zeros((0, 0)), B=np.zeros((0, 1)), C=np.zeros((1, 0)), D=np.zeros((1, 1)),
                          dofs=tuple(dofs), order=0, fit_error=0.0, entry_errors=np.zeros((1, 1)), report={})
    with warnings.catch_warnings():
        warnings.filterwarnings("error", message=".*not an equilibrium")
        plant = build_plant(scene, HydroModel(tuple(dofs), data, none, source), radiation=False)
    sys = linearize(plant)                               # raises if rest is not an equilibrium
    # its heave stiffness is rho g pi r1^2 (the mesh's exact waterplane) over m + A33(inf)
    a_inf = float(data["added_mass_inf"].sel(radiating_dof="float__Heave", influenced_dof="float__Heave"))
    i_q, i_v = plant.states.index("heave"), plant.states.index("heave__vel")
    assert -sys.A[i_v, i_q] == pytest.approx(RHO * G * math.pi * R1 ** 2 / (scene.bodies[0].mass + a_inf),
                                             rel=1e-9)
    # a body 1 % heavier is not at rest there: the check this test relies on does fire
    (tmp_path / "heavy.toml").write_text(SCENE.replace('mass = "displaced"', f"mass = {1.01 * RHO * vol}"))
    heavy = load_scene(tmp_path / "heavy.toml")
    with pytest.warns(RuntimeWarning, match="not an equilibrium"):
        plant = build_plant(heavy, HydroModel(tuple(dofs), data, none, source), radiation=False)
    with pytest.raises(LinearizationError, match="not an equilibrium"):
        linearize(plant)


def _scene_error(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as err:
        load_scene(path)
    return str(err.value)


@pytest.mark.parametrize("profile, field, expected", [
    ("[[1.0, 0.0]]", r"profile", r"at least 2 \[r, z\] points"),
    ("3.0", r"profile", r"at least 2 \[r, z\] points"),
    ("[[1.0, 0.0], [1.0]]", r"profile\[1\]", r"expected \[r, z\], two numbers"),
    ("[[1.0, 0.0], [-1.0, 1.0]]", r"profile\[1\]", r"r = -1; expected r >= 0"),
    ("[[1.0, 0.5], [1.0, 0.2], [0, 0.2]]", r"profile\[1\]", r"expected z non-decreasing"),
    ("[[1.0, 0.0], [0.0, 0.5], [1.0, 1.0]]", r"profile\[1\]", r"only the top and keel"),
    ("[[1.0, 0.0], [1.0, 0.0]]", r"profile\[1\]", r"repeats the previous point"),
    ("[[1.0, 0.0], [2.0, 0.0]]", r"profile", r"expected a body with height"),
    ("[[1.0, 0.0], [0.5, 0.0], [0.5, 1.0]]", r"profile\[0\]", r"turns back on itself at z = 0"),
    ("[[1.0, 0.0], [\"1 kg\", 1.0]]", r"profile\[1\]", r"kg"),
    ("[[\"{R}\", 0.0], [\"{R}\", \"{-D}\"]]", r"profile\[1\]", r"expected z non-decreasing"),
])
def test_bad_profiles_name_file_body_and_field(tmp_path, profile, field, expected):
    text = SCENE.replace(SCENE[SCENE.index("profile = "):SCENE.index("[[joint]]")],
                         f"profile = {profile}\n").replace("[parameters]", "[parameters]\nR = 1.0\nD = 0.5")
    message = _scene_error(tmp_path, text)
    assert message.startswith(str(tmp_path / "bad.toml")), message
    assert f"body[0].geometry.{field.replace(chr(92), '')}: body 'float': " in message, message
    assert re.search(expected, message), message


@pytest.mark.parametrize("geometry, expected", [
    ('type = "cylinder"\nradius = 1.0\nlength = 1.0', r"body\[0\]\.mass: .*type box or revolution.*"
                                                       r"profile = \[\[R, -f\], \[R, d\], \[0, d\]\]"),
    ('type = "revolution"\nprofile = [[1.0, -2.0], [1.0, -1.0]]', r"body\[0\]\.mass: \"displaced\": the "
                                                                   r"geometry has no volume below"),
])
def test_displaced_needs_a_geometry_with_an_exact_volume(tmp_path, geometry, expected):
    text = SCENE.replace(SCENE[SCENE.index("type = \"revolution\""):SCENE.index("[[joint]]")], geometry + "\n")
    assert re.search(expected, _scene_error(tmp_path, text))
    bare = SCENE.replace(SCENE[SCENE.index("[body.geometry]"):SCENE.index("[[joint]]")], "")
    assert re.search(r"needs the body's displaced volume: from its \[body.geometry\].*or from the BEM data "
                     r"of \[hydro\] source", _scene_error(tmp_path, bare))


def test_hydro_checks_name_body_and_field():
    """BemBodies made in code (not from a scene) are checked too, naming body and field."""
    with pytest.raises(HydroError, match=r"body 'buoy': geometry\.profile\[2\]: .*z non-decreasing"):
        hull_mesh(BemBody("buoy", {"type": "revolution", "profile": [[1, 0], [1, 2], [0, 1]]}, (0, 0, 0), 1.0, 0.2))
    with pytest.raises(HydroError, match=r"body 'buoy': geometry \(revolution\) lies entirely above"):
        hull_mesh(BemBody("buoy", {"type": "revolution", "profile": [[1, -2], [1, -1]]}, (0, 0, 0), 1.0, 0.2))
    with pytest.raises(HydroError, match=r"body 'buoy': geometry\.center"):
        hull_mesh(BemBody("buoy", {"type": "revolution", "profile": CYLINDER, "center": [0, 0]}, (0, 0, 0), 1.0, 0.2))


def test_obstacle_and_reference_scene_parse():
    """A revolution obstacle parses (the reference scene's keys include profile)."""
    text = SCENE.replace("[hydro]", '[[obstacle]]\nname = "pile"\n[obstacle.geometry]\ntype = "revolution"\n'
                         'center = [5.0, 0.0, 0.0]\nprofile = [[0.3, -1.0], [0.3, 10.0]]\n[hydro]')
    scene = parse_scene(tomllib.loads(text), Path("with_pile.toml"))
    assert scene.obstacles[0].geometry.profile == ((0.3, -1.0), (0.3, 10.0))
