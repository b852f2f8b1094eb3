"""Several PTOs, one plant: joint tuning (controllers.joint) and design's bounds on devices
with more than one PTO, checked against independent derivations.

References: each PTO's Thevenin equivalent with the others closed by their laws as scene
damping and stiffness (analysis.bounds.pto_thevenin: a different path through the plant's
mechanical matrices than the multiport responses the tuner uses), the FD solution of the
whole device with every law in its parameters (analysis.frequency_domain_response), and
the multiport complex-conjugate optimum (no set of PTO forces absorbs more).
"""
from __future__ import annotations

import numpy as np
import pytest

from mbcontrol.analysis import frequency_domain_response, pto_thevenin
from mbcontrol.analysis.ports import multiport_bound
from mbcontrol.controllers.joint import joint_tuning, other_laws
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.studies.design import design
from mbcontrol.waves import regular

# simulated / linear theory: the nonlinear plant, its radiation fit and the step size
# (design's dt = T / 1000) move the power by well under a percent in these small waves
BOUND_TOLERANCE = 0.01


@pytest.fixture(scope="module")
def array4():
    return build_plant(load_scene("array4"))


@pytest.fixture(scope="module")
def flap_pair():
    return build_plant(load_scene("flap_pair"))


def _laws(tuned):
    return {"damping": tuned.damping, "stiffness": tuned.stiffness}


def _fd_powers(plant, wave, laws) -> np.ndarray:
    """Each PTO's mean power (W) from the FD solution with every law in the plant."""
    params = {f"{p}__{k}": v for k in ("damping", "stiffness") for p, v in laws[k].items()}
    names = list(laws["damping"])
    V = frequency_domain_response(plant, wave.omega, direction=wave.direction, params=params,
                                  outputs=[f"{p}__velocity" for p in names])
    c = np.array([laws["damping"][p] for p in names])
    return np.sum(0.5 * c[None, :] * np.abs(V * wave.amplitude[:, None]) ** 2, axis=0)


def test_regular_wave_optimum_reaches_the_multiport_bound(array4):
    """In a regular wave the joint laws absorb the multiport optimum (Falnes), in the FD
    solution of the device with those laws; moving any one gain lowers the total; and each
    PTO absorbs no more than its own conjugate bound with the others closed."""
    wave = regular(0.02, 1.5)
    tuned = joint_tuning(array4, wave)
    assert tuned.method.startswith("closed form")
    total = _fd_powers(array4, wave, _laws(tuned)).sum()
    assert total == pytest.approx(multiport_bound(array4, wave).power, rel=1e-6)
    assert tuned.total_W == pytest.approx(total, rel=1e-6)
    for pto in tuned.damping:
        for key in ("damping", "stiffness"):
            for factor in (0.95, 1.05):
                laws = _laws(tuned)
                laws[key] = {**laws[key], pto: laws[key][pto] * factor}
                assert _fd_powers(array4, wave, laws).sum() < total
        th = pto_thevenin(array4, wave.omega, pto, params=other_laws(array4, _laws(tuned), pto))
        conditional = np.abs(th.excitation[0] * wave.amplitude[0]) ** 2 / (8 * th.impedance[0].real)
        assert tuned.predicted_W[pto] <= conditional * (1 + 1e-9)


def test_predicted_power_is_the_devices_fd_solution(flap_pair):
    """A sea, with limits: the tuner's per-PTO powers are the FD solution of the device with
    every law in the plant (c |V|^2 / 2 per component)."""
    from mbcontrol.waves import from_args
    om = flap_pair.hydro.omega
    wave = from_args("jonswap", hs=0.01, tp=2.5, gamma=3.3, seed=1, duration=100,
                     data_band=(float(om[0]), float(om[-1])))
    tuned = joint_tuning(flap_pair, wave, force_max={"pto1": 1.0, "pto2": 1.0})
    powers = _fd_powers(flap_pair, wave, _laws(tuned))
    for j, pto in enumerate(tuned.damping):
        assert tuned.predicted_W[pto] == pytest.approx(powers[j], rel=1e-6)
        assert tuned.statistics[pto]["force_peak"] <= 1.0 * (1 + 1e-9)
    assert tuned.total_W <= multiport_bound(flap_pair, wave).power


def _within(result):
    pct = result.percent_of_bound
    for key in ("complex_conjugate", "total_complex_conjugate"):
        if pct.get(key) is not None:
            assert pct[key] <= 100 * (1 + BOUND_TOLERANCE), (key, pct[key])


def test_design_array4_stays_within_its_bounds(array4):
    """The issue's case: reactive, regular H 0.02 m, T 1.5 s, unconstrained, used to
    simulate 111 % of its bound."""
    result = design(array4, regular(0.02, 1.5), "reactive", limits=False)
    assert result.valid
    _within(result)
    total = result.metrics["total_mean_power_W"]
    assert total == pytest.approx(result.bound["total_complex_conjugate_W"], rel=BOUND_TOLERANCE)
    assert result.predicted_power_W == pytest.approx(result.metrics["mean_power_W"],
                                                     rel=BOUND_TOLERANCE)
    assert "jointly" in result.tuner["other_ptos"]


@pytest.mark.parametrize("model,height,period", [("flap_pair", 0.01, 2.5),
                                                 ("raft3", 0.02, 1.2)])
def test_design_multi_pto_within_bounds(model, height, period):
    plant = build_plant(load_scene(model))
    result = design(plant, regular(height, period), "reactive")
    assert result.valid, result.invalid_reasons
    _within(result)
    # the margins closed the others with their tuned laws: the very loop simulated
    assert result.margins.stable


def test_design_single_pto_with_friction_and_mooring_within_bound():
    plant = build_plant(load_scene("hinged_raft"))
    result = design(plant, regular(0.02, 1.2), "reactive")
    assert result.valid, result.invalid_reasons
    _within(result)


def test_predictive_control_of_several_ptos_is_bounded_in_total(array4):
    """The MPC acts on all four PTOs: one PTO's power has no bound of its own (the others
    can feed it), the total has."""
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = design(array4, regular(0.02, 1.5), "mpc", simulate_s=30.0)
    assert result.bound["complex_conjugate_W"] is None
    assert "every PTO" in result.bound["constrained_reason"]
    assert result.percent_of_bound["complex_conjugate"] is None
    assert result.percent_of_bound["total_complex_conjugate"] is not None
    _within(result)


def test_cli_sets_one_ptos_value():
    import inspect

    from mbcontrol.controllers.reactive import Reactive
    from mbcontrol.cli.commands import parse_settings
    signature = inspect.signature(Reactive).parameters
    out = parse_settings(["damping.pto1=2", "damping.pto2=3", "stiffness=-1"], signature)
    assert out == {"damping": {"pto1": 2.0, "pto2": 3.0}, "stiffness": -1.0}
    with pytest.raises(ValueError, match="already set for every PTO"):
        parse_settings(["damping=1", "damping.pto1=2"], signature)
