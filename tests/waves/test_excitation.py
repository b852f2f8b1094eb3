"""Excitation synthesis (FFT and direct paths), wave construction from arguments, and waves
recovered from an elevation record, against a direct sum of components written out in
wave_reference.py and the impulse-response convolution.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from mbcontrol.waves import excitation_series, from_args, interpolate_complex, irregular, regular
from tests.helpers.wave_reference import HS, TP, direct_sum, half_cosine

# ----------------------------------------------------------------------- excitation series

def coefficient_table(d_omega, k_lo, k_hi):
    """Excitation per unit amplitude on a grid whose nodes include every component
    (k d_omega), so linear interpolation returns the nodal values exactly: two DOFs,
    F1 = (1 + 0.5 i) w^2 and F2 = (0.3 - 2 i) w."""
    omega = np.arange(k_lo - 1, k_hi + 2) * d_omega
    table = np.stack([(1 + 0.5j) * omega**2, (0.3 - 2j) * omega], axis=1)
    return omega, table


def test_excitation_fft_path_equals_direct_sum(monkeypatch):
    w = irregular(HS, TP, duration=600.0, seed=3)
    k = np.rint(w.omega / w.d_omega).astype(int)
    omega_data, table = coefficient_table(w.d_omega, k[0], k[-1])
    t = np.arange(6000) * 0.1                 # 0.1 s divides the 600 s period: FFT-able
    calls = []
    irfft = np.fft.irfft
    monkeypatch.setattr(np.fft, "irfft", lambda *a, **kw: calls.append(1) or irfft(*a, **kw))
    got = excitation_series(w, omega_data, table, t)
    assert calls, "the uniform-grid FFT path was not taken"
    coeffs = np.stack([(1 + 0.5j) * w.omega**2, (0.3 - 2j) * w.omega], axis=1)
    expected = half_cosine(t, w.ramp_time)[:, None] * direct_sum(
        w.omega, w.amplitude, w.phase, coeffs, t)
    assert got.shape == (6000, 2)
    # both are exact sums; the difference is rounding (FFT ~ eps log N, direct cos of
    # arguments up to ~2000 rad ~ 1e-13): 1e-10 of the largest value
    for j in range(2):
        scale = np.abs(expected[:, j]).max()
        np.testing.assert_allclose(got[:, j], expected[:, j], rtol=0, atol=1e-10 * scale)


def test_excitation_at_the_integrators_nodes_equals_direct_sum(monkeypatch):
    """RK4's nodes t_i, t_i + dt/2, t_i + dt over a record longer than the wave's repeat
    period (so it wraps): one inverse FFT on the half-step grid serves all three nodes, against
    the direct sum within 1e-9 of the largest value (issue 38)."""
    from mbcontrol.waves import excitation_at_offsets
    w = irregular(HS, TP, duration=200.0, seed=5)          # repeat period 200 s
    k = np.rint(w.omega / w.d_omega).astype(int)
    omega_data, table = coefficient_table(w.d_omega, k[0], k[-1])
    coeffs = np.stack([(1 + 0.5j) * w.omega**2, (0.3 - 2j) * w.omega], axis=1)
    calls = []
    irfft = np.fft.irfft
    monkeypatch.setattr(np.fft, "irfft", lambda *a, **kw: calls.append(1) or irfft(*a, **kw))
    n, dt = 5000, 0.05                                       # 250 s: past one period
    got = excitation_at_offsets(w, omega_data, table, n, dt, [0.0, 0.5, 1.0])
    assert len(calls) == 1, "one inverse FFT for all the nodes"
    for j, c in enumerate((0.0, 0.5, 1.0)):
        t = (np.arange(n) + c) * dt
        expected = half_cosine(t, w.ramp_time)[:, None] * direct_sum(
            w.omega, w.amplitude, w.phase, coeffs, t)
        for d in range(2):
            np.testing.assert_allclose(got[:, j, d], expected[:, d], rtol=0,
                                       atol=1e-9 * np.abs(expected[:, d]).max())


def test_excitation_direct_path_equals_direct_sum():
    w = irregular(HS, TP, duration=600.0, seed=4)
    k = np.rint(w.omega / w.d_omega).astype(int)
    omega_data, table = coefficient_table(w.d_omega, k[0], k[-1])
    t = 0.05 + np.arange(3000) * 0.2           # t[0] != 0: the per-component sum is used
    coeffs = np.stack([(1 + 0.5j) * w.omega**2, (0.3 - 2j) * w.omega], axis=1)
    expected = half_cosine(t, w.ramp_time)[:, None] * direct_sum(
        w.omega, w.amplitude, w.phase, coeffs, t)
    got = excitation_series(w, omega_data, table, t)
    for j in range(2):
        np.testing.assert_allclose(got[:, j], expected[:, j], rtol=0,
                                   atol=1e-10 * np.abs(expected[:, j]).max())


def test_unit_excitation_is_the_elevation():
    # Conventions agree: with F = 1 the excitation series is the elevation itself, for both
    # synthesis paths (rounding only)
    w = irregular(HS, TP, duration=600.0, seed=5)
    for t in (np.arange(6000) * 0.1, 0.3 + np.arange(1000) * 0.3):
        got = excitation_series(w, [0.1, 10.0], np.ones((2, 1), dtype=complex), t)[:, 0]
        np.testing.assert_allclose(got, w.elevation(t), rtol=0, atol=1e-12)


@pytest.mark.parametrize("phase", [0.0, 1.1])
def test_regular_excitation_is_exact(phase):
    H, T = 0.2, 2.0
    w = regular(H, T, phase=phase)
    omega = 2 * math.pi / T
    # a table linear in omega: linear interpolation reproduces it exactly at any omega
    F = lambda x: (2.0 - 1.0j) * (x + 1.0)
    omega_data = np.array([0.5, 2.0, 5.0])
    table = F(omega_data)[:, None]
    t = np.linspace(0.0, 5 * T, 2001)
    got = excitation_series(w, omega_data, table, t)[:, 0]
    exact = np.real(H / 2 * F(omega) * np.exp(-1j * (omega * t + phase)))
    after = t >= w.ramp_time
    # after the ramp: Re(a F(w) e^{-i (w t + phi)}) to rounding (|a F| ~ 0.9)
    np.testing.assert_allclose(got[after], exact[after], rtol=0, atol=1e-13)
    # during the ramp: the same times the half-cosine
    np.testing.assert_allclose(got, half_cosine(t, w.ramp_time) * exact, rtol=0, atol=1e-13)


def test_excitation_outside_data_band_raises():
    w = irregular(HS, TP)                        # components 0.3..4 wp = 0.24..3.1 rad/s
    with pytest.raises(ValueError, match=r"outside the hydro data's band 1\.\.2 rad/s"):
        excitation_series(w, [1.0, 1.5, 2.0], np.ones((3, 1)), np.arange(10.0))
    r = regular(0.1, 1.0)                        # 2 pi rad/s, above a band ending at 5
    with pytest.raises(ValueError, match=r"components at 6\.28\.\.6\.28 rad/s lie outside the "
                                         r"hydro data's band 0\.5\.\.5 rad/s"):
        excitation_series(r, [0.5, 5.0], np.ones((2, 1)), np.arange(10.0))


def test_interpolate_complex_reproduces_a_linear_function():
    rng = np.random.default_rng(0)
    omega_data = np.sort(rng.uniform(0.2, 8.0, 25))             # non-uniform grid
    alpha = rng.normal(size=(2, 3)) + 1j * rng.normal(size=(2, 3))
    beta = rng.normal(size=(2, 3)) + 1j * rng.normal(size=(2, 3))
    f = lambda x: alpha + beta * np.asarray(x)[:, None, None]
    omega = np.concatenate([rng.uniform(omega_data[0], omega_data[-1], 200),
                            omega_data[[0, -1]]])              # include both end points
    got = interpolate_complex(omega_data, f(omega_data), omega)
    assert got.shape == (omega.size, 2, 3)
    # linear interpolation of a linear function is exact: rounding of values ~ 10 only
    np.testing.assert_allclose(got, f(omega), rtol=0, atol=1e-12)


# ------------------------------------------------------------------------------- from_args

def test_from_args_builds_each_kind():
    assert from_args("regular", height=1.0, period=5.0).kind == "regular"
    assert from_args("jonswap", hs=1.0, tp=6.0, seed=2).settings == {
        "hs": 1.0, "tp": 6.0, "gamma": 3.3, "seed": 2}
    assert from_args("pm", hs=1.0, tp=6.0).settings["gamma"] == 1.0


@pytest.mark.parametrize("kind, kwargs, message", [
    ("regular", {"period": 5.0}, "a regular wave needs --height and --period"),
    ("regular", {"height": 1.0}, "a regular wave needs --height and --period"),
    ("jonswap", {"tp": 6.0}, "a jonswap sea needs --hs and --tp"),
    ("jonswap", {"hs": 1.0}, "a jonswap sea needs --hs and --tp"),
    ("pm", {"hs": 1.0}, "a pm sea needs --hs and --tp"),
    ("stokes", {"height": 1.0, "period": 5.0},
     "unknown wave type 'stokes'; expected regular, jonswap or pm"),
])
def test_from_args_errors(kind, kwargs, message):
    with pytest.raises(ValueError, match=message):
        from_args(kind, **kwargs)


def test_from_elevation_recovers_a_regular_wave():
    """A sampled cosine is one FFT component: amplitude and phase come back exactly."""
    from mbcontrol.waves import from_elevation
    dt, n = 0.05, 2000                                 # 100 s record
    t = 3.0 + np.arange(n) * dt                        # a record need not start at 0
    w0 = 2 * np.pi * 7 / (n * dt)                      # on the record's frequency grid
    eta = 0.2 + 0.5 * np.cos(w0 * t + 0.7)
    wave = from_elevation(t, eta)
    i = int(np.argmax(wave.amplitude))
    # an on-grid sinusoid is exact in the DFT: round-off only
    assert wave.omega[i] == pytest.approx(w0, rel=1e-12)
    assert wave.amplitude[i] == pytest.approx(0.5, rel=1e-12)
    assert np.angle(np.exp(1j * (wave.phase[i] - 0.7))) == pytest.approx(0.0, abs=1e-10)
    np.testing.assert_allclose(wave.elevation(t), eta - 0.2, atol=1e-12)
    assert wave.settings["mean_m"] == pytest.approx(0.2, rel=1e-12)


def test_from_elevation_excitation_equals_irf_convolution():
    """FFT route (components x F) vs the non-causal impulse-response convolution."""
    from mbcontrol.waves import excitation_impulse_response, from_elevation, irregular

    # F decays smoothly at both ends of its band, so K_e(t) is negligible beyond 30 s (an F
    # cut off sharply, as data at a band edge, would give a slow 1/t tail to window instead)
    w_data = np.linspace(0.05, 8.0, 800)
    F = ((1.0 + 0.3j * w_data) * w_data**2 * np.exp(-0.25 * w_data**2))[:, None]
    sea = irregular(1.0, 6.0, gamma=1.0, seed=3, duration=400.0, band=(0.4, 3.0))
    dt = 0.1
    t = np.arange(0, 400.0, dt)
    eta = sea.elevation(t)
    eta -= eta.mean()                                  # a static offset is not a wave
    wave = from_elevation(t, eta, band=(0.05, 8.0))
    fft_route = excitation_series(wave, w_data, F, t)[:, 0]
    tau = np.arange(-30.0, 30.0 + dt / 2, dt)
    K = excitation_impulse_response(w_data, F, tau)[:, 0]
    # circular convolution: the record is periodic, as the FFT route assumes
    shifts = np.round(tau / dt).astype(int)
    sample = np.arange(0, t.size, 50)
    conv = np.array([dt * np.sum(K * eta[(i - shifts) % t.size]) for i in sample])
    ref = fft_route[sample]
    # measured 1e-5 of the peak (quadrature of K_e and the 0.1 s convolution sum); 1e-4
    # leaves room for platform round-off while any phase or sign error would be O(1)
    assert np.max(np.abs(conv - ref)) < 1e-4 * np.max(np.abs(ref))


def test_irregular_sea_kept_inside_the_hydro_data():
    from mbcontrol.waves import from_args, jonswap_spectrum
    wave = from_args("jonswap", hs=0.04, tp=1.2, seed=3, duration=300.0, data_band=(0.5, 14.0))
    assert wave.omega.min() >= 0.5 and wave.omega.max() <= 14.0
    assert 4 * np.sqrt(0.5 * np.sum(wave.amplitude**2)) == pytest.approx(0.04, rel=1e-12)
    # the variance above 14 rad/s (2.67 wp), from the JONSWAP formula by direct quadrature
    w = np.linspace(14.0, 4 * 2 * np.pi / 1.2, 20001)
    tail = np.trapezoid(jonswap_spectrum(w, 0.04, 1.2, 3.3), w) / (0.04 / 4) ** 2
    assert wave.settings["spectrum_outside_data"] == pytest.approx(tail, rel=0.02)
    with pytest.raises(ValueError, match="lies outside the hydro data's band"):
        from_args("jonswap", hs=0.04, tp=60.0, data_band=(0.5, 14.0))   # all of it below 0.5 rad/s
