"""Power figures: energy flux against the deep-water identity, annual energy by hand, the seas
file's errors, and NDBC spectra to Hm0, Te and an occurrence table."""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.studies.sweep import annual_energy_MWh, energy_flux, occurrence, read_seas
from mbcontrol.waves import read_ndbc_spectra, spectral_hm0_te, te_over_tp

SITES = Path(__file__).resolve().parents[4] / "shared" / "data" / "sites"


def test_energy_flux_deep_water_identity():
    # deep water: J = rho g^2 Hm0^2 Te / (64 pi) for any spectrum (c_g = g / 2 omega)
    for hs, tp, gamma in ((1.0, 8.0, 3.3), (2.5, 12.0, 1.0), (4.0, 10.0, 7.0)):
        te = tp * te_over_tp(gamma)
        expected = 1025 * 9.81 ** 2 * hs ** 2 * te / (64 * math.pi)
        assert energy_flux(hs, tp, gamma) == pytest.approx(expected, rel=2e-3)
    # finite depth tends to it
    assert energy_flux(2.0, 8.0, depth=500.0) == pytest.approx(energy_flux(2.0, 8.0), rel=1e-3)


@pytest.mark.parametrize("depth, ratio", [(20.0, 1.152), (5.0, 0.985)])
def test_finite_depth_flux_against_its_own_dispersion(depth, ratio):
    """J = rho g sum S(w) c_g(w) dw with c_g from omega^2 = g k tanh(k h) solved here by
    bisection (not the package's dispersion): in 20 m the group velocity of an 8 s sea's
    components exceeds deep water's (c_g / c_g,deep peaks near kh = 1.2), so the flux is 15 %
    higher; in 5 m the long waves slow down and it is lower."""
    from mbcontrol.waves.spectra import jonswap_spectrum
    hs, tp, rho, g = 2.0, 8.0, 1025.0, 9.81
    wp = 2 * math.pi / tp
    w = np.linspace(0.2 * wp, 6.0 * wp, 4000)
    spectrum = jonswap_spectrum(w, hs, tp, 3.3)
    spectrum *= (hs / 4) ** 2 / np.trapezoid(spectrum, w)

    def wavenumber(omega):
        lo, hi = 1e-9, 10 * omega ** 2 / g + 10 / depth
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if g * mid * math.tanh(mid * depth) < omega ** 2 else (lo, mid)
        return 0.5 * (lo + hi)

    k = np.array([wavenumber(x) for x in w])
    cg = w / k * 0.5 * (1 + 2 * k * depth / np.sinh(2 * k * depth))
    expected = rho * g * np.trapezoid(spectrum * cg, w)
    assert energy_flux(hs, tp, depth=depth) == pytest.approx(expected, rel=2e-3)
    assert energy_flux(hs, tp, depth=depth) / energy_flux(hs, tp) == pytest.approx(ratio, abs=0.002)


def test_te_over_tp_of_pierson_moskowitz():
    # gamma = 1: S ~ w^-5 exp(-5/4 (wp/w)^4), so m_n ~ Gamma(1 - n/4) (5/4 wp^4)^((n-4)/4)
    # and Te / Tp = (5/4)^(-1/4) Gamma(5/4)
    assert te_over_tp(1.0) == pytest.approx(1.25 ** -0.25 * math.gamma(1.25), rel=1e-5)


def test_annual_energy_by_hand_on_a_3x3_table():
    power = np.array([[10e3, 20e3, 30e3], [40e3, 50e3, 60e3], [70e3, 80e3, 90e3]])
    weights = np.array([[0.1, 0.2, 0.1], [0.2, 0.1, 0.1], [0.05, 0.1, 0.05]])
    # 0.1*10 + 0.2*20 + 0.1*30 + 0.2*40 + 0.1*50 + 0.1*60 + 0.05*70 + 0.1*80 + 0.05*90 = 43 kW
    assert annual_energy_MWh(power, weights) == pytest.approx(43e3 * 8766 / 1e6)
    with pytest.raises(ValueError, match="no power"):
        annual_energy_MWh([np.nan, 1.0], [0.5, 0.5])


@pytest.mark.parametrize("text, message", [
    ("Hm0,weights\n1.0,1.0\n", "expected columns Hm0 and Tp (or Te)"),
    ("Hm0,Tp,weights\n1.0,8,0.5\n-2.0,9,0.5\n", "row 3, column Hm0: expected a positive"),
    ("Hm0,Tp,weights\n1.0,8,0.5\n2.0,9,0.3\n", "weights sum to 0.8"),
    ("Hm0,Tp\n1.0,eight\n", "row 2, column Tp: expected a number, got 'eight'"),
])
def test_bad_seas_files_are_named(tmp_path, text, message):
    path = tmp_path / "seas.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as exc:
        read_seas(path)
    assert str(path) in str(exc.value) and message in str(exc.value)


def test_weights_within_rounding_are_normalised(tmp_path):
    path = tmp_path / "seas.csv"
    path.write_text("Hm0,Tp,weights\n1.0,8,0.5\n2.0,9,0.51\n")
    with pytest.warns(UserWarning, match=r"weights sum to 1.01; normalised to 1"):
        seas = read_seas(path)
    assert [s.weight for s in seas] == pytest.approx([0.5 / 1.01, 0.51 / 1.01])


@pytest.mark.skipif(not SITES.exists(), reason="site data not found")
def test_pacwave_file_reads_with_its_weights():
    seas = read_seas(SITES / "pacwave_cluster_32.csv")
    assert len(seas) == 32 and sum(s.weight for s in seas) == pytest.approx(1.0, abs=1e-6)
    assert all(s.hs > 0 and s.tp > 0 and s.te > 0 for s in seas)


@pytest.mark.skipif(not SITES.exists(), reason="site data not found")
def test_ndbc_year_to_occurrence_table():
    f, S, stamps = read_ndbc_spectra(SITES / "46042w1996.txt.gz")
    assert f[0] == pytest.approx(0.03) and S.shape == (len(stamps), f.size)
    assert 8000 < len(stamps) <= 8784                     # hourly, 1996 (a leap year)
    hm0, te = spectral_hm0_te(f, S)
    # the first hour by hand: trapezoids over the file's own frequencies
    m0 = sum(0.5 * (S[0, k] + S[0, k + 1]) * (f[k + 1] - f[k]) for k in range(f.size - 1))
    assert hm0[0] == pytest.approx(4 * math.sqrt(m0))
    assert 0.3 < np.median(hm0) < 4.0 and 5.0 < np.median(te) < 14.0
    table = occurrence(hm0, te, np.arange(0, 8.5, 0.5), np.arange(3, 20, 1.0))
    assert float(table.sum()) == pytest.approx(np.mean((hm0 < 8) & (te >= 3) & (te < 19)))
