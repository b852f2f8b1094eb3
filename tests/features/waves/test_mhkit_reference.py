"""The sea package against MHKiT (the field's reference for resource statistics) on the shipped
site files, and the PacWave file's own J column against its documented origin.

MHKiT is not installed here (see tests/waves/make_mhkit_reference.py for why): its values were computed
once with MHKiT 1.1.2 in a separate environment and are pinned below. The command that made
them (from the repository root):

    python3 -m venv /tmp/mhkit-venv && /tmp/mhkit-venv/bin/pip install "mhkit[wave]==1.1.2"
    /tmp/mhkit-venv/bin/python tests/waves/make_mhkit_reference.py

That script uses only MHKiT (resource.jonswap_spectrum, significant_wave_height,
energy_period, energy_flux with h), numpy and pandas; nothing here is shared with it.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.waves import (deep_water_flux, energy_flux, group_velocities, jonswap_spectrum,
                             read_ndbc_spectra, read_seas, spectral_hm0_te,
                             spectrum_energy_flux, te_over_tp)

SITES = Path(__file__).resolve().parents[4] / "shared" / "data" / "sites"
pytestmark = pytest.mark.skipif(not SITES.exists(), reason="site data not found")

F = np.linspace(0.005, 1.0, 4000)      # Hz: the grid make_mhkit_reference.py used
DEPTH, RHO, G = 399.0, 1025.0, 9.80665  # MHKiT's PacWave example depth; MHKiT's rho and g

# JONSWAP gamma 3.3 at each PacWave sea's Hm0 and Tp (file order), by MHKiT on F.
PACWAVE_MHKIT = [  # Hm0 (m), Te (s), J (W/m) in 399 m, J deep (W/m)
    (1.2554147, 8.3963177, 6487.818, 6487.8178),
    (2.6445494, 11.364748, 38968.035, 38967.141),
    (1.9552885, 7.2676158, 13622.256, 13622.256),
    (7.3188797, 13.336598, 350344.55, 350243.16),
    (2.2650078, 13.574596, 34155.638, 34143.001),
    (4.7599517, 11.115352, 123472.53, 123470.63),
    (2.7425842, 9.2301108, 34037.869, 34037.859),
    (1.3069958, 6.8840065, 5765.3414, 5765.3414),
    (1.3422786, 10.177074, 8989.6929, 8989.6685),
    (3.9250981, 13.46259, 101720.47, 101686.9),
    (1.8231919, 12.218861, 19914.283, 19912.732),
    (1.8808775, 7.9854279, 13850.153, 13850.153),
    (6.141211, 10.713005, 198087.95, 198086.43),
    (4.5928358, 9.8118786, 101472.86, 101472.74),
    (1.2581056, 7.6117388, 5906.8161, 5906.8161),
    (1.3404308, 5.9473306, 5238.9742, 5238.9742),
    (2.6376271, 8.0189979, 27351.57, 27351.57),
    (3.3851353, 9.9603512, 55958.083, 55957.987),
    (3.0478887, 16.845251, 77082.027, 76720.438),
    (1.5654942, 11.10769, 13346.537, 13346.335),
    (2.9864905, 12.441572, 54409.889, 54404.258),
    (5.3120779, 12.740216, 176281.06, 176254.83),
    (3.592561, 10.949463, 69285.368, 69284.564),
    (2.0139321, 9.6152308, 19119.875, 19119.86),
    (2.4658244, 10.402347, 31009.366, 31009.234),
    (2.005406, 8.7618682, 17275.744, 17275.742),
    (1.7963332, 6.4568176, 10214.749, 10214.749),
    (3.9846444, 12.034474, 93684.569, 93678.865),
    (2.7850767, 15.016982, 57184.143, 57107.398),
    (5.4717896, 14.469918, 212584.37, 212402.78),
    (1.2721156, 9.1970462, 7296.8769, 7296.8749),
    (3.6810346, 8.7407594, 58066.33, 58066.326),
]

# NDBC 46042 (1996): MHKiT's Hm0, Te and J (h = 2000 m: every frequency in the file, 0.03 Hz
# and up, is then in MHKiT's deep regime, so J does not depend on the exact buoy depth) at
# every 1000th valid hour, and the year's means.
BUOY_MHKIT = {
    'hours': 8600,
    'pick': [0, 1000, 2000, 3000, 4000, 5000, 6000, 7000, 8000],
    'hm0': [3.7320236, 1.484318, 1.221147, 1.3266499, 2.591679, 1.1784736, 1.6918629, 1.5788603, 3.869677],
    'te': [12.291596, 12.223329, 10.608333, 7.8727469, 8.1374262, 8.8429343, 9.9336557, 9.1681921, 13.036833],
    'J': [83932.936, 13203.188, 7755.6535, 6793.1989, 26796.919, 6021.0395, 13940.386, 11204.862, 95709.911],
    'mean_hm0': 2.193377619,
    'mean_te': 9.557402093,
    'mean_J': 26488.28667,
}


# The NDBC frequency bands (Hz) of buoy 46050's spectral files, which MHKiT's PacWave example
# reused to evaluate J of each cluster.
NDBC_46050_F = np.concatenate([[0.02], np.arange(0.0325, 0.0926, 0.005),
                               np.arange(0.10, 0.3501, 0.01), np.arange(0.365, 0.4851, 0.02)])


def _pacwave():
    seas = read_seas(SITES / "pacwave_cluster_32.csv")
    return seas, np.array(PACWAVE_MHKIT)


def test_jonswap_moments_match_mhkit_on_the_pacwave_seas():
    seas, ref = _pacwave()
    for s, (hm0, te, J, J_deep) in zip(seas, ref):
        S_f = 2 * math.pi * jonswap_spectrum(2 * math.pi * F, s.hs, s.tp, 3.3)   # m^2/Hz
        ours_hm0, ours_te = spectral_hm0_te(F, S_f)
        # same spectrum formula (DNV / IEC JONSWAP), same grid: only the quadrature differs
        # (MHKiT sums S df with backward differences, we use trapezoids); on a 0.25 mHz grid
        # that is < 1e-6 relative (measured 2e-7), so 1e-5 catches any change of formula
        assert ours_hm0 == pytest.approx(hm0, rel=1e-5)
        assert ours_te == pytest.approx(te, rel=1e-5)
        J_ours = spectrum_energy_flux(2 * math.pi * F, S_f / (2 * math.pi), DEPTH, RHO, G)
        assert J_ours == pytest.approx(J, rel=1e-5)       # measured 4e-8
        # deep water: MHKiT's IEC formula rho g^2 Hm0^2 Te / 64 pi from its own moments
        # (the pinned values carry 8 significant digits)
        assert deep_water_flux(hm0, te, RHO, G) == pytest.approx(J_deep, rel=1e-7)


def test_energy_flux_of_a_jonswap_sea_matches_mhkit():
    # energy_flux scales the spectrum to Hm0 exactly (MHKiT's JONSWAP carries Hm0 only to the
    # (1 - 0.287 ln gamma) approximation), so compare J / Hm0^2; the rest is our 4000-point
    # grid over 0.2..6 wp against MHKiT's fine grid: measured 5.3e-4, the omega^-5 tail
    # above 6 wp holds ~6e-4 of the flux
    seas, ref = _pacwave()
    for s, (hm0, _, J, _) in zip(seas, ref):
        ours = energy_flux(s.hs, s.tp, 3.3, DEPTH, RHO, G)
        assert ours / s.hs ** 2 == pytest.approx(J / hm0 ** 2, rel=1e-3)


def test_site_te_and_the_simulated_te_differ_by_the_jonswap_ratio():
    # the PacWave file's Tp is its Te / 0.858 (MHKiT's example); a JONSWAP gamma 3.3 sea at
    # that Tp has Te = 0.9033 Tp (MHKiT's own moments agree), 5.3 % above the site's Te
    seas, ref = _pacwave()
    for s, (_, te, _, _) in zip(seas, ref):
        assert s.te / s.tp == pytest.approx(0.858, abs=1e-12)
        # MHKiT's grid stops at 1 Hz (the tail above is dropped from m0 more than from
        # m_-1: measured Te up to 2.1e-4 high); our ratio integrates to 50 times the peak
        assert te / s.tp == pytest.approx(te_over_tp(3.3), rel=5e-4)
    assert te_over_tp(3.3) == pytest.approx(0.9033, abs=1e-4)


def test_buoy_46042_hm0_te_and_flux_match_mhkit():
    f, S, stamps = read_ndbc_spectra(SITES / "46042w1996.txt.gz")
    assert len(stamps) == BUOY_MHKIT["hours"]          # same rows dropped (999 codes)
    hm0, te = spectral_hm0_te(f, S)
    J = spectrum_energy_flux(2 * math.pi * f, S / (2 * math.pi), 2000.0, RHO, G)
    pick = BUOY_MHKIT["pick"]
    # the buoy's 0.01 Hz bands: trapezoids against MHKiT's backward rectangles differ by
    # half a band at the ends, measured at most 0.21 % per hour and 0.1 % on the year's mean
    # flux; 0.5 % per hour and 0.2 % on the means leave room and still catch a units slip
    np.testing.assert_allclose(hm0[pick], BUOY_MHKIT["hm0"], rtol=5e-3)
    np.testing.assert_allclose(te[pick], BUOY_MHKIT["te"], rtol=5e-3)
    np.testing.assert_allclose(J[pick], BUOY_MHKIT["J"], rtol=5e-3)
    assert hm0.mean() == pytest.approx(BUOY_MHKIT["mean_hm0"], rel=2e-3)
    assert te.mean() == pytest.approx(BUOY_MHKIT["mean_te"], rel=2e-3)
    assert J.mean() == pytest.approx(BUOY_MHKIT["mean_J"], rel=2e-3)


def _mhkit_example_gamma(tp, hs):
    """The gamma MHKiT's jonswap_spectrum picks when none is given (IEC 62600-101 / DNV)."""
    x = tp / math.sqrt(hs)
    return 5.0 if x <= 3.6 else 1.0 if x > 5 else math.exp(5.75 - 1.15 * x)


def test_pacwave_file_J_column_is_what_the_mhkit_example_computed():
    """The file's J is not the flux of its own Hm0 and Te: MHKiT's example evaluated a
    JONSWAP (its default gamma) on `f = w / 2 * np.pi` with w buoy 46050's bands in Hz, i.e.
    on frequencies pi/2 times too high (0.031..0.76 Hz), in h = 399 m, rho 1025, g 9.80665,
    summing S cg df with backward differences. Rebuilt here with our spectrum and c_g it
    agrees to 1e-10; the physical flux of the file's Hm0/Te differs from it by -4 % to +22 %."""
    seas = read_seas(SITES / "pacwave_cluster_32.csv")
    f = NDBC_46050_F / 2 * np.pi
    df = np.diff(f, prepend=2 * f[0] - f[1])
    for s in seas:
        S_f = 2 * math.pi * jonswap_spectrum(2 * math.pi * f, s.hs, s.tp,
                                             _mhkit_example_gamma(s.tp, s.hs))
        J = RHO * G * np.sum(S_f * group_velocities(2 * math.pi * f, DEPTH, G) * df)
        assert J == pytest.approx(s.j, rel=1e-8)          # measured 1.3e-10
    # the physical flux of each sea (its Hm0 and Te, deep water: 399 m is deep for these
    # periods to 0.6 %) against the file's column: the spread the artefact makes
    physical = np.array([deep_water_flux(s.hs, s.te, RHO, G) for s in seas])
    ratio = np.array([s.j for s in seas]) / physical
    assert 0.95 < ratio.min() < 0.97 and 1.21 < ratio.max() < 1.23
