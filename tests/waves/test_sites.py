"""Site files, Te/Tp, band clipping and annual energy of the waves package: each number from
the file itself, a closed form or a hand count."""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.waves import (SeaState, band_limits, bin_seas, energy_flux, gamma_for_te_over_tp,
                             irregular, occurrence, read_seas, site_energy_flux, te_over_tp)

SITES = Path(__file__).resolve().parents[3] / "shared" / "data" / "sites"


@pytest.mark.skipif(not SITES.exists(), reason="site data not found")
def test_pacwave_file_keeps_its_own_te_tp_and_J():
    seas = read_seas(SITES / "pacwave_cluster_32.csv")
    first = seas[0]
    # row 0 of the file, as written there
    assert (first.hs, first.tp, first.te, first.j) == pytest.approx(
        (1.2539695860020375, 9.294278901653492, 7.974491297618696, 6031.115427233068))
    # a sweep's J is the flux of the site's own sea (Hm0, Tp, its Te / Tp = 0.858: JONSWAP
    # gamma 1.02), which in deep water is rho g^2 Hm0^2 Te / (64 pi) for any spectrum: 1e-3
    # (quadrature on the flux's grid); the file's own J column is 2 % off for this row (the
    # MHKiT example's frequency slip, tests/features/waves/test_mhkit_reference.py)
    deep = 1025.0 * 9.81 ** 2 * first.hs ** 2 * first.te / (64 * np.pi)
    assert site_energy_flux(first, rho=1025.0, g=9.81) == pytest.approx(deep, rel=1e-3)
    assert abs(first.j / deep - 1) > 0.015


def test_energy_flux_without_a_site_value_is_the_jonswap_flux():
    sea = SeaState(2.0, 9.0, 3.3)
    assert site_energy_flux(sea, 50.0, 1025.0) == energy_flux(2.0, 9.0, 3.3, 50.0, 1025.0)


def test_te_only_file_takes_tp_from_the_simulated_spectrum(tmp_path):
    path = tmp_path / "seas.csv"
    path.write_text("Hm0,Te,weights\n2.0,9.0,1.0\n")
    for gamma in (1.0, 3.3):
        (sea,) = read_seas(path, gamma=gamma)
        assert sea.te == 9.0 and sea.tp == pytest.approx(9.0 / te_over_tp(gamma))


def test_te_over_tp_closed_form_and_inverse():
    # gamma = 1: Te / Tp = (5/4)^(-1/4) Gamma(5/4) (moments of the PM form)
    assert te_over_tp(1.0) == pytest.approx(1.25 ** -0.25 * math.gamma(1.25), rel=1e-5)
    # the PacWave file's 0.858 is a JONSWAP of gamma ~ 1.02, not the 3.3 it was simulated with
    g = gamma_for_te_over_tp(0.858)
    assert 1.0 < g < 1.05 and te_over_tp(g) == pytest.approx(0.858, rel=1e-8)
    with pytest.raises(ValueError, match="Te/Tp"):
        gamma_for_te_over_tp(0.99)


def test_one_band_clipping_rule():
    wp = 2 * math.pi / 10.0
    assert band_limits(10.0) == (0.3, 4.0)
    # cut to the data: 0.5 rad/s is 0.796 wp, above the default 0.3 wp
    lo, hi = band_limits(10.0, (0.5, 20.0))
    assert lo == pytest.approx(0.5 / wp) and hi == 4.0
    wave = irregular(1.0, 10.0, data_band=(0.5, 20.0), duration=600.0)
    assert wave.omega.min() >= 0.5 and 0 < wave.settings["spectrum_outside_data"] < 1
    assert waves.from_args("jonswap", hs=1.0, tp=10.0, data_band=(0.5, 20.0)).omega.tolist() \
        == wave.omega.tolist()
    with pytest.raises(ValueError, match="lies outside the hydro data's band"):
        band_limits(100.0, (0.5, 20.0))
    import mbcontrol.studies.sweep.runner as runner
    assert not hasattr(runner, "_band")            # the sweep uses the same rule


def test_bin_seas_and_outside_records():
    hm0 = np.array([0.2, 0.7, 0.8, 1.2, 9.0])      # the last is above the table
    te = np.array([5.5, 6.5, 6.6, 7.2, 8.0])
    table = occurrence(hm0, te, np.arange(0, 2.5, 0.5), np.arange(5, 9, 1.0))
    assert table.attrs["outside"] == 1 and float(table.sum()) == pytest.approx(0.8)
    seas = bin_seas(table, gamma=3.3)
    # occupied bins (0.25, 5.5), (0.75, 6.5) twice, (1.25, 7.5): three seas, by hand
    assert [(s.hs, s.te, s.weight) for s in seas] == [(0.25, 5.5, 0.2), (0.75, 6.5, 0.4),
                                                      (1.25, 7.5, 0.2)]
    assert seas[0].tp == pytest.approx(5.5 / te_over_tp(3.3))
