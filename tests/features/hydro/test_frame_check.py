"""A scene written z-up (WEC-Sim's convention) is caught (issue 58): WEC-Sim's RM3 with its
CoGs as WEC-Sim writes them (float -0.72 m, plate -21.29 m, z up) against rm3.out's own CoGs
(its Xg, Yg, Zg: the independent statement of where each body's CoG is)."""
from pathlib import Path

import pytest

from mbcontrol.errors import SceneError
from mbcontrol.hydro import converted_source
from mbcontrol.scene import load_scene

MODELS = Path(__file__).resolve().parents[3] / "models"


def _rm3(tmp_path, float_z: str, plate_z: str):
    text = (MODELS / "rm3.toml").read_text()
    text = text.replace('file = "rm3_hydro.nc"\n', "").replace(
        '"../../shared', f'"{MODELS.parents[1]}/shared')
    text = text.replace("cog = [0.0, 0.0, 0.72]", f"cog = [0.0, 0.0, {float_z}]").replace(
        "cog = [0.0, 0.0, 21.29]", f"cog = [0.0, 0.0, {plate_z}]")
    path = tmp_path / "my_rm3.toml"
    path.write_text(text)
    return load_scene(path)


def test_a_z_up_scene_is_refused_naming_the_frame(tmp_path, monkeypatch):
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path / "cache"))
    with pytest.raises(SceneError, match=r"body 'float': cog z = -0.72 m, but rm3.out states its "
                                         r"CoG at z = 0.72 m.*written z-up.*Add frame = \"z-up\".*NED"):
        converted_source(_rm3(tmp_path, "-0.72", "-21.29"))


def test_the_same_scene_in_ned_converts(tmp_path, monkeypatch):
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path / "cache"))
    _, data = converted_source(_rm3(tmp_path, "0.72", "21.29"))
    assert data["cog"].sel(body="float").values[2] == pytest.approx(0.72)


def test_without_source_bodies_the_mapping_says_the_scene_looks_z_up(tmp_path, monkeypatch):
    """Bodies mapped by position: the plate's z-up CoG is 42.6 m from the file's, too far to
    match; the refusal says its mirror lies there."""
    from mbcontrol.errors import HydroError
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path / "cache"))
    scene = _rm3(tmp_path, "-0.72", "-21.29")
    text = Path(scene.path).read_text().replace('source_bodies = ["float", "plate"]\n', "")
    Path(scene.path).write_text(text)
    with pytest.raises(HydroError, match=r"scene body 'plate' with y and z negated lies within "
                                         r"it: the scene looks written z-up"):
        converted_source(load_scene(scene.path))
