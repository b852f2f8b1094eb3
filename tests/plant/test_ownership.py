"""Who owns a PTO's force (mbcontrol.plant.ownership): one rule, written once, and every
stage agreeing on a PTO damping the user sets. References: the frequency-domain solution
(the tuner's prediction) for the simulated power, and the simulation itself run with the
same total damping split differently between the scene law and the controller."""
import re
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.analysis import complex_conjugate_bound
from mbcontrol.controllers import make
from mbcontrol.controllers.passive import optimal_damping
from mbcontrol.export.plant import plant_parameters
from mbcontrol.plant import build_plant, controlled_params, linear_params
from mbcontrol.sim import simulate
from mbcontrol.waves import regular

ROOT = Path(__file__).resolve().parents[2]
USER_DAMPING = 1.2e5           # N s/m: a damper the user puts in parallel with the controller
WAVE = regular(1.0, 8.0)


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


def test_the_rule_is_written_once():
    """No module but plant/ownership.py zeroes a PTO law or a Coulomb friction itself."""
    zeroing = re.compile(r'__(damping|stiffness|coulomb)"\s*(\]\s*=|,)\s*0(\.0)?\b')
    found = [f"{path.relative_to(ROOT)}:{n}" for folder in ("mbcontrol", "controllers")
             for path in sorted((ROOT / folder).rglob("*.py"))
             if path.name != "ownership.py"
             for n, line in enumerate(path.read_text().splitlines(), 1) if zeroing.search(line)]
    assert not found, found


def test_the_precedence_rule(sphere):
    scene_law = {"pto__damping": 0.0, "pto__stiffness": 0.0}
    assert controlled_params(sphere) == scene_law
    mine = controlled_params(sphere, {"pto__damping": USER_DAMPING})
    assert mine == {"pto__damping": USER_DAMPING, "pto__stiffness": 0.0}        # the user wins
    whole = controlled_params(sphere, {"pto__damping": USER_DAMPING}, whole=["pto"])
    assert whole == scene_law                          # ... except where the whole force is chosen
    assert linear_params(sphere, ["pto"], {"pto__damping": USER_DAMPING}) == scene_law
    vector = sphere.params(pto__damping=USER_DAMPING)
    assert controlled_params(sphere, vector)["pto__damping"] == USER_DAMPING


def test_every_stage_agrees_on_a_user_set_damping(sphere):
    """A damping the user sets is a damper in parallel with the controller. The bound is over
    the PTO's whole force, so the damper does not move it. The tuner sees the damper as part
    of the plant and tunes the controller's own gain beside it, predicting the controller's
    own power; simulate keeps the damper, so the run gives what the tuner predicts, and the
    same total damping as the scene's law alone gives the same motion. The exported plant
    has the parameters simulate runs a controller with."""
    mine = {"pto__damping": USER_DAMPING}
    bound, bound_mine = (complex_conjugate_bound(sphere, WAVE, params=p).power for p in (None, mine))
    assert bound_mine == pytest.approx(bound, rel=1e-12)
    total, predicted_total = optimal_damping(sphere, WAVE)
    gain, predicted = optimal_damping(sphere, WAVE, params=mine)
    assert gain != pytest.approx(total, rel=1e-3)   # the damper changes the controller's optimum
    assert predicted < predicted_total < bound      # and loses power the controller could take

    def run(controller_gain, params):
        controller = None if controller_gain is None else make("passive", damping=controller_gain)
        return simulate(sphere, WAVE, duration=20 * WAVE.period, dt=WAVE.period / 400,
                        controller=controller, params=params)
    beside = run(gain, mine)
    alone = run(None, {"pto__damping": USER_DAMPING + gain})      # the scene's law does it all
    late = beside["time"].values >= 10 * WAVE.period
    own = -beside["u__pto"].values * beside["pto__velocity"].values
    # the frequency-domain solution; a controller samples and holds its force (0.5-0.7 % less
    # power at 400 samples a period)
    assert float(own[late].mean()) == pytest.approx(predicted, rel=0.01)
    v_alone, v_beside = alone["pto__velocity"].values, beside["pto__velocity"].values
    assert np.max(np.abs(v_beside - v_alone)) <= 0.01 * np.max(np.abs(v_alone))
    ran_with = beside.attrs["parameters"]
    assert ran_with["pto__damping"] == USER_DAMPING
    plain = run(gain, None).attrs["parameters"]
    np.testing.assert_array_equal(plant_parameters(sphere),
                                  [plain[name] for name in sphere.parameters])
