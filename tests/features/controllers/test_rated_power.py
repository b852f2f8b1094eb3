"""A PTO's rated power (`[[pto]] rated_power`): the tuners detune to it in a sea that would
give more, and a sweep's weighted figures cap each sea's power at it (the power matrix a
project is judged by). rm3 rated at 300 kW, a test copy of the catalogue scene."""
import json

import pytest
from tests.helpers.drivetrain_scenes import catalogue_copy

from mbcontrol import waves
from mbcontrol.cli import main
from mbcontrol.controllers.passive import optimal_damping
from mbcontrol.controllers.reactive import reactive_tuning
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene

RATED = 3e5


def rated_rm3(folder):
    """rm3 with its PTO rated at 300 kW (the PTO table is the scene's last)."""
    return catalogue_copy(folder, "rm3", "rated", '\nrated_power = "300 kW"\n')


def test_the_scene_key_reads_in_watts(tmp_path):
    assert load_scene(str(rated_rm3(tmp_path))).ptos[0].rated_power == RATED


@pytest.mark.parametrize("tuner", ["passive", "reactive"])
def test_tuners_detune_to_the_rated_power(tmp_path, tuner):
    """In Hs 4.75 m, Tp 12.3 s the tuned laws inside the envelope predict 0.69 (passive) and
    0.70 MW (reactive); rated at 300 kW they predict exactly that, and in Hs 1.25 m, where
    they stay below it, the rating changes nothing."""
    plant = build_plant(load_scene(str(rated_rm3(tmp_path))))
    band = (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))

    def tune(hs, tp, **kw):
        sea = waves.irregular(hs, tp, duration=600.0, data_band=band)
        if tuner == "passive":
            return optimal_damping(plant, sea, pto="pto", envelope=True, **kw)[-1]
        return reactive_tuning(plant, sea, "pto", envelope=True, **kw)[-1]
    assert tune(4.75, 12.3) > 1.3 * RATED
    assert tune(4.75, 12.3, rated_power=RATED) == pytest.approx(RATED, rel=1e-3)
    assert tune(4.75, 12.3, rated_power=RATED) <= RATED
    small = tune(1.25, 9.3)
    assert small < RATED and tune(1.25, 9.3, rated_power=RATED) == pytest.approx(small, rel=1e-6)


def test_a_designed_sweep_reports_its_rated_power(tmp_path, capsys):
    """The scene's rating reaches the tuner (`--design`) and the summary: the big sea's
    simulated power sits at the rating (linear theory predicts it exactly; the nonlinear run
    within 10 %), the small one under it, and the weighted figures cap each sea at it."""
    seas = tmp_path / "seas.csv"
    seas.write_text("Hm0,Tp,weights\n1.25,9.3,0.5\n4.75,12.3,0.5\n")
    code = main(["sweep", str(rated_rm3(tmp_path)), "--seas", str(seas), "--duration", "300",
                 "--dt", "0.1", "--workers", "0", "--controller", "reactive", "--design",
                 "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    s = json.loads(out)
    assert s["rated_power_W"] == RATED and s["valid_cases"] == 2
    small, big = s["seas"]
    assert big["predicted_power_W"] == pytest.approx(RATED, rel=1e-3)
    assert big["mean_power_W"] == pytest.approx(RATED, rel=0.10)
    assert small["mean_power_W"] < 0.5 * RATED
    capped = [min(r["mean_power_W"], RATED) for r in s["seas"]]
    assert s["weighted_mean_power_W"] == pytest.approx(0.5 * sum(capped), rel=1e-12)
