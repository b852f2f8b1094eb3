"""`mbcontrol design` with a measured record on the sphere (the shipped 300 s record).

The record's FFT reaches the top of the sphere's WAMIT data, where the radiation damping was
repaired to zero (11.5..12 rad/s) while the excitation is not: the complex-conjugate bound is
infinite there. `simulate` declares it unbounded (validity.UNBOUNDED); `design` used to crash
in the envelope bound's cone programme (cvxpy DCPError on inf / nan coefficients). Now it
exits 0 and states the same: no complex-conjugate or constrained bound, each with the reason
naming the components, the simulate warning, and the bound inside the envelope, which stays
finite. The designed power is checked against references outside `design`: a plain
`mbcontrol simulate` of the same record with the printed settings (the re-run command), the
linear-theory prediction (frequency domain, BEM data) and the envelope bound."""
import json
import math
import shlex

import pytest

from mbcontrol.analysis.validity import UNBOUNDED
from mbcontrol.cli import main

SHIPPED = "tests/waves/data/sphere_record.csv"


def test_design_with_a_record_states_the_unbounded_bound_and_matches_simulate(capsys):
    assert main(["design", "sphere", "--controller", "passive", "--wave", "elevation",
                 "--eta", SHIPPED, "--duration", "300", "--dt", "0.02", "--json"]) == 0
    captured = capsys.readouterr()
    designed = json.loads(captured.out)
    assert designed["valid"] and designed["wave"]["type"] == "record"
    # the bound: declared unbounded, as simulate does, with the components named
    bound = designed["bound"]
    assert bound["complex_conjugate_W"] is None and bound["constrained_W"] is None
    reason = bound["constrained_reason"]
    assert "unbounded" in reason and "no radiation damping" in reason and "11.52" in reason
    assert designed["percent_of_bound"] == {"complex_conjugate": None, "constrained": None}
    assert designed["simulation"]["summary"]["validity"]["bound_W"] is None
    assert UNBOUNDED in designed["simulation"]["summary"]["validity_warnings"]
    assert UNBOUNDED in captured.err                         # warned as simulate warns
    share = designed["tuner"]["share"]
    assert share["complex_conjugate_W"] is None and "unbounded" in share["why"]
    inside = share["envelope_bound_W"]
    assert inside is not None and math.isfinite(inside)

    # an independent run: plain `simulate` of the same record with the printed settings
    command = shlex.split(designed["simulate_command"])
    assert command[:2] == ["mbcontrol", "simulate"]
    assert main(command[1:] + ["--json"]) == 0
    captured = capsys.readouterr()
    simulated = json.loads(captured.out)
    assert UNBOUNDED in captured.err and simulated["validity"]["bound_W"] is None
    power = designed["metrics"]["mean_power_W"]
    # the settings print to 6 digits: measured 6e-11 apart
    assert simulated["ptos"]["pto"]["mean_power_W"] == pytest.approx(power, rel=1e-5)
    # linear theory straight from the BEM data against the nonlinear time-domain plant:
    # measured 22.05 kW simulated, 22.19 kW predicted (-0.6 %, the start-up in the window)
    assert power == pytest.approx(designed["predicted_power_W"], rel=0.02)
    assert 0 < power < inside                    # 20 % of the bound inside the envelope


def test_design_text_says_there_is_no_finite_bound(capsys):
    """The text report on the same record (bounds off: the envelope share still shows)."""
    assert main(["design", "sphere", "--controller", "passive", "--wave", "elevation",
                 "--eta", SHIPPED, "--duration", "100", "--dt", "0.05", "--bounds", "off"]) == 0
    out = capsys.readouterr().out
    assert "complex-conjugate bound of this wave is unbounded" in out
    assert "no finite bound to set it against" in out
    assert "no finite bound to check against" in out and "predicts 0 %" not in out
