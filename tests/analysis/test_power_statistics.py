"""The spectral estimate of a record's mean power (analysis.power_statistics) against three
independent references: the time-domain sum of the same components (Monte Carlo), Bendat &
Piersol's mean-square error 1 / (B_s T), and seed by seed the closed-loop simulation itself."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis.power_statistics import (form_statistics, law_responses, power_form,
                                                 record_power_statistics)
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene

DAMPING = 4e5          # N s/m, the sphere's passive damper


@pytest.fixture(scope="module")
def sphere():
    return build_plant(load_scene("sphere"))


def _sea(plant, duration=120.0, tp=8.0, seed=0):
    omega = plant.hydro.omega
    return waves.irregular(2.0, tp, seed=seed, duration=duration,
                           data_band=(float(omega[0]), float(omega[-1])))


def test_moments_match_the_time_domain_sum_of_components(sphere):
    """Mean and standard deviation of the window's mean power over 3000 draws of phases (and
    Rayleigh amplitudes), each a time series summed from the components' responses."""
    wave = _sea(sphere)
    gains = {"pto": (DAMPING, 2e5)}
    responses = law_responses(sphere, wave.omega, gains)
    V, X = responses["pto"]
    predicted = form_statistics(power_form(wave.omega, responses, gains, (16.0, 120.0)),
                                wave.amplitude)
    t = np.arange(16.0, 120.0, 0.02)
    basis = np.exp(1j * np.outer(t, wave.omega))
    rng = np.random.default_rng(7)
    for kind in ("deterministic", "random"):
        draws = []
        for _ in range(3000):
            a = wave.amplitude * (np.sqrt(rng.exponential(1.0, wave.omega.size))
                                  if kind == "random" else 1.0)
            z = a * np.exp(1j * rng.uniform(0, 2 * np.pi, wave.omega.size))
            v, x = np.real(basis @ (z * V)), np.real(basis @ (z * X))
            draws.append(np.trapezoid(DAMPING * v * v + 2e5 * x * v, t) / (t[-1] - t[0]))
        mean, std = predicted[kind]
        # 3000 draws: the sample mean within 4 of its standard errors, the std within 8 %
        assert np.mean(draws) == pytest.approx(mean, abs=4 * std / np.sqrt(3000))
        assert np.std(draws) == pytest.approx(std, rel=0.08)


def test_whole_repeat_period_is_bendat_and_piersol(sphere):
    """Over one whole repeat period the random-amplitude CV^2 is 1 / (B_s T) exactly."""
    wave = _sea(sphere, duration=200.0, tp=10.0)
    period = 2 * np.pi / wave.d_omega
    stats = record_power_statistics(sphere, wave.omega, wave.amplitude, {"pto": (DAMPING, 0.0)},
                                    (0.0, period))
    assert stats["cv"] ** 2 == pytest.approx(1 / (stats["bandwidth_hz"] * period), rel=2e-3)
    assert stats["effective_samples"] == pytest.approx(stats["bandwidth_hz"] * period, rel=2e-3)


def test_each_seed_is_predicted_by_the_quadratic_form(sphere):
    """The same form evaluated on each seed's own phases against the closed-loop simulation's
    mean power over the metrics' window (6 seeds): the simulation steps the radiation fit,
    the ramp's transient and a held force, and still follows seed by seed."""
    from mbcontrol.analysis.metrics import pto_metrics
    from mbcontrol.controllers import make
    from mbcontrol.sim import simulate
    gains = {"pto": (DAMPING, 0.0)}
    first = _sea(sphere)
    Q = power_form(first.omega, law_responses(sphere, first.omega, gains), gains,
                   (first.ramp_time, 120.0))
    simulated, predicted = [], []
    for seed in range(6):
        wave = _sea(sphere, seed=seed)
        u = np.concatenate([wave.amplitude * np.cos(wave.phase),
                            wave.amplitude * np.sin(wave.phase)])
        predicted.append(u @ Q @ u)
        run = simulate(sphere, wave, duration=120.0, dt=0.1,
                       controller=make("passive", damping=DAMPING))
        simulated.append(pto_metrics(run, sphere.scene.ptos[0])["mean_power_W"])
    simulated, predicted = np.array(simulated), np.array(predicted)
    assert np.corrcoef(simulated, predicted)[0, 1] > 0.999
    assert np.all(np.abs(simulated / predicted - 1) < 0.06), simulated / predicted
