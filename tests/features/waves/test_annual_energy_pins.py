"""The annual energies README.md and notebooks/power_matrix.ipynb quote for RM3 (passive PTO
tuned in the frequency domain on PacWave's most energetic sea), recomputed the notebook's way:
these fail when the physics of the plant, the seas or the annual-energy rule changes.

Pinned values (this machine, with the response-judged radiation fit of issue 37: 44 states,
response error 0.69 %; the kernel-judged 36-state fit before it gave 1705.3 and 1313.9 MWh,
-0.3 %, and the 32-state one before that 1716.3 and 1321.5 MWh; see the last test for how far
the fit moves them from the BEM):
- PacWave South, 32 weighted seas, 1200 s each, seed 0: 1710.0 MWh (README: 1710).
- NDBC 46042 (1996): 1317.1 MWh (README: 1317), each occupied Hm0 x Te bin of the occurrence
  table simulated at its own centre. The old rule (linear interpolation of an Hs x Tp matrix,
  seas clipped to its edges) gave 1.4 % more on the same plant.
The runs are deterministic (seeded phases, fixed-step integration): 1e-3 relative covers
compiler rounding across machines, and any change of physics moves these by more.
"""
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import readme
from mbcontrol import waves

SITES = Path(__file__).resolve().parents[4] / "shared" / "data" / "sites"
# With the physics checks (mbcontrol.analysis.validity): in the big seas the float's
# significant motion relative to the free surface exceeds its 2.54 m mean draft, so those
# cases are invalid and the annual energy counts them as producing nothing (a lower bound):
# (MWh over the valid seas, share of the year they cover), pinned like the linear figures
# A threshold statistic: the Hs 2.64 m, Tp 12.6 s sea (3.5 % of the year, 92 MWh) sits on it,
# at 2.55 m relative heave against the 2.54 m draft with an older fit (then 526.07 MWh, 0.76269);
# the kernel-judged fit gave 618.51 and 619.12 MWh with the same coverage
PACWAVE_VALID = (619.91, 0.79791)          # 11 of 32 seas invalid
BUOY_VALID = (620.23, 0.81826)             # 32 of 92 bins invalid
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not SITES.exists(), reason="site data not found")]


@pytest.fixture(scope="module")
def tuned():
    from mbcontrol.controllers.passive import optimal_damping
    from mbcontrol.plant import build_plant
    plant = build_plant("rm3")
    seas = waves.read_seas(SITES / "pacwave_cluster_32.csv")
    # the notebook's design sea: largest weight x energy flux (the site's own J; the same
    # sea as with the JONSWAP flux in the scene's depth)
    design = max(seas, key=lambda s: s.weight * waves.site_energy_flux(s))
    damping, _ = optimal_damping(plant, waves.irregular(design.hs, design.tp, duration=1200,
                                                        band=(0.5, 3.0)))
    # 2.44e7 N s/m when pinned; the AEPs below are what move if this does
    assert damping == pytest.approx(2.4408e7, rel=1e-3)
    return seas, damping


def _aep(seas, damping):
    """(annual energy over the valid seas, share of the year they cover, the linear model's
    figure with every sea, failed or not), MWh."""
    from mbcontrol.studies.sweep import sweep
    _, summary = sweep("rm3", seas, controller="passive", settings={"damping": damping},
                       duration=1200, dt=0.05, workers=0, progress=False)
    return (summary["annual_energy_MWh"], summary["annual_energy_coverage"],
            summary["annual_energy_unchecked_MWh"])


def _as_quoted(site: str, valid: float, coverage: float, linear: float) -> None:
    """The README's table ("site") rounds these: valid-seas MWh, share of the year, linear MWh."""
    *_, share, valid_mwh, linear_mwh = readme.numbers(" ".join(readme.row("site", site)))
    assert abs(share - 100 * coverage) <= 0.051, (site, share, coverage)
    assert abs(valid_mwh - valid) <= 0.51 and abs(linear_mwh - linear) <= 0.51, \
        (site, valid_mwh, valid, linear_mwh, linear)


def test_pacwave_annual_energy(tuned):
    seas, damping = tuned
    valid, coverage, linear = _aep(seas, damping)
    _as_quoted("PacWave South", valid, coverage, linear)
    assert linear == pytest.approx(1710.05, rel=1e-3)
    assert (valid, coverage) == pytest.approx(PACWAVE_VALID, rel=1e-3)


def test_buoy_46042_annual_energy(tuned):
    _, damping = tuned
    f, S, stamps = waves.read_ndbc_spectra(SITES / "46042w1996.txt.gz")
    hm0, te = waves.spectral_hm0_te(f, S)
    table = waves.occurrence(hm0, te, np.arange(0, 8.5, 0.5), np.arange(3, 21, 1.0))
    assert table.attrs["outside"] == 0 and len(stamps) == 8600
    bins = waves.bin_seas(table, gamma=3.3)
    assert len(bins) == 92 and sum(s.weight for s in bins) == pytest.approx(1.0)
    valid, coverage, linear = _aep(bins, damping)
    _as_quoted("NOAA 46042", valid, coverage, linear)
    assert linear == pytest.approx(1317.07, rel=1e-3)
    assert (valid, coverage) == pytest.approx(BUOY_VALID, rel=1e-3)


def test_radiation_fit_moves_the_annual_energy_less_than_its_tolerance(monkeypatch):
    """The linear annual energy by the frequency-domain solution, straight from the BEM data
    and again with the radiation fit's K(jω) in place of A(ω), B(ω) (same seas, components and
    damping): the fit, held to rm3's radiation_tol = 2 %, may not move it by more. Measured:
    1708.3 MWh from the BEM, 1689.4 MWh through the shipped 44-state fit (-1.11 %; the
    kernel-judged 36-state one: -1.39 %; the 32-state one before it: -0.74 %). The time-domain
    pin above sits +1.2 % over its fit's own frequency-domain figure (ramp, finite record)."""
    from mbcontrol.analysis import frequency_domain_response
    from mbcontrol.plant import build_plant
    plant = build_plant("rm3")
    hydro, pto = plant.hydro, plant.scene.ptos[0].name
    params = {f"{f.name}__coulomb": 0.0 for f in plant.scene.frictions}
    params.update({f"{pto}__damping": 2.4408e7, f"{pto}__stiffness": 0.0})
    seas = waves.read_seas(SITES / "pacwave_cluster_32.csv")
    band = (float(hydro.omega[0]), float(hydro.omega[-1]))
    radiation, a_inf = hydro.radiation, hydro.added_mass_inf

    def fitted(omega):
        K = radiation.frequency_response(np.asarray(omega))
        return a_inf[None] + K.imag / np.asarray(omega)[:, None, None], K.real

    def aep():
        powers = []
        for sea in seas:
            wave = waves.irregular(sea.hs, sea.tp, gamma=sea.gamma, seed=0, duration=1200,
                                   data_band=band)
            v = frequency_domain_response(plant, wave.omega, params=params,
                                          outputs=[f"{pto}__velocity"])[:, 0]
            powers.append(np.sum(0.5 * params[f"{pto}__damping"] * np.abs(v * wave.amplitude) ** 2))
        return waves.annual_energy_MWh(powers, [s.weight for s in seas])

    bem = aep()
    # on the class, undone after the test: the cached plant other tests share is left alone
    monkeypatch.setattr(type(hydro), "frequency_domain_matrices", lambda self, omega: fitted(omega))
    through_fit = aep()
    tol = plant.scene.hydro.radiation_tol
    assert bem == pytest.approx(1708.3, rel=1e-3)
    assert abs(through_fit / bem - 1) <= tol, (bem, through_fit)
