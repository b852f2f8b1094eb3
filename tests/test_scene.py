"""Scene files: the catalogue models load with the numbers of their files, and every bad scene
raises a SceneError that names the file, the field and what was expected (DESIGN.md,
"Errors are explicit").

Bad scenes are one-line variants of a small valid fixture (`VALID`, two bodies on revolute
joints), written to tmp_path, so each test shows exactly what it breaks.
"""
from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import catalogue_dir, list_models, load_scene
from mbcontrol.units import UnitError, to_si

# ------------------------------------------------------------------------------ fixtures

VALID = """\
name = "two_link"
description = "test fixture: two bodies on revolute joints"

[[body]]
name = "a"
mass = 10.0
inertia = [1.0, 2.0, 3.0]
cog = [0.5, 0.0, 0.0]
hydro = false

[[body]]
name = "b"
mass = 20.0
inertia = [4.0, 5.0, 6.0]
cog = [1.5, 0.0, 0.0]
hydro = false

[[joint]]
name = "ja"
type = "revolute"
parent = "ground"
child = "a"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]

[[joint]]
name = "jb"
type = "revolute"
parent = "a"
child = "b"
point = [1.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]

[[pto]]
name = "pb"
joint = "jb"
damping = 2.0
"""


def variant(*edits: tuple[str, str], base: str = VALID) -> str:
    """VALID with each (old, new) applied; old must occur exactly once, so edits stay precise."""
    text = base
    for old, new in edits:
        assert text.count(old) == 1, f"fixture edit {old!r} is not unique"
        text = text.replace(old, new)
    return text


def write(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def hydro_table(body: str) -> tuple[str, str]:
    """An edit appending a [hydro] table with `body` to VALID."""
    return ("damping = 2.0", "damping = 2.0\n\n[hydro]\n" + body)


def jb_type(kind: str) -> tuple[str, str]:
    """An edit changing the type of joint jb (joint[1])."""
    return ('name = "jb"\ntype = "revolute"', f'name = "jb"\ntype = "{kind}"')


B_HYDRO = "cog = [1.5, 0.0, 0.0]\nhydro = false"       # body b's last lines, unique in VALID


def fails(path: Path, field: str, expected: str):
    """pytest.raises for a SceneError reading '<file>: <field>: <expected...>'.

    `field` is matched literally; `expected` is a regular expression.
    """
    return pytest.raises(SceneError, match=re.escape(f"{path}: {field}: ") + expected)


def test_valid_fixture_loads(tmp_path):
    # The base of every bad-scene variant below must itself be valid, or those tests would
    # pass for the wrong reason.
    scene = load_scene(write(tmp_path, VALID))
    assert [b.name for b in scene.bodies] == ["a", "b"]
    assert scene.body("b").mass == 20.0
    assert scene.joint("jb").axis == (0.0, 0.0, 1.0)
    assert scene.ptos[0].joint == "jb" and scene.ptos[0].damping == 2.0


# ------------------------------------------------------------------------ catalogue models

def box_inertia(m, lx, ly, lz):
    """Principal moments of a uniform box about its centre: m (b^2 + c^2) / 12 (any textbook)."""
    return (m * (ly**2 + lz**2) / 12, m * (lx**2 + lz**2) / 12, m * (lx**2 + ly**2) / 12)


def test_list_models_has_both_catalogue_models():
    # Others may add models, so only require these two (the files in models/).
    assert {"hinged_barge", "hinged_raft"} <= set(list_models())
    assert (catalogue_dir() / "hinged_barge.toml").exists()


def test_hinged_barge_values():
    s = load_scene("hinged_barge")
    # Every number below is copied from models/hinged_barge.toml; the comparisons are exact
    # because TOML floats and the SI-number path involve no arithmetic.
    assert s.name == "hinged_barge"
    assert Path(s.path) == catalogue_dir() / "hinged_barge.toml"
    assert (s.water.rho, s.water.g, s.water.depth) == (1000.0, 9.81, math.inf)
    assert [b.name for b in s.bodies] == ["barge1", "barge2"]
    for body, cog in zip(s.bodies, [(0.32, 0.0, 0.0), (0.96, 0.0, 0.0)]):
        assert body.mass == 18.0
        assert body.cog == cog
        # diagonal list [Ixx, Iyy, Izz] becomes a 3x3 tuple of tuples
        assert body.inertia == ((0.195, 0.0, 0.0), (0.0, 0.6, 0.0), (0.0, 0.0, 0.675))
        assert body.hydro is True
        assert body.geometry.kind == "box"
        assert body.geometry.size == (0.6, 0.3, 0.2)
        assert body.geometry.center == cog
        # Independent check of the file's own numbers: a uniform 0.6 x 0.3 x 0.2 m box of
        # 18 kg has these principal moments (the file's comment says so); 1e-12 = rounding.
        np.testing.assert_allclose(np.diag(body.inertia), box_inertia(18.0, 0.6, 0.3, 0.2),
                                   rtol=1e-12)
    pivot, hinge = s.joints
    assert (pivot.name, pivot.type, pivot.parent, pivot.child) == (
        "pivot", "revolute", "ground", "barge1")
    assert pivot.point == (0.0, 0.0, 0.0) and pivot.axis == (0.0, 1.0, 0.0)
    assert (hinge.name, hinge.parent, hinge.child) == ("hinge", "barge1", "barge2")
    assert hinge.point == (0.64, 0.0, 0.0) and hinge.axis == (0.0, 1.0, 0.0)
    assert [j.n_coordinates for j in s.joints] == [1, 1]
    (pto,) = s.ptos
    assert (pto.name, pto.joint, pto.damping, pto.stiffness, pto.force_max) == (
        "hinge_pto", "hinge", 0.5, 0.0, 5.0)
    (fr,) = s.frictions
    assert (fr.joint, fr.viscous, fr.coulomb, fr.velocity_scale) == ("hinge", 0.02, 0.01, 0.01)
    # hydro: "20 mm" -> 0.02 m (one multiplication 20 * 1e-3: <= 1 ulp of rounding)
    assert s.hydro.panel_size == pytest.approx(0.02, rel=1e-15)
    assert Path(s.hydro.file) == catalogue_dir() / "hinged_barge_hydro.nc"
    # three segments: 12 log points in [0.3, 2) + 131 uniform on [2, 15] (0.1 apart) + 8 log
    # points on [15, 30], the shared 15.0 counted once: 12 + 131 + 7 = 150 frequencies
    w = np.array(s.hydro.omega)
    assert len(w) == 150 and w[0] == 0.3 and w[-1] == pytest.approx(30.0, rel=1e-15)
    np.testing.assert_allclose(np.diff(w[12:143]), 0.1, rtol=1e-9)
    np.testing.assert_allclose(w[1:12] / w[:11], (2.0 / 0.3) ** (1 / 12), rtol=1e-12)
    assert s.hydro.dofs == ("Surge", "Heave", "Pitch")
    assert s.hydro.headings == (0.0,) and s.hydro.radiation_tol == 0.01


def test_hinged_raft_values():
    s = load_scene("hinged_raft")
    assert s.name == "hinged_raft"
    assert [b.mass for b in s.bodies] == [18.0, 18.0]
    raft, hinge = s.joints
    assert (raft.type, raft.parent, raft.child) == ("free", "ground", "barge1")
    assert raft.dofs == ("Surge", "Heave", "Pitch")
    assert raft.n_coordinates == 3 and raft.axis is None
    # the file gives no point for the free joint: it defaults to its child's CoG
    assert raft.point == s.body("barge1").cog == (0.32, 0.0, 0.0)
    assert hinge.point == (0.64, 0.0, 0.0) and hinge.axis == (0.0, 1.0, 0.0)
    (pto,) = s.ptos
    assert (pto.joint, pto.damping, pto.stiffness, pto.force_max) == ("hinge", 0.5, 0.0, 5.0)
    (m,) = s.moorings
    assert (m.name, m.body, m.point) == ("bow_line", "barge1", (0.02, 0.0, 0.0))
    assert m.stiffness == (5.0, 0.0, 0.0) and m.damping == (1.0, 0.0, 0.0)
    # the raft shares the barge pair's BEM data: same bodies at the same places
    assert s.hydro.file == load_scene("hinged_barge").hydro.file
    assert s.hydro.dofs == ("Surge", "Heave", "Pitch")


def test_digest_is_stable():
    a, b = load_scene("hinged_barge"), load_scene("hinged_barge")
    assert a.digest() == b.digest()
    assert len(a.digest()) == 64 and a.digest() != load_scene("hinged_raft").digest()
    # Stable across interpreters too (no dependence on hash randomisation or object ids):
    code = "from mbcontrol.scene import load_scene; print(load_scene('hinged_barge').digest())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, "PYTHONHASHSEED": "12345"}, check=True)
    assert out.stdout.strip() == a.digest()


def test_digest_changes_when_a_number_changes(tmp_path):
    text = (catalogue_dir() / "hinged_barge.toml").read_text()
    # Copies in one folder, so the hydro file (stored as an absolute path) is the same.
    same = load_scene(write(tmp_path, text, "copy.toml"))
    changed = load_scene(write(tmp_path, variant(("mass = 18.0\ninertia = [0.195, 0.6, 0.675]\n"
                                                  "cog = [0.96",
                                                  "mass = 18.5\ninertia = [0.195, 0.6, 0.675]\n"
                                                  "cog = [0.96"), base=text), "changed.toml"))
    assert changed.body("barge2").mass == 18.5
    assert same.digest() == load_scene(write(tmp_path, text, "copy2.toml")).digest()  # path-free
    assert changed.digest() != same.digest()


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
    with fails(path, "body[1].geometry", r"body 'b' takes hydrodynamic loads but has no geometry "
                                         r"and the scene has no hydro\.file"):
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


# ----------------------------------------------------------------------------- units.to_si

def test_to_si_conversions():
    # Factors from the SI definitions (1 mm = 1e-3 m, 1 deg = pi/180 rad, 1 Hz = 2 pi rad/s
    # for an angular frequency); one multiplication each: 1e-15 relative covers the rounding.
    assert to_si("25 mm", "length") == pytest.approx(0.025, rel=1e-15)
    assert to_si("25mm", "length") == pytest.approx(0.025, rel=1e-15)     # space optional
    assert to_si("1.5e3 mm", "length") == pytest.approx(1.5, rel=1e-15)
    assert to_si("-2 cm", "length") == pytest.approx(-0.02, rel=1e-15)
    assert to_si("2 km", "length") == 2000.0
    assert to_si("180 deg", "angle") == pytest.approx(math.pi, rel=1e-15)
    assert to_si("5 deg", "angle") == pytest.approx(5 * math.pi / 180, rel=1e-15)
    assert to_si("1 Hz", "frequency") == pytest.approx(2 * math.pi, rel=1e-15)
    assert to_si("0.25 Hz", "frequency") == pytest.approx(math.pi / 2, rel=1e-15)
    assert to_si("3 rad/s", "frequency") == 3.0
    assert to_si("2 t", "mass") == 2000.0
    assert to_si("1 min", "time") == 60.0
    assert to_si("1 kg m^2", "inertia") == 1.0


def test_to_si_plain_numbers():
    # numbers are SI already, whatever the dimension, including no dimension
    for dimension in ("length", "mass", "angle", "frequency", None):
        assert to_si(3, dimension) == 3.0 and isinstance(to_si(3, dimension), float)
        assert to_si(-0.5, dimension) == -0.5
        assert to_si("7", dimension) == 7.0          # a string without a unit is a number
        assert to_si(".5", dimension) == 0.5


@pytest.mark.parametrize("value, dimension, message", [
    ("heavy", "mass", r"expected a number or '<number> <unit>', got 'heavy'"),
    ("", "length", r"expected a number or '<number> <unit>', got ''"),
    ("mm 25", "length", r"expected a number or '<number> <unit>'"),
    ("3 kg", "length", r"expected a length in one of \['cm', 'km', 'm', 'mm'\], got '3 kg'"),
    ("5 deg", "mass", r"expected a mass in one of \['g', 'kg', 't'\], got '5 deg'"),
    ("1 Hz", "angle", r"expected an? angle in one of"),
    ("2 N*s/m", None, r"expected a plain SI number here, got a unit in '2 N\*s/m'"),
    (True, "mass", r"expected a number, got the boolean True"),
    (None, "mass", r"expected a number, got NoneType None"),
    ([1.0], "length", r"expected a number, got list \[1\.0\]"),
])
def test_to_si_errors(value, dimension, message):
    with pytest.raises(UnitError, match=message):
        to_si(value, dimension)
