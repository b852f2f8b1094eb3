"""What the linear model's envelope costs a controller, checked on the plant that covers large
motions (mbcontrol.studies.design.envelope_gain, `mbcontrol design` on a nonlinear scene).

References independent of the code under test: the validity check's own limits (the draft
times DRAFT_FACTOR, 30 deg) for the excursion ratios, by hand; linear theory's prediction for
the lifted law (the frequency-domain solution from the BEM data), which the nonlinear plant
must fall below once the sphere's relative heave passes the linear range (the published
nonlinear codes fall below the linear ones in steep waves: tests/features/plant/test_nonlinear_fk.py).
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from mbcontrol import waves
from mbcontrol import defaults
from mbcontrol.plant import build_plant
from mbcontrol.studies.design import design
from mbcontrol.studies.design.envelope_gain import excursion_ratios

SCENE = Path(__file__).resolve().parents[2] / "plant" / "sphere_nonlinear.toml"


def test_excursion_ratios_are_the_checks_own_limits():
    excursions = {"float": {"relative_heave_significant": 2.0, "relative_heave_limit_m": 4.0,
                            "roll_significant": math.radians(15.0)},
                  "spar": {"relative_heave_limit_m": None, "pitch_significant": 0.1}}
    ratios = excursion_ratios(excursions)
    ANGLE_MAX_RAD, DRAFT_FACTOR = (defaults.get("validity.angle_max"),
                                   defaults.get("validity.draft_factor"))
    assert ratios["float relative heave"] == pytest.approx(2.0 / (DRAFT_FACTOR * 4.0))
    assert ratios["float roll"] == pytest.approx(math.radians(15.0) / ANGLE_MAX_RAD)
    assert ratios["spar pitch"] == pytest.approx(0.1 / ANGLE_MAX_RAD)
    assert "spar relative heave" not in ratios          # a submerged body: no draft


@pytest.fixture(scope="module")
def reactive_in_a_steep_wave():
    # H 5 m, T 9 s on the R = 5 m sphere: the reactive optimum's motion leaves the envelope
    return design(build_plant(str(SCENE)), waves.regular(5.0, 9.0), "reactive", bounds=False,
                  robust=False)


def test_lifting_the_envelope_is_checked_on_the_nonlinear_plant(reactive_in_a_steep_wave):
    result = reactive_in_a_steep_wave
    inside, lifted = result.tuner["envelope"], result.envelope_lifted
    assert inside["inside"] and lifted["binds"]
    assert lifted["parameters"]["stiffness"] != result.parameters["stiffness"]
    # past the linear model's range, and still a valid run of the nonlinear plant
    assert lifted["envelope_used"]["sphere relative heave"] > 1.0
    assert result.metrics is not None and lifted["valid"], lifted["invalid_reasons"]
    # linear theory overstates what the lifted law absorbs once the motion is that large
    assert lifted["mean_power_W"] < 0.97 * lifted["predicted_power_W"]
    assert lifted["gain_W"] == pytest.approx(lifted["mean_power_W"]
                                             - result.metrics["mean_power_W"])
    assert result.to_dict()["envelope_lifted"]["binds"] is True


def test_a_linear_scene_reports_no_lifted_envelope():
    result = design(build_plant("sphere"), waves.regular(1.0, 9.0), "passive", bounds=False)
    assert result.envelope_lifted is None and result.to_dict()["envelope_lifted"] is None
