"""Response measures of the identification costs against hand computations."""
import math

import numpy as np
import pytest

from mbcontrol.studies.identify.costs import (eq67_error, harmonic, harmonic_weights,
                                              peak_low_indices, peaks_and_lows, whole_periods)

OMEGA = 2 * math.pi          # a 1 s period


def test_harmonic_of_a_sine_is_exact():
    t = np.arange(0, 10, 0.01)
    y = 0.3 + 2.0 * np.cos(OMEGA * t + 0.7)           # Re(Y e^{i w t}), Y = 2 e^{0.7 i}
    Y = harmonic(t, y, OMEGA, 2.0, 7.5)               # 5 whole periods of 2.0..7.5
    assert abs(Y - 2.0 * np.exp(0.7j)) < 1e-12
    W = harmonic_weights(t, OMEGA, 2.0, 7.5)           # the same as linear weights
    assert abs(complex(*(W @ y)) - Y) < 1e-12
    assert np.all(W[:, t < 2.0 - 1e-9] == 0) and np.all(W[:, t >= 7.0 - 1e-9] == 0)


def test_harmonic_with_noise_and_a_second_harmonic():
    rng = np.random.default_rng(3)
    t = np.arange(0, 20, 0.005)
    y = np.cos(OMEGA * t) + 0.2 * np.cos(2 * OMEGA * t + 1) + 0.01 * rng.standard_normal(t.size)
    # the second harmonic is orthogonal over whole periods; the noise's share of 4000 samples
    # on two coefficients is ~0.01 sqrt(2 / 4000) = 2e-4: 1e-3 is 5 sigma
    assert abs(harmonic(t, y, OMEGA, 0.0, 20.0) - 1.0) < 1e-3


def test_eq67_peaks_and_lows_by_hand():
    # two periods sampled at quarter periods: values chosen so each period's max and min are plain
    t = np.array([0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75])
    y = np.array([0.0, 3.0, 0.0, -2.0, 0.0, 4.0, 0.5, -1.0])
    measured = peaks_and_lows(t, y, OMEGA, 0.0, 2.0)
    assert measured.tolist() == [3.0, -2.0, 4.0, -1.0]
    assert peak_low_indices(t, y, OMEGA, 0.0, 2.0).tolist() == [1, 3, 5, 7]
    model = np.array([2.5, -2.0, 4.5, -1.5])
    # sum (f_hat - f)^2 = 0.25 + 0 + 0.25 + 0.25
    assert eq67_error(measured, model) == pytest.approx(0.75)
    with pytest.raises(ValueError, match="differ in number"):
        eq67_error(measured, model[:3])


def test_whole_periods_and_short_windows():
    assert whole_periods(None, OMEGA, 1.0, 4.7) == (1.0, 4.0, 3)
    with pytest.raises(ValueError, match="shorter than one wave period"):
        whole_periods(None, OMEGA, 1.0, 1.9)
