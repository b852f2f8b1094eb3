"""Issue-3 validation on third-party BEM data (WEC-Sim's WAMIT runs of RM3 and the sphere).

References independent of the radiation fit and of each other:
- the frequency-domain solution straight from the BEM data, per frequency;
- a simulation with direct Cummins convolution of K(t) = (2/pi) int B cos(wt) dw.
"""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis import frequency_domain_response, linearize, regular_wave_amplitudes
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate, simulate_convolution

CASES = {
    # model: (outputs compared, frequencies spanning the response peaks, rad/s)
    "sphere": (["heave", "pto__force"], np.geomspace(0.5, 2.5, 8)),
    "rm3": (["float_heave", "plate_heave", "pto__force"], np.geomspace(0.4, 2.0, 8)),
}




@pytest.fixture(scope="module", params=["sphere", "rm3"])
def case(request):
    plant = build_plant(request.param)
    return request.param, plant, linearize(plant)


def test_radiation_fit_stable_and_accurate(case):
    name, plant, _ = case
    rad = plant.hydro.radiation
    assert np.max(np.linalg.eigvals(rad.A).real) < 0
    # issue 3: normalised RMS error at most 2 % over the BEM band (scene tolerance 1 %)
    assert rad.fit_error <= 0.02


def test_time_domain_matches_frequency_domain(case):
    """Steady amplitudes in regular waves: nonlinear plant vs BEM-direct FD, within 1 %."""
    name, plant, sys = case
    outputs, omegas = CASES[name]
    fd = np.abs(frequency_domain_response(plant, omegas, outputs=outputs))
    # these heave-only models are linear, so the wave height (1 m) does not matter
    td = regular_wave_amplitudes(plant, sys, omegas, outputs, height=1.0)
    worst = np.max(np.abs(td / fd - 1))
    # issue 3's criterion: 1 %; the radiation fit (1 % normalised RMS over the band, better
    # near the peaks) and linear interpolation of the BEM data are what separate them
    assert worst < 0.01


@pytest.mark.parametrize("sea", ["regular", "irregular"])
def test_state_space_matches_convolution(case, sea):
    """Time histories with the fitted radiation model vs direct convolution, within 1 %."""
    name, plant, _ = case
    outputs, omegas = CASES[name]
    peak = omegas[len(omegas) // 2]
    if sea == "regular":
        wave = waves.regular(1.0, 2 * np.pi / peak)
    else:
        wave = waves.irregular(1.5, 2 * np.pi / peak, gamma=3.3, seed=5, duration=120.0,
                               band=(0.5, 2.5))
    dt = 0.05
    ds = simulate(plant, wave, duration=120.0, dt=dt)
    t, Y, ref_plant = simulate_convolution(plant.scene, wave, duration=120.0, dt=dt)
    for out in outputs:
        a, b = ds[out].values, Y[:, ref_plant.outputs.index(out)]
        amplitude = 0.5 * np.ptp(b[t > 30])
        # issue 3's criterion: within 1 % of the response amplitude, over the whole record
        assert np.max(np.abs(a - b)) < 0.01 * amplitude, out
