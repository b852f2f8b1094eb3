"""A WEC-Sim user's RM3 on the first try (issue 58): tests/hydro/data/wecsim_rm3.toml is written
from WEC-Sim's RM3 example: its rm3.out as it comes, mass = "displaced" on both bodies, the WAMIT
CoGs, the catalogue's joints and PTO, and no reader or fit options. References: the catalogue's
rm3 (models/rm3.toml: masses rho x mean(VOLX, VOLY, VOLZ) of rm3.out written out by hand, and
every option its authors chose) for masses and power; the scene's z-up twin for the frame rule
(the same device, so the same numbers exactly)."""
import json
import re
import tomllib
from pathlib import Path

import pytest

from mbcontrol.cli import main
from mbcontrol.errors import HydroError
from mbcontrol.plant import build_plant
from mbcontrol.scene import DISPLACED_PENDING, catalogue_dir, load_scene
from tests.helpers.reader_data import RM3

DATA = Path(__file__).resolve().parents[2] / "hydro" / "data"
NED, ZUP = DATA / "wecsim_rm3.toml", DATA / "wecsim_rm3_zup.toml"
pytestmark = [pytest.mark.skipif(not RM3.exists(), reason="reference data not found"),
              pytest.mark.filterwarnings("ignore::mbcontrol.hydro.readers.HydroCleaningWarning")]
WAVE = ["--wave", "regular", "--height", "2", "--period", "8", "--duration", "200", "--json"]


def _power(capsys, model) -> float:
    assert main(["simulate", str(model), *WAVE]) == 0
    return json.loads(capsys.readouterr().out)["ptos"]["pto"]["mean_power_W"]


@pytest.fixture(scope="module")
def plant():
    return build_plant(load_scene(NED))


def test_the_first_simulate_gives_the_catalogues_power(capsys):
    """Same wave, same PTO damping: within 1 % of the catalogue (measured 0.07 %: 182.40 kW
    against 182.52 kW; the fits differ, 0-2.76 rad/s at 1 % against 0-3 rad/s at 2 %)."""
    mine, catalogue = _power(capsys, NED), _power(capsys, "rm3")
    assert mine == pytest.approx(catalogue, rel=0.01)


def test_displaced_masses_are_the_catalogues_and_are_stated(plant):
    scene = load_scene(NED)
    assert all(b.mass_from == DISPLACED_PENDING for b in scene.bodies)     # not guessed at load
    given = tomllib.loads((catalogue_dir() / "rm3.toml").read_text())["body"]
    expected = {"float": given[0]["mass"], "spar": given[1]["mass"]}       # 725833.3333, 886688.3333
    for body in plant.scene.bodies:
        assert body.mass == pytest.approx(expected[body.name], rel=1e-9)
        assert re.search(rf"rho 1000 kg/m\^3 x {expected[body.name] / 1000:.7g} m\^3, the displaced "
                         rf"volume of BEM body '{body.name}' in rm3.out", body.mass_from)
    from mbcontrol.plant import provenance
    assert set(provenance(plant)["masses"]) == {"float", "spar"}


def test_the_fit_band_defaults_to_where_the_device_moves_and_meets_the_tolerance(plant):
    """No fit_omega_max: the band ends where the device's wave motion falls under 1 % of its
    peak (2.76 rad/s), below rm3.out's repaired top (damping set to 0 at 5.12-5.2 rad/s) and
    above the float's heave resonance; the default tolerance is met (0.71 %, 36 states)."""
    hydro = plant.hydro
    assert 2.5 < hydro.fit_omega_max < 3.0
    assert hydro.radiation.fit_error <= load_scene(NED).hydro.radiation_tol == 0.01
    assert list(hydro.dofs) == ["spar__Heave", "float__Heave"]              # the joints' DOFs


def test_the_z_up_twin_is_the_same_scene():
    ned, zup = load_scene(NED), load_scene(ZUP)
    for a, b in zip(ned.bodies, zup.bodies):
        assert a.cog == b.cog and a.inertia == b.inertia
    for a, b in zip(ned.joints, zup.joints):
        assert a.point == b.point and a.axis == (0.0, 0.0, 1.0) and b.axis == (0.0, 0.0, -1.0)
    assert build_plant(zup).hydro.radiation.fit_error == pytest.approx(
        build_plant(ned).hydro.radiation.fit_error, rel=1e-12)


def test_the_z_up_scene_without_the_key_is_caught(tmp_path):
    text = ZUP.read_text().replace('frame = "z-up"', "").replace(
        '"../../../../shared', f'"{RM3.parents[2]}')
    (tmp_path / "zup.toml").write_text(text)
    with pytest.raises(HydroError, match=r"scene body 'spar' with y and z negated lies within it: the "
                                         r"scene looks written z-up.*add frame = \"z-up\" to the scene"):
        build_plant(load_scene(tmp_path / "zup.toml"))
