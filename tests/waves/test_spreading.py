"""Directional spreading (mbcontrol.waves.spreading), spread seas' realisations and a seas file's
direction and spread columns: each number against a quadrature, a closed form or the file."""
import math

import numpy as np
import pytest

from mbcontrol.waves import SeaState, Spreading, irregular, read_seas, spread_from_s
from mbcontrol.waves.spreading import component_directions, wrap

THETA = np.linspace(-np.pi, np.pi, 200001)      # a fine trapezoid grid over the circle


@pytest.mark.parametrize("sigma_deg", [5.0, 20.0, 30.0, 60.0, 80.0])
def test_cos2s_is_normalised_and_its_sigma_is_the_circular_std(sigma_deg):
    sigma = math.radians(sigma_deg)
    sp = Spreading("cos2s", 0.7, sigma)
    D = sp.density(THETA)[0]
    # the closed-form C(s) against a 2e5-point trapezoid: 1e-6 (the trapezoid's error where
    # cos^(2s)(x/2) has an infinite slope at +-pi, s = 0.026 at 80 deg: 7e-8 there)
    assert np.trapezoid(D, THETA) == pytest.approx(1.0, abs=1e-6)
    # sigma = sqrt(2 (1 - m1)), m1 = |E exp(i theta)| (Kuik et al. 1988), by quadrature
    m1 = abs(np.trapezoid(D * np.exp(1j * THETA), THETA))
    assert math.sqrt(2 * (1 - m1)) == pytest.approx(sigma, rel=1e-6)
    assert spread_from_s(sp.s_peak) == pytest.approx(sigma, rel=1e-12)   # the inverse map


def test_mitsuyasu_s_follows_goda_and_stays_normalised():
    sp = Spreading("mitsuyasu", 0.0, math.radians(20.0))
    wp = 0.6
    w = np.array([0.3, 0.6, 1.2])
    s_max = 2 / math.radians(20.0) ** 2 - 1                   # sigma at the peak
    # Goda (1985): s_max (w / wp)^5 below the peak, s_max (w / wp)^-2.5 above
    assert sp.s(w, wp) == pytest.approx([s_max * 0.5 ** 5, s_max, s_max * 2.0 ** -2.5])
    assert np.trapezoid(sp.density(THETA, w, wp), THETA, axis=1) == pytest.approx(1.0, abs=1e-8)


def test_sector_renormalises_and_bins_hold_the_mass():
    sigma = math.radians(30.0)
    full, cut = Spreading("cos2s", 0.0, sigma), Spreading("cos2s", 0.0, sigma, math.pi / 2)
    inside = np.abs(THETA) <= math.pi / 2
    share_out = 1 - np.trapezoid(full.density(THETA)[0] * inside, THETA)
    assert cut.outside()[0] == pytest.approx(share_out, rel=1e-4)
    assert np.trapezoid(cut.density(THETA)[0], THETA) == pytest.approx(1.0, abs=1e-6)
    # bins of 13 headings, 15 deg apart: each the integral of D over its bin (quadrature)
    h = np.radians(np.arange(-90, 91, 15))
    W = cut.bin_weights(h)[0]
    edges = np.concatenate([[-math.pi / 2], 0.5 * (h[1:] + h[:-1]), [math.pi / 2]])
    D = cut.density(THETA)[0]
    ref = [np.trapezoid(D * ((THETA >= a) & (THETA < b)), THETA) for a, b in zip(edges, edges[1:])]
    assert W == pytest.approx(ref, abs=2e-4)     # bins' step edges on a 2e5 grid
    assert W.sum() == pytest.approx(1.0, abs=1e-12)


def test_spread_sea_draws_every_run_of_components_from_the_whole_distribution():
    sigma, mean = math.radians(30.0), 0.3
    sp = Spreading("cos2s", mean, sigma)
    long = irregular(2.0, 10.0, seed=4, direction=mean)
    short = irregular(2.0, 10.0, seed=4, spreading=sp)
    # the same frequencies, amplitudes and phases: only the directions differ
    assert np.array_equal(long.amplitude, short.amplitude)
    assert np.array_equal(long.phase, short.phase)
    assert short.directional and not long.directional
    assert short.describe()["direction_rad"] == mean and short.settings["spreading"] == "cos2s"
    # any 34 consecutive components (a Weyl sequence: discrepancy below 0.06 there, Niederreiter)
    # sample D: their circular std is sigma within 6 %, their mean the mean within 3 deg
    for start in (0, 50, 100):
        d = short.direction[start:start + 34]
        z = np.mean(np.exp(1j * (d - mean)))
        assert math.sqrt(2 * (1 - abs(z))) == pytest.approx(sigma, rel=0.06)
        assert abs(np.angle(z)) < math.radians(3.0)
    # the quantiles are the sequence frac(u0 + i (sqrt 5 - 1) / 2), by hand
    d = component_directions(sp, short.omega, 2 * np.pi / 10, 4)
    u = np.array([np.interp(x, np.linspace(-4, 4, 200001),
                            np.cumsum(sp.density(np.linspace(-4, 4, 200001))[0]) * 8 / 200000)
                  for x in d[:5]])
    step = (math.sqrt(5) - 1) / 2
    assert np.diff(u) % 1.0 == pytest.approx(np.full(4, step), abs=1e-3)
    assert np.array_equal(d, short.direction)


def test_seas_file_direction_and_spread_columns(tmp_path):
    path = tmp_path / "seas.csv"
    path.write_text("Hm0,Tp,weights,direction,spread\n2.0,9.0,0.5,10,30\n1.0,7.0,0.5,-20,0\n")
    seas = read_seas(path)
    # degrees in the file, radians inside
    assert seas[0].direction == pytest.approx(math.radians(10)) and \
        seas[0].spread == pytest.approx(math.radians(30)) and seas[0].spread_given
    assert seas[1].direction == pytest.approx(math.radians(-20)) and not seas[1].spread_given
    plain = tmp_path / "plain.csv"                 # no columns: long-crested, not given
    plain.write_text("Hm0,Tp\n1,8\n")
    assert math.isnan(read_seas(plain)[0].spread) and math.isnan(read_seas(plain)[0].direction)


@pytest.mark.parametrize("row, column", [("2.0,9.0,10,85", "spread"), ("2.0,9.0,10,-1", "spread"),
                                         ("2.0,9.0,x,30", "direction"),
                                         ("2.0,9.0,inf,30", "direction")])
def test_seas_file_refuses_a_bad_direction_or_spread(tmp_path, row, column):
    path = tmp_path / "seas.csv"
    path.write_text(f"Hm0,Tp,direction,spread\n1.0,8.0,0,20\n{row}\n")
    with pytest.raises(ValueError) as err:
        read_seas(path)
    assert str(path) in str(err.value) and "row 3" in str(err.value) \
        and f"column {column}" in str(err.value)


def test_spreading_refuses_a_spread_past_uniform():
    with pytest.raises(ValueError, match="spread sigma"):
        Spreading("cos2s", 0.0, math.radians(82.0))
    assert SeaState(1.0, 8.0).spreading == "cos2s"
