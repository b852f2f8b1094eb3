"""A reactive law tuned within the robustness floors (reactive_tuning(robust=True); `design`
and `export` by default, --robust kept as an alias; sweep --design too, --aggressive lifts it): the tuner keeps min |1 + L| >= 0.52 on the BEM data's
impedance; the margins are then read off the linearised state-space plant
(controllers.margins), a second derivation, and must meet the floors: gain margin 2 and
phase margin 30 deg (0.52 guarantees 2.08 and 30.1 deg). The issue's case: rm3, JONSWAP Hs 2 m, Tp 10 s, designed at gain margin 1.03."""
import json

import pytest

from mbcontrol import waves
from mbcontrol.cli import main
from mbcontrol.controllers.margins import loop_margins
from mbcontrol.controllers.reactive import reactive_tuning
from mbcontrol.controllers.robustness import STABILITY_FLOOR, robustness
from mbcontrol.plant import build_plant


@pytest.fixture(scope="module")
def rm3():
    return build_plant("rm3")


def test_a_robust_reactive_law_meets_the_floors_at_little_cost(rm3):
    """Measured with a floor of 0.5 (0.52 now): stiffness -246 -> -126 kN/m, gain margin 1.03
    -> 2.00, phase margin 12.4 -> 58.9 deg, min |1 + L| 0.025 -> 0.49999 (state space)
    against 0.5 (the tuner's grid), predicted power 119.2 -> 117.1 kW (-1.8 %)."""
    band = (float(rm3.hydro.omega[0]), float(rm3.hydro.omega[-1]))
    sea = waves.irregular(2.0, 10.0, duration=600.0, data_band=band)
    c0, k0, p0 = reactive_tuning(rm3, sea, "pto", envelope=True)
    c1, k1, p1 = reactive_tuning(rm3, sea, "pto", envelope=True, robust=True)
    fragile = loop_margins(rm3, {"damping": c0, "stiffness": k0})
    firm = loop_margins(rm3, {"damping": c1, "stiffness": k1})
    assert not robustness(fragile)["meets"] and fragile.gain_margin < 1.1
    assert firm.stable and firm.stability_margin >= STABILITY_FLOOR * (1 - 1e-3)
    assert robustness(firm)["meets"], robustness(firm)["why"]
    assert 0.9 * p0 <= p1 <= p0


def test_aggressive_goes_with_design(capsys):
    code = main(["sweep", "rm3", "--hs", "1", "--tp", "8", "--workers", "0", "--controller",
                 "reactive", "--aggressive"])
    assert code == 1 and "--aggressive" in capsys.readouterr().err


def test_design_robust_reports_the_floors_met(rm3, capsys):
    code = main(["design", "rm3", "--controller", "reactive", "--wave", "jonswap", "--hs", "2",
                 "--tp", "10", "--duration", "120", "--bounds", "off", "--robust", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    assert d["tuner"]["robust"] is True and d["tuner"]["robustness"]["meets"] is True
