"""Which BEM body of a [hydro] source is which scene body (mbcontrol.hydro.source): named by
[hydro] source_bodies, or matched by position with the mapping said and noted, and refused when
ambiguous or far; and supplied data that couple bodies a scene declares uncoupled ([hydro]
interaction = false) are refused, not silently kept (mbcontrol.hydro.model)."""
import logging
import re

import numpy as np
import pytest
import xarray as xr

from mbcontrol.errors import HydroError
from mbcontrol.hydro import load_hydro_data
from mbcontrol.scene import catalogue_dir, load_scene
from tests.helpers.reader_data import RM3, SPHERE

pytestmark = [pytest.mark.skipif(not (SPHERE.exists() and RM3.exists()), reason="reference data not found"),
              pytest.mark.filterwarnings("ignore::mbcontrol.hydro.readers.HydroCleaningWarning")]


def _scene(tmp_path, name, *, mapped: bool, edit=lambda text: text):
    """The catalogue scene `name` in a user's folder, reading its WEC-Sim file by absolute path,
    without its converted [hydro] file, with or without its source_bodies."""
    text = (catalogue_dir() / f"{name}.toml").read_text()
    text = re.sub(r'^file = ".*"\s*(#.*)?$', "", text, count=1, flags=re.M)
    source = {"sphere": SPHERE, "rm3": RM3}[name]
    text = re.sub(r'^source = ".*"$', f'source = "{source}"', text, count=1, flags=re.M)
    if not mapped:
        text = re.sub(r"^source_bodies = .*$", "", text, count=1, flags=re.M)
    path = tmp_path / f"my_{name}.toml"
    path.write_text(edit(text))
    return load_scene(path)


def test_by_position_the_mapping_is_said_and_noted_and_gives_the_named_data(tmp_path, caplog):
    """sphere.out's one body sits at the XBODY origin (0, 0, -2) z up = the scene's CoG (0, 0, 2)
    NED: matched at 0 m; the data are those of the explicit source_bodies mapping."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    with caplog.at_level(logging.INFO, logger="mbcontrol"):
        _, by_position = load_hydro_data(_scene(tmp_path / "a", "sphere", mapped=False), ["sphere__Heave"])
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "matched to scene bodies by position" in said and "'sphere' -> 'sphere' (0 m)" in said
    assert any("'sphere' -> 'sphere' (0 m)" in n for n in by_position.attrs["notes"])   # what `mbcontrol hydro` prints
    _, named = load_hydro_data(_scene(tmp_path / "b", "sphere", mapped=True), ["sphere__Heave"])
    for var in ("added_mass", "radiation_damping", "excitation_force", "hydrostatic_stiffness"):
        xr.testing.assert_equal(by_position[var], named[var])


def test_two_bodies_are_matched_by_their_places_not_their_order(tmp_path):
    """rm3.out lists the float (XBODY z = -0.72) then the spar (-21.29). A scene listing the plate
    first gets the float's data on 'float' all the same: its C33 is rho g Awp of the float's
    waterplane, far larger than the plate's (values printed in rm3.out: C(3,3) of body 1)."""
    def plate_first(text):
        head, float_, plate = re.split(r"(?=^\[\[body\]\]\nname = \"(?:float|plate)\")", text, maxsplit=2, flags=re.M)
        rest = re.split(r"(?=^\[\[joint\]\])", plate, maxsplit=1, flags=re.M)
        return head + rest[0] + float_ + rest[1]
    scene = _scene(tmp_path, "rm3", mapped=False, edit=plate_first)
    assert [b.name for b in scene.bodies][:2] == ["plate", "float"]
    _, data = load_hydro_data(scene, ["float__Heave", "plate__Heave"])
    k = data["hydrostatic_stiffness"]
    c_float = float(k.sel(radiating_dof="float__Heave", influenced_dof="float__Heave"))
    c_plate = float(k.sel(radiating_dof="plate__Heave", influenced_dof="plate__Heave"))
    assert c_float > 5 * c_plate        # the float pierces the surface with the larger waterplane
    assert any("'float' -> 'float'" in n and "'spar' -> 'plate'" in n for n in data.attrs["notes"])


def test_a_body_far_from_every_scene_body_is_refused(tmp_path):
    scene = _scene(tmp_path, "sphere", mapped=False,
                   edit=lambda t: t.replace("cog = [0.0, 0.0, 2.0]", "cog = [30.0, 0.0, 2.0]")
                   .replace("point = [0.0, 0.0, 2.0]", "point = [30.0, 0.0, 2.0]"))
    with pytest.raises(HydroError, match=r"my_sphere\.toml: \[hydro\] source_bodies is not given and BEM body "
                                         r"'sphere'.*is farther than 3\.2\d* m.*candidates: 'sphere' 30 m"):
        load_hydro_data(scene, ["sphere__Heave"])


TWIN = """
[[body]]
name = "twin"
mass = 1000.0
inertia = [1.0, 1.0, 1.0]
cog = [1.0, 0.0, 2.0]

[[joint]]
name = "twin_heave"
type = "prismatic"
parent = "ground"
child = "twin"
point = [1.0, 0.0, 2.0]
axis = [0.0, 0.0, 1.0]
"""


def test_two_scene_bodies_near_one_bem_body_are_ambiguous(tmp_path):
    """A second scene body 1 m from the sphere's CoG: both within V^(1/3)/2 = 3.2 m of the one BEM
    body, so the position says nothing; source_bodies must."""
    scene = _scene(tmp_path, "sphere", mapped=False, edit=lambda t: t + TWIN)
    with pytest.raises(HydroError, match=r"has more than one scene body within 3\.2\d* m.*candidates: "
                                         r"'sphere' 0 m, 'twin' 1 m.*source_bodies = \["):
        load_hydro_data(scene, ["sphere__Heave"])


def _with_interaction(tmp_path, name, line):
    text = (catalogue_dir() / f"{name}.toml").read_text()
    text = re.sub(r'^file = "(.*?)"', lambda m: f'file = "{catalogue_dir() / m.group(1)}"\n{line}', text,
                  count=1, flags=re.M)
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return load_scene(path)


def test_interaction_false_with_coupled_data_is_refused(tmp_path):
    """hinged_barge_hydro.nc is a coupled solve: A[barge1 Surge, barge2 Surge] is of the order of
    the diagonal. Dropping only those blocks would keep the other barge's scattered waves in the
    excitation, so the scene is refused, naming the field and the two ways out."""
    scene = _with_interaction(tmp_path, "hinged_barge", "interaction = false")
    with pytest.raises(HydroError, match=r"hinged_barge\.toml: \[hydro\] interaction = false, but the hydro "
                                         r"data .*couple bodies 'barge1' and 'barge2'.*give \[hydro\] omega"):
        load_hydro_data(scene, ["barge1__Heave", "barge2__Heave"])


def test_interaction_false_with_data_solved_apart_is_used(tmp_path):
    """barge_chain's file was computed with each barge alone: its cross blocks are exact zeros."""
    scene = load_scene("barge_chain")
    assert not scene.hydro.interaction
    _, data = load_hydro_data(scene, ["barge1__Heave", "barge2__Heave"])
    a = data["added_mass"].sel(radiating_dof="barge1__Heave", influenced_dof="barge2__Heave").values
    assert np.all(a == 0)
