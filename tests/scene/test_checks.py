"""Bad scenes: every one raises a SceneError that names the file, the field and what was
expected (DESIGN.md, "Errors are explicit"). Each is a one-line variant of the valid fixture
(`scene_fixture.VALID`, two bodies on revolute joints), written to tmp_path, so each test shows
exactly what it breaks."""
from __future__ import annotations

import math
import re

import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene
from tests.helpers.scene_fixture import B_HYDRO, VALID, fails, hydro_table, jb_type, variant, write

# ------------------------------------------------------------------------------ bad scenes

def test_unknown_top_level_key(tmp_path):
    path = write(tmp_path, variant(('name = "two_link"', 'name = "two_link"\nbodys = 3')))
    with fails(path, "bodys", r"unknown key \(did you mean 'body'\?\); expected one of name, "):
        load_scene(path)


def test_unknown_key_in_body_with_hint(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0", "masss = 20.0")))
    with fails(path, "body[1].masss", r"unknown key \(did you mean 'mass'\?\); expected one of "
                                      r"name, mass, inertia, cog, geometry, hydro"):
        load_scene(path)


def test_unknown_key_in_body_without_hint(tmp_path):
    # nothing close to "colour": no hint, still the list of keys
    path = write(tmp_path, variant(("mass = 20.0", "mass = 20.0\ncolour = \"red\"")))
    with fails(path, "body[1].colour", r"unknown key; expected one of name, mass"):
        load_scene(path)


def test_unknown_key_in_joint(tmp_path):
    path = write(tmp_path, variant(('parent = "a"', 'prent = "a"')))
    with fails(path, "joint[1].prent", r"unknown key \(did you mean 'parent'\?\)"):
        load_scene(path)


def test_missing_body_mass(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0\n", "")))
    with fails(path, "body[1].mass", "missing required field"):
        load_scene(path)


def test_missing_joint_child(tmp_path):
    path = write(tmp_path, variant(('child = "b"\n', "")))
    with fails(path, "joint[1].child", "missing required field"):
        load_scene(path)


def test_missing_point_of_revolute_joint(tmp_path):
    path = write(tmp_path, variant(("point = [1.0, 0.0, 0.0]\n", "")))
    with fails(path, "joint[1].point", "missing required field"):
        load_scene(path)


@pytest.mark.parametrize("mass", ["0.0", "-5.0", '"-5 kg"'])
def test_non_positive_mass(tmp_path, mass):
    path = write(tmp_path, variant(("mass = 20.0", f"mass = {mass}")))
    with fails(path, "body[1].mass", r"expected a finite positive number, got -?(0|5)\.0"):
        load_scene(path)


def test_infinite_mass(tmp_path):
    # inf is valid TOML; an infinite mass would turn the mass matrix into NaNs downstream
    path = write(tmp_path, variant(("mass = 20.0", "mass = inf")))
    with fails(path, "body[1].mass", r"expected a finite positive number, got inf"):
        load_scene(path)


def test_inertia_not_symmetric(tmp_path):
    path = write(tmp_path, variant(("inertia = [4.0, 5.0, 6.0]",
                                    "inertia = [[4, 0.5, 0], [0, 5, 0], [0, 0, 6]]")))
    with fails(path, "body[1].inertia", "expected a symmetric inertia matrix"):
        load_scene(path)


def test_inertia_diagonal_not_positive_definite(tmp_path):
    path = write(tmp_path, variant(("inertia = [4.0, 5.0, 6.0]", "inertia = [1, -1, 1]")))
    with fails(path, "body[1].inertia", r"expected a positive definite inertia matrix"):
        load_scene(path)


def test_inertia_matrix_with_negative_eigenvalue(tmp_path):
    # [[1, 2, 0], [2, 1, 0], [0, 0, 1]] has eigenvalues -1, 1, 3 (1 +- 2 from the 2x2 block):
    # positive diagonal, symmetric, yet indefinite.
    path = write(tmp_path, variant(("inertia = [4.0, 5.0, 6.0]",
                                    "inertia = [[1, 2, 0], [2, 1, 0], [0, 0, 1]]")))
    with fails(path, "body[1].inertia",
               r"expected a positive definite inertia matrix .*eigenvalues \[-1\. +1\. +3\.\]"):
        load_scene(path)


def test_inertia_ragged_matrix(tmp_path):
    path = write(tmp_path, variant(("inertia = [4.0, 5.0, 6.0]",
                                    "inertia = [[4, 0, 0], [0, 5], [0, 0, 6]]")))
    with fails(path, "body[1].inertia", r"expected \[Ixx, Iyy, Izz\] or a 3x3 matrix"):
        load_scene(path)


def test_inertia_infinite(tmp_path):
    path = write(tmp_path, variant(("inertia = [4.0, 5.0, 6.0]", "inertia = [inf, 5.0, 6.0]")))
    with fails(path, "body[1].inertia", r"expected finite numbers"):
        load_scene(path)


def test_unknown_parent(tmp_path):
    path = write(tmp_path, variant(('parent = "a"', 'parent = "c"')))
    with fails(path, "joint[1].parent", r"unknown body 'c'; expected 'ground' or one of a, b"):
        load_scene(path)


def test_unknown_child(tmp_path):
    path = write(tmp_path, variant(('child = "b"', 'child = "c"')))
    with fails(path, "joint[1].child", r"unknown body 'c'; expected one of a, b"):
        load_scene(path)


def test_joints_forming_a_loop(tmp_path):
    # a's joint now hangs from b, and b's from a: a -> b -> a, nothing reaches ground
    path = write(tmp_path, variant(('parent = "ground"', 'parent = "b"')))
    with pytest.raises(SceneError, match=re.escape(f"{path}: joints form a loop: a -> b -> a; "
                                                   "expected a tree")):
        load_scene(path)


def test_body_without_joint(tmp_path):
    body_c = ('\n\n[[body]]\nname = "c"\nmass = 1.0\ninertia = [1, 1, 1]\ncog = [0, 0, 0]\n'
              'hydro = false')
    path = write(tmp_path, variant((B_HYDRO, B_HYDRO + body_c)))
    with fails(path, "body[2]", r"no joint has body 'c' as child; give it a 'free' or 'fixed' "
                                r"joint to ground"):
        load_scene(path)


def test_two_joints_on_the_same_child(tmp_path):
    # jb now also has child a (from b, so it is not a self-joint): a has two parent joints
    path = write(tmp_path, variant(('child = "b"', 'child = "a"'),
                                   ('parent = "a"', 'parent = "b"')))
    with fails(path, "joint[1].child", r"body 'a' already has a parent joint; joints must form "
                                       r"a tree"):
        load_scene(path)


def test_free_joint_with_a_body_parent(tmp_path):
    path = write(tmp_path, variant(jb_type("free"),
                                   ("[[pto]]\nname = \"pb\"\njoint = \"jb\"\ndamping = 2.0\n", "")))
    with fails(path, "joint[1].parent", "a free joint must connect to 'ground'"):
        load_scene(path)


def test_zero_axis(tmp_path):
    path = write(tmp_path, variant(("axis = [0.0, 0.0, 1.0]", "axis = [0.0, 0.0, 0.0]")))
    with fails(path, "joint[1].axis", r"expected a non-zero direction, got \[0\.0, 0\.0, 0\.0\]"):
        load_scene(path)


def test_bad_type_mass_string(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0", 'mass = "heavy"')))
    with fails(path, "body[1].mass", r"expected a number or '<number> <unit>', got 'heavy' "
                                     r"\(SI unit kg\)"):
        load_scene(path)


def test_bad_type_cog_two_entries(tmp_path):
    path = write(tmp_path, variant(("cog = [1.5, 0.0, 0.0]", "cog = [1.5, 0.0]")))
    with fails(path, "body[1].cog",
               r"expected three finite numbers \[x, y, z\], got \[1\.5, 0\.0\]"):
        load_scene(path)


def test_bad_type_axis_string(tmp_path):
    path = write(tmp_path, variant(("axis = [0.0, 0.0, 1.0]", 'axis = "z"')))
    with fails(path, "joint[1].axis", r"expected a list of numbers, got 'z'"):
        load_scene(path)


def test_bad_type_boolean_for_number(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0", "mass = true")))
    with fails(path, "body[1].mass", r"expected a number, got the boolean True"):
        load_scene(path)


def test_bad_type_number_for_boolean(tmp_path):
    path = write(tmp_path, variant((B_HYDRO, "cog = [1.5, 0.0, 0.0]\nhydro = 0")))
    with fails(path, "body[1].hydro", r"expected true or false, got 0"):
        load_scene(path)


def test_mass_unit_for_a_length(tmp_path):
    path = write(tmp_path, variant(("cog = [1.5, 0.0, 0.0]", 'cog = ["3 kg", 0.0, 0.0]')))
    with fails(path, "body[1].cog", r"expected a length in one of \['cm', 'km', 'm', 'mm'\], "
                                    r"got '3 kg' \(SI unit m\)"):
        load_scene(path)


def test_angle_unit_for_a_mass(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0", 'mass = "5 deg"')))
    with fails(path, "body[1].mass", r"expected a mass in one of \['g', 'kg', 't'\], "
                                     r"got '5 deg' \(SI unit kg\)"):
        load_scene(path)


def test_unit_in_a_plain_si_field(tmp_path):
    # PTO damping has no unit name in the scene format (N m s/rad here): plain numbers only
    path = write(tmp_path, variant(("damping = 2.0", 'damping = "2 N*m*s/rad"')))
    with fails(path, "pto[0].damping", r"expected a plain SI number here, got a unit in "
                                       r"'2 N\*m\*s/rad'"):
        load_scene(path)


def test_units_are_converted(tmp_path):
    # the good path of the same fields: "mm" for a length, "t" for a mass, "deg" for headings
    path = write(tmp_path, variant(("cog = [1.5, 0.0, 0.0]", 'cog = ["1500 mm", 0.0, "2 cm"]'),
                                   ("mass = 20.0", 'mass = "0.02 t"'),
                                   hydro_table('headings = ["90 deg"]\n'
                                               'omega = ["0.5 Hz", "1 Hz"]')))
    s = load_scene(path)
    # factors 1e-3, 1e-2, 1e3, pi/180 and 2 pi: one multiplication each, so 1e-15 relative
    assert s.body("b").cog == pytest.approx((1.5, 0.0, 0.02), rel=1e-15)
    assert s.body("b").mass == pytest.approx(20.0, rel=1e-15)
    assert s.hydro.headings == pytest.approx((math.pi / 2,), rel=1e-15)
    assert s.hydro.omega == pytest.approx((math.pi, 2 * math.pi), rel=1e-15)


def test_unknown_joint_type(tmp_path):
    path = write(tmp_path, variant(jb_type("hinge")))
    with fails(path, "joint[1].type", r"expected one of revolute, prismatic, fixed, free, "
                                      r"got 'hinge'"):
        load_scene(path)


def test_pto_on_unknown_joint(tmp_path):
    path = write(tmp_path, variant(('joint = "jb"', 'joint = "jc"')))
    with fails(path, "pto[0].joint", r"expected a joint with one coordinate .* got 'jc'; "
                                     r"candidates: ja, jb"):
        load_scene(path)


def test_pto_on_fixed_joint(tmp_path):
    path = write(tmp_path, variant(jb_type("fixed")))
    with fails(path, "pto[0].joint", r"expected a joint with one coordinate \(revolute, prismatic,"
                                     r" or free with one dof\); got 'jb'; candidates: ja$"):
        load_scene(path)


def test_invalid_toml(tmp_path):
    path = write(tmp_path, variant(("mass = 20.0", "mass = = 20.0")))
    # "mass = = 20.0" is body b's mass line, line 13 of VALID: tomllib reports the position
    with pytest.raises(SceneError, match=re.escape(f"{path}: not valid TOML: ") + r".*line 13"):
        load_scene(path)


def test_missing_file(tmp_path):
    path = tmp_path / "nowhere.toml"
    with pytest.raises(SceneError, match=re.escape(f"{path}: no such scene file")):
        load_scene(path)


def test_unknown_catalogue_name():
    with pytest.raises(SceneError, match=r"^hinged_bargee: not a file and not a catalogue model; "
                                         r"the catalogue has .*hinged_barge, hinged_raft"):
        load_scene("hinged_bargee")


def test_hydro_loads_without_geometry_or_hydro_file(tmp_path):
    path = write(tmp_path, variant((B_HYDRO, "cog = [1.5, 0.0, 0.0]")))   # b: hydro on
    with fails(path, "body[1].geometry", r"body 'b' takes hydrodynamic loads but has no geometry, "
                                         r"and the scene gives no hydrodynamic data \(\[hydro\] "
                                         r"file, or source"):
        load_scene(path)


def test_hydro_loads_with_a_hydro_file_need_no_geometry(tmp_path):
    # the same body is fine when precomputed hydro data are named (the catalogue's case)
    text = VALID.replace("hydro = false\n", "")          # both bodies take hydro loads
    path = write(tmp_path, variant(hydro_table('file = "x.nc"'), base=text))
    scene = load_scene(path)
    assert [b.hydro for b in scene.bodies] == [True, True]
    assert scene.hydro.file == str(tmp_path / "x.nc")     # relative to the scene file


def test_duplicate_body_names(tmp_path):
    path = write(tmp_path, variant(('name = "b"', 'name = "a"'), ('child = "b"', 'child = "a"')))
    with fails(path, "body[1].name", r"duplicate name 'a'"):
        load_scene(path)


@pytest.mark.parametrize("name", ["b.1", "b__1", "ground", "b 1"])
def test_bad_body_names(tmp_path, name):
    path = write(tmp_path, variant(('name = "b"', f'name = "{name}"'),
                                   ('child = "b"', f'child = "{name}"')))
    with fails(path, "body[1].name", re.escape(f"expected a name without dots, spaces or '__' "
                                               f"(and not 'ground'), got {name!r}")):
        load_scene(path)


def test_bad_joint_name(tmp_path):
    path = write(tmp_path, variant(('name = "jb"', 'name = "j.b"'),
                                   ('joint = "jb"', 'joint = "j.b"')))
    with fails(path, "joint[1].name", r"expected a name without dots"):
        load_scene(path)


def test_frequency_list_not_increasing(tmp_path):
    path = write(tmp_path, variant(hydro_table("omega = [2.0, 1.0]")))
    with fails(path, "hydro.omega",
               r"expected positive, strictly increasing frequencies \(rad/s\)"):
        load_scene(path)


def test_frequency_table_min_above_max(tmp_path):
    path = write(tmp_path, variant(hydro_table("omega = { min = 3.0, max = 1.0, n = 10 }")))
    with fails(path, "hydro.omega", r"expected min < max"):
        load_scene(path)


def test_frequency_table_fractional_n(tmp_path):
    # n counts grid points: 2.5 must not be truncated silently to 2
    path = write(tmp_path, variant(hydro_table("omega = { min = 1.0, max = 3.0, n = 2.5 }")))
    with fails(path, "hydro.omega.n", r"expected an integer number of frequencies >= 2, got 2\.5"):
        load_scene(path)


def test_frequency_table_good(tmp_path):
    path = write(tmp_path, variant(hydro_table('omega = { min = "0.5 Hz", max = "1 Hz", n = 3 }')))
    # 0.5 Hz = pi rad/s, 1 Hz = 2 pi rad/s; linspace midpoint 1.5 pi; 1e-15 = one rounding
    assert load_scene(path).hydro.omega == pytest.approx(
        (math.pi, 1.5 * math.pi, 2 * math.pi), rel=1e-15)
