"""Your own BEM results in a scene ([hydro] source, mbcontrol.hydro.source): a copy of a catalogue
scene that names WEC-Sim's file instead of the catalogue's converted one reproduces the
catalogue's hydrodynamics (the reference: the shipped body-frame files, converted from the same
WAMIT and BEMIO files by models/generate_hydro.py), is cached, and says which data it used."""
import logging
import re

import numpy as np
import pytest
import xarray as xr

from mbcontrol.hydro import load_hydro_data, read_netcdf
from mbcontrol.scene import catalogue_dir, load_scene
from tests.helpers.reader_data import SPHERE, WAVESTAR

pytestmark = pytest.mark.skipif(not (SPHERE.exists() and WAVESTAR.exists()),
                                reason=f"reference data not found in {SPHERE.parent.parent}")


def _own_scene(tmp_path, name: str, source, omega: bool = False):
    """The catalogue scene `name` written into a user's folder, its [hydro] file removed and
    its source given as an absolute path (as a user would point at their WEC-Sim files)."""
    text = (catalogue_dir() / f"{name}.toml").read_text()
    text = re.sub(r'^file = ".*"\s*(#.*)?$', "", text, count=1, flags=re.M)
    text = re.sub(r'^source = ".*"$', f'source = "{source}"', text, count=1, flags=re.M)
    if omega:
        text = text.replace("[hydro]\n", "[hydro]\nomega = [0.5, 1.0, 2.0]\n", 1)
    path = tmp_path / f"my_{name}.toml"
    path.write_text(text)
    return load_scene(path)


@pytest.mark.parametrize("name, source", [("sphere", SPHERE), ("wavestar", WAVESTAR)],
                         ids=["WAMIT .out", "BEMIO .h5"])
def test_a_scene_reads_its_own_bem_file(tmp_path, name, source, caplog):
    scene = _own_scene(tmp_path, name, source)
    assert scene.hydro.file is None
    catalogue = load_scene(name)
    dofs = list(read_netcdf(catalogue.hydro.file)["radiating_dof"].values)
    with caplog.at_level(logging.INFO, logger="mbcontrol"):
        described, data = load_hydro_data(scene, dofs)
    assert str(source.resolve()) in described and data.attrs["converted_from"] == source.name
    shipped = read_netcdf(catalogue.hydro.file)
    for var in ("added_mass", "radiation_damping", "added_mass_inf", "excitation_force",
                "hydrostatic_stiffness"):
        # an axisymmetric scene (the sphere) serves every heading from the file's one
        ours = data[var].sel(wave_direction=shipped.wave_direction) \
            if "wave_direction" in data[var].dims else data[var]
        xr.testing.assert_allclose(ours, shipped[var], rtol=1e-12, atol=0)
    assert record_notes(data) == record_notes(shipped)       # the same repairs, said the same way
    # converted once: the second scene reading the same file with the same bodies loads the cache
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="mbcontrol"):
        (tmp_path / "another").mkdir()
        _, again = load_hydro_data(_own_scene(tmp_path / "another", name, source), dofs)
    assert not [r for r in caplog.records if "reading" in r.getMessage()]
    np.testing.assert_array_equal(again["added_mass"].values, data["added_mass"].values)


def record_notes(data):
    return [n for n in data.attrs["notes"] if "restricted" not in n]


def test_the_source_wins_over_omega_and_says_so(tmp_path, caplog):
    scene = _own_scene(tmp_path, "sphere", SPHERE, omega=True)
    assert scene.hydro.omega and scene.hydro.source
    with caplog.at_level(logging.INFO, logger="mbcontrol"):
        described, data = load_hydro_data(scene, ["sphere__Heave"])
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "source sphere.out is used" in said and "omega" in said
    assert data.sizes["omega"] == 240          # WAMIT's frequencies, not the three given


def test_a_missing_source_is_named(tmp_path):
    from mbcontrol.errors import HydroError
    scene = _own_scene(tmp_path, "sphere", tmp_path / "nowhere.out")
    with pytest.raises(HydroError, match=r"source .*nowhere\.out.*no such file; expected a WAMIT"):
        load_hydro_data(scene, ["sphere__Heave"])


def test_the_plant_built_from_the_users_file_is_the_catalogues(tmp_path):
    """The radiation fit is keyed by the data: the same data give the shipped fit."""
    from mbcontrol.plant import build_plant
    own, shipped = build_plant(_own_scene(tmp_path, "sphere", SPHERE)), build_plant("sphere")
    np.testing.assert_array_equal(own.hydro.radiation.A, shipped.hydro.radiation.A)
    np.testing.assert_array_equal(own.p0, shipped.p0)
