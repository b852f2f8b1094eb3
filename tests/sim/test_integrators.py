"""Integration methods: observed order of convergence against theory, on a smooth case.

The sphere in heave (linear hydrostatics, 8 radiation states) in a regular wave with no ramp:
the solution is smooth on [0, T], so a method of order p must show its error fall by 2^p when
the step halves. Reference: dopri5 at a step 32x finer than the coarsest (its own error is
below 1e-15 relative there, far beneath the errors measured).
"""
import warnings

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate
from mbcontrol.sim.methods import METHODS, radiation_exponential, radiation_split

H_COARSE, DURATION = 0.1, 40.0          # 0.1 s: inside every explicit method's stable range


@pytest.fixture(scope="module")
def case():
    plant = build_plant("sphere")
    wave = waves.regular(2.0, 8.0, ramp_time=0.0)
    ref = simulate(plant, wave, duration=DURATION, dt=H_COARSE / 32, method="dopri5")
    return plant, wave, ref


def _error(ds, ref) -> float:
    """Relative RMS error of the heave over the record, on the run's own grid."""
    stride = int(round(ds.attrs["dt_s"] / ref.attrs["dt_s"]))
    a, b = ds["state"].values[:, 0], ref["state"].values[::stride, 0]
    return float(np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)))


@pytest.mark.parametrize("method", ["rk3", "rk4", "dopri5", "exp-rk4"])
def test_fixed_step_order_matches_theory(case, method):
    plant, wave, ref = case
    errors = [_error(simulate(plant, wave, duration=DURATION, dt=h, method=method), ref)
              for h in (H_COARSE, H_COARSE / 2, H_COARSE / 4)]
    observed = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # measured 3.02/3.01, 4.01/4.01, 5.05/5.02, 4.02/4.00: within 0.15 of the theory on both
    # halvings (asymptotic regime; a wrong tableau coefficient drops an order at once)
    assert np.all(np.abs(observed - METHODS[method].order) < 0.15), (method, errors, observed)


@pytest.mark.parametrize("method", ["cvodes", "adams"])
def test_adaptive_error_follows_tolerance(case, method):
    """Variable order and step: theory promises tolerance proportionality (error ~ rtol),
    not a fixed order. Measured slopes over rtol 1e-5..1e-8: 0.77 (BDF), 1.23 (Adams)."""
    plant, wave, ref = case
    rtols = np.array([1e-5, 1e-6, 1e-7, 1e-8])
    errors = np.array([_error(simulate(plant, wave, duration=DURATION, dt=H_COARSE,
                                       method=method, rtol=r), ref) for r in rtols])
    slope = np.polyfit(np.log10(rtols), np.log10(errors), 1)[0]
    assert 0.5 < slope < 1.5, (errors, slope)
    assert np.all(errors < 10 * rtols), errors      # the global error stays near the request


def test_exponential_is_exact_on_the_radiation_states():
    """exp-rk4's matrix exponential of the modal radiation A_r, built block by block in
    closed form, equals scipy's dense expm of the whole matrix (a second computation)."""
    import scipy.linalg
    plant = build_plant("rm3")
    _, A, sparsity, labels = radiation_split(plant)
    for tau in (0.05, 0.8, 3.0):
        E = radiation_exponential(A, labels, tau)
        assert np.allclose(E, scipy.linalg.expm(A * tau), rtol=1e-12, atol=1e-12)
    # the block sparsity holds every nonzero of exp(A tau)
    dense = np.array(__import__("casadi").DM(sparsity, 1.0))
    assert np.all(dense[np.abs(scipy.linalg.expm(A)) > 1e-14] == 1)


def test_methods_agree_in_an_irregular_sea():
    """Every method, fixed-step or adaptive, lands on the same answer in a JONSWAP sea on a
    two-body plant (rm3): the pairwise spread is what their settings promise (< 1e-4)."""
    plant = build_plant("rm3")
    sea = waves.irregular(2.5, 8.0, seed=3, duration=120)
    runs = {}
    for method in METHODS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            runs[method] = simulate(plant, sea, duration=120, dt=0.05, method=method,
                                    rtol=1e-9)
    ref = runs["dopri5"]["state"].values[:, :plant.n_q]
    scale = np.sqrt(np.mean(ref**2, axis=0))
    for method, ds in runs.items():
        diff = np.sqrt(np.mean((ds["state"].values[:, :plant.n_q] - ref) ** 2, axis=0)) / scale
        assert diff.max() < 1e-4, (method, diff)


def test_compiled_code_is_keyed_by_structure_not_values(tmp_path, monkeypatch):
    """One library per (plant structure, method, chunk length): other parameter values, steps
    and seas reuse it, in this process and (by its content hash) in the next."""
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path))
    plant = build_plant("sphere")      # a new plant: its workspace holds no compiled code yet
    for dt, damping in ((0.1, 1e5), (0.05, 4e5)):
        for seed in (1, 2):
            simulate(plant, waves.irregular(2.0, 8.0, seed=seed, duration=51.2), duration=51.2,
                     dt=dt, method="exp-rk4", params={"pto__damping": damping})
    chunks = sorted(p.name for p in (tmp_path / "compiled").glob("chunk_*.so"))
    assert len(chunks) == 1, chunks     # 512 and 1024 steps both use the 512-step chunk
    # a "new process": a new plant, its workspace empty, finds the library on disk
    simulate(build_plant("sphere"), None, duration=51.2, dt=0.1, method="exp-rk4")
    assert sorted(p.name for p in (tmp_path / "compiled").glob("chunk_*.so")) == chunks


@pytest.mark.parametrize("method", ["rk4", "exp-rk4"])
def test_a_step_that_calls_f_equals_the_inlined_step(case, monkeypatch, method):
    """Large plants (a farm) step with f called as one function (MX) instead of inlined at every
    stage (SX), and map their outputs with unoptimised code: the same trajectory to round-off."""
    from mbcontrol.sim import integrators
    plant, wave, _ = case
    inlined = simulate(plant, wave, duration=10.0, dt=0.05, method=method)
    monkeypatch.setattr(integrators, "CALL_F_STATES", 0)
    monkeypatch.setattr(integrators, "PLAIN_OUTPUTS_STATES", 0)
    plant.workspace.clear()            # the compiled chunk and output map, built again
    called = simulate(plant, wave, duration=10.0, dt=0.05, method=method)
    plant.workspace.clear()            # the shared plant's later users get the inlined code
    for name in ("heave", "heave__vel", "pto__force", "pto__power"):
        a, b = called[name].values, inlined[name].values
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
    assert np.array_equal(called["time"].values, inlined["time"].values)
