"""frame = "z-up" (mbcontrol.scene.frames): a scene written in WEC-Sim's frame is turned by pi
about x on load. Reference: the rotation R = diag(1, -1, -1) applied by hand to each field (a
proper rotation: det R = 1, so the frame stays right-handed), and the same scene written NED."""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import parse_scene
from mbcontrol.scene.frames import to_ned

PATH = Path("s.toml")

R = np.diag([1.0, -1.0, -1.0])

ZUP = {
    "frame": "z-up",
    "body": [{"name": "b", "mass": 10.0, "cog": [1.0, 2.0, "-300 mm"],
              "inertia": [[4.0, 0.1, 0.2], [0.1, 5.0, 0.3], [0.2, 0.3, 6.0]],
              "geometry": {"type": "revolution", "center": [0.0, 0.0, 0.5],
                           "profile": [[1.0, 0.2], [1.0, -0.8]]}}],
    "joint": [{"name": "j", "type": "prismatic", "parent": "ground", "child": "b",
               "point": [1.0, 2.0, -0.3], "axis": [0.0, 0.6, 0.8]}],
    "pto": [{"name": "p", "joint": "j", "damping": 1.0}],
    "mooring": [{"name": "m", "body": "b", "point": [1.0, 2.0, -0.3], "stiffness": [1.0, 2.0, 3.0]}],
    "hydro": {"headings": ["30 deg", 0.5], "nonlinear_direction": 0.25},
}


def test_points_axes_inertia_and_headings_are_rotated_by_pi_about_x():
    assert np.linalg.det(R) == pytest.approx(1.0)
    out = to_ned(ZUP, "s.toml")
    body = out["body"][0]
    assert body["cog"] == [1.0, -2.0, pytest.approx(0.3)]
    np.testing.assert_allclose(body["inertia"], R @ np.array(ZUP["body"][0]["inertia"]) @ R.T)
    assert body["geometry"]["center"] == [0.0, -0.0, -0.5]
    assert body["geometry"]["profile"] == [[1.0, -0.2], [1.0, 0.8]]        # still top to keel
    assert out["joint"][0]["point"] == [1.0, -2.0, 0.3] and out["joint"][0]["axis"] == [0.0, -0.6, -0.8]
    assert out["mooring"][0]["point"] == [1.0, -2.0, 0.3]
    assert out["mooring"][0]["stiffness"] == [1.0, 2.0, 3.0]                 # magnitudes stay
    assert out["hydro"]["headings"] == [pytest.approx(-math.radians(30)), -0.5]
    assert out["hydro"]["nonlinear_direction"] == -0.25
    assert ZUP["body"][0]["cog"][2] == "-300 mm"                             # the input untouched


def test_a_z_up_scene_parses_as_its_ned_twin():
    ned = to_ned(ZUP, "s.toml")
    ned.pop("frame")
    zup_scene, ned_scene = parse_scene(ZUP, PATH), parse_scene(ned, PATH)
    assert zup_scene.bodies == ned_scene.bodies and zup_scene.joints == ned_scene.joints
    assert zup_scene.bodies[0].inertia[0][1] == -0.1 and zup_scene.bodies[0].inertia[1][2] == 0.3


def test_a_ned_scene_is_left_as_it_is_and_other_frames_are_refused():
    plain = {k: v for k, v in ZUP.items() if k != "frame"}
    assert to_ned(plain, "s.toml") is plain
    with pytest.raises(SceneError, match=r"s\.toml: frame: expected one of ned, z-up, got 'z_up'"):
        parse_scene({**plain, "frame": "z_up"}, PATH)


def test_a_mesh_file_in_a_z_up_scene_is_refused():
    scene = {**ZUP, "body": [{**ZUP["body"][0], "geometry": {"type": "mesh", "file": "hull.stl"}}]}
    with pytest.raises(SceneError, match=r"body\[0\]\.geometry: a mesh file with frame = \"z-up\""):
        to_ned(scene, "s.toml")
