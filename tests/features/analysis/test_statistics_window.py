"""No transient is reported as a steady number: the statistics window never overlaps the wave's
ramp, and a window of fewer than "stats.min_periods" (10) wave periods makes the result INVALID with the
shortest duration that works (analysis.metrics.statistics_window, analysis.validity.assess).

Before: the sphere in a regular 8 s wave with damping 6e5 printed 4.8 kW "valid" over a 10 s
run and 56 kW "valid" over 30 s (the window started at t = -70 s, inside the ramp); the steady
answer is 93.8 kW."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis import frequency_domain_response
from mbcontrol.analysis.summary import summary
from mbcontrol.errors import InputError
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

DAMPING = 6e5          # N s/m, the case
PERIOD, HEIGHT = 8.0, 2.0
RAMP = 2 * PERIOD      # regular()'s default ramp
MIN_PERIODS = 10       # the default "stats.min_periods"


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


def _run(plant, duration, wave=None, **attrs):
    ds = simulate(plant, wave or waves.regular(HEIGHT, PERIOD), duration=duration, dt=0.02,
                  params={"pto__damping": DAMPING})
    ds.attrs.update(attrs)
    return summary(ds, plant)


def _steady_power(plant) -> float:
    """The frequency-domain answer straight from the BEM data (no radiation fit, no time
    stepping): P = c |v|^2 / 2 per unit amplitude, times the amplitude H / 2 squared."""
    v = frequency_domain_response(plant, [2 * np.pi / PERIOD], params={"pto__damping": DAMPING},
                                  outputs=["pto__velocity"])[0, 0]
    return 0.5 * DAMPING * abs(v) ** 2 * (HEIGHT / 2) ** 2


def test_a_short_run_is_invalid_and_names_the_shortest_that_works(sphere):
    s = _run(sphere, 30.0)
    assert not s["valid"]
    # the window starts when the ramp ends, never before (it was -70 s), and says what it holds
    assert s["window_start_s"] == pytest.approx(RAMP)
    assert s["window_end_s"] == pytest.approx(30.0)
    assert s["window_periods"] == pytest.approx((30.0 - RAMP) / PERIOD)
    shortest = RAMP + MIN_PERIODS * PERIOD          # 96 s
    [reason] = s["invalid_reasons"]
    assert "fewer than the 10" in reason and f"simulate at least {shortest:.0f} s" in reason
    assert s["validity"]["window"]["shortest_duration_s"] == pytest.approx(shortest)


def test_the_shortest_duration_named_gives_the_steady_answer(sphere):
    s = _run(sphere, RAMP + MIN_PERIODS * PERIOD)
    assert s["valid"], s["invalid_reasons"]
    # measured 93,794 W against 93,820 W (0.03 %): the heavy damping settles the transient
    # within the ramp; 1 % leaves room for the radiation fit and rk4 at dt = 0.02 s
    assert s["ptos"]["pto"]["mean_power_W"] == pytest.approx(_steady_power(sphere), rel=0.01)


def test_a_run_shorter_than_the_ramp_is_refused_with_the_duration(sphere):
    with pytest.raises(InputError, match="simulate at least 96 s"):
        _run(sphere, 10.0)


def test_a_caller_window_inside_the_ramp_is_invalid(sphere):
    s = _run(sphere, 200.0, statistics_from_s=0.0, statistics_note="the whole record")
    assert not s["valid"]
    assert "starts at 0 s, before the ramp ends at 16 s" in s["invalid_reasons"][0]


def test_a_sea_window_counts_peak_periods(sphere):
    sea = waves.irregular(2.0, PERIOD, duration=60.0, seed=1)
    s = _run(sphere, 60.0, wave=sea)
    # after the 16 s ramp, 44 s hold 5.5 peak periods
    assert not s["valid"] and s["window_periods"] == pytest.approx(44.0 / PERIOD)
    assert "simulate at least 96 s" in s["invalid_reasons"][0]


def test_the_periods_asked_for_are_a_default_the_user_sets(sphere):
    from mbcontrol import defaults
    with defaults.override(stats_min_periods=1):
        s = _run(sphere, 30.0)            # 1.75 periods after the ramp
    assert s["valid"] and s["window_start_s"] == pytest.approx(22.0)   # the last period
