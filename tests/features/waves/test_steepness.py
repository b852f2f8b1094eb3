"""A wave that cannot exist is refused by the wave, not blamed later on the time step (Hs 1e6 m
used to end in 'diverged: try a smaller dt'). Breaking limit: H/L = 1/7 (Michell 1893)."""
import math

import pytest

from mbcontrol import waves
from mbcontrol.errors import WaveError


def test_a_wave_steeper_than_breaking_is_refused():
    # deep-water wavelength of an 8 s wave: g T^2 / 2 pi = 99.9 m, so at most 14.27 m high
    limit = 9.80665 * 64 / (2 * math.pi) / 7
    waves.regular(0.999 * limit, 8.0)
    with pytest.raises(WaveError, match="steeper than a wave can be.*at most 14.27 m"):
        waves.regular(1.001 * limit, 8.0)


@pytest.mark.parametrize("hs, tp", [(1e6, 8.0), (20.0, 4.0), (math.inf, 8.0), (math.nan, 8.0),
                                    (2.0, math.nan)])
def test_an_impossible_sea_is_refused_by_its_parameters(hs, tp):
    with pytest.raises(WaveError, match="--hs against --tp|expected hs > 0"):
        waves.irregular(hs, tp, duration=100.0)


def test_the_field_s_real_seas_are_far_inside_the_limit():
    # the steepest sea of ../shared/data/sites/pacwave_cluster_32.csv is Hm0 6.1 m at Tp 11.9 s
    # (Hs/Lp = 1/36); the README's tank sea 4 cm at 1.2 s (1/56)
    waves.irregular(6.13, 11.86, duration=100.0)
    waves.irregular(0.04, 1.2, duration=20.0)


def test_a_sea_too_long_to_hold_or_a_period_past_waves_is_refused():
    # --duration 1e308 asked numpy for 4.6e307 components; --period 1e308 overflowed
    with pytest.raises(WaveError, match="holds 4.6.e\\+307 components, more than 100000"):
        waves.irregular(1.0, 8.0, duration=1e308)
    with pytest.raises(WaveError, match="a period of at most 1000 s"):
        waves.regular(1.0, 1e308)
    assert waves.irregular(1.0, 8.0, duration=3 * 3600.0).omega.size < 10_000   # 3 hours
