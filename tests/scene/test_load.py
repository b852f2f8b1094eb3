"""Scene files load: the valid fixture, the catalogue models with the numbers of their files,
and a stable content digest. Bad scenes are in test_checks.py, units in test_units.py."""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.scene import catalogue_dir, list_models, load_scene
from tests.helpers.scene_fixture import VALID, variant, write


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
    assert s.hydro.headings == (0.0,) and s.hydro.radiation_tol == 0.006


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
