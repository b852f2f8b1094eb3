"""Sweeps: cases equal separate `simulate` runs; serial and Dask give the same numbers; a sweep
killed part-way (the process, or a worker) resumes with every case present exactly once."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from mbcontrol import waves
from mbcontrol.analysis import summary
from mbcontrol.plant import build_plant
from mbcontrol.results import read_dataset
from mbcontrol.sim import simulate
from mbcontrol.studies.sweep import grid, sweep

SEAS = grid([1.0, 2.0], [8.0, 11.0])
# 140 s: the 2 Tp ramp and 10 peak periods of the longest sea, 11 s ("stats.min_periods")
SHORT = dict(duration=140.0, dt=0.1, progress=False)


def test_cases_equal_separate_simulate_runs():
    ds, result = sweep("sphere", SEAS, seeds=2, vary={"pto__damping": [2e5, 6e5]},
                       workers=0, **SHORT)
    assert ds["mean_power_W"].dims == ("sea", "seed", "pto__damping")
    assert result["computed"] == 16 and result["reused"] == 0
    plant = build_plant("sphere")
    for k, sea in enumerate(SEAS):
        for seed in (0, 1):
            for damping in (2e5, 6e5):
                band = (max(0.3, plant.hydro.omega[0] * sea.tp / (2 * np.pi)),
                        min(4.0, plant.hydro.omega[-1] * sea.tp / (2 * np.pi)))
                wave = waves.irregular(sea.hs, sea.tp, seed=seed, duration=140.0, band=band)
                run = simulate(plant, wave, duration=140.0, dt=0.1,
                               params={"pto__damping": damping})
                expected = summary(run, plant)["ptos"]["pto"]["mean_power_W"]
                got = float(ds["mean_power_W"].sel(sea=k, seed=seed, pto__damping=damping))
                assert got == pytest.approx(expected, rel=1e-12)


def test_serial_and_two_workers_agree(monkeypatch):
    serial, _ = sweep("sphere", SEAS, workers=0, **SHORT)
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")   # too small to start one
    dask, result = sweep("sphere", SEAS, workers=2, **SHORT)
    assert result["computed"] == len(SEAS)
    xr.testing.assert_identical(serial.drop_attrs(), dask.drop_attrs())


FAULTS = Path(__file__).resolve().parents[3] / "helpers" / "sweep_faults.py"


def _cli(store, *extra, fault=None):
    """The sweep command in a fresh process; fault: injected by tests/helpers/sweep_faults.py."""
    head = [sys.executable, str(FAULTS), fault] if fault else [sys.executable, "-m",
                                                              "mbcontrol.cli"]
    argv = [*head, "sweep", "sphere", "--hs", "1", "2", "--tp", "8", "10", "12", "--duration",
            "150", "--dt", "0.1", "--store", str(store), "--json", *extra]
    return subprocess.run(argv, capture_output=True, text=True, timeout=600, env=os.environ)


def test_killed_sweep_resumes_with_each_case_once(tmp_path):
    store = tmp_path / "store"
    killed = _cli(store, "--workers", "0", fault="exit-after:2")
    assert killed.returncode == 9                       # stopped after two cases were kept
    assert len(list((store / "cases").glob("*.json"))) == 2
    assert not list((store / "cases").glob("*.tmp"))     # nothing half written
    resumed = _cli(store, "--workers", "0")
    assert resumed.returncode == 0, resumed.stderr
    s = json.loads(resumed.stdout)
    assert (s["cases"], s["computed"], s["reused"]) == (6, 4, 2)
    assert len(list((store / "cases").glob("*.json"))) == 6
    again = json.loads(_cli(store, "--workers", "0").stdout)
    assert (again["computed"], again["reused"]) == (0, 6)   # same inputs: nothing to do
    ds = read_dataset(store / "sweep.nc")       # the reader of `simulate --out` files too
    assert np.all(np.isfinite(ds["mean_power_W"].values))
    assert ds.attrs["model"] == "sphere"


def test_a_dead_worker_loses_only_its_task(tmp_path):
    flag = tmp_path / "killed"
    store = tmp_path / "store"
    run = _cli(store, "--workers", "2", fault=f"kill-worker-once:{flag}")
    assert run.returncode == 0, run.stderr
    assert flag.exists()                                 # a worker did die mid-task
    s = json.loads(run.stdout)
    assert (s["computed"], s["reused"]) == (6, 0)
    assert len(list((store / "cases").glob("*.json"))) == 6
    reference = json.loads(_cli(tmp_path / "serial", "--workers", "0").stdout)
    assert [r["mean_power_W"] for r in s["seas"]] == [r["mean_power_W"] for r in reference["seas"]]


def test_an_existing_cluster_by_its_address():
    from dask.distributed import LocalCluster
    serial, _ = sweep("sphere", SEAS[:2], workers=0, **SHORT)
    with LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster:
        remote, result = sweep("sphere", SEAS[:2], workers=None,
                               scheduler=cluster.scheduler_address, **SHORT)
    assert result["computed"] == 2
    xr.testing.assert_identical(serial.drop_attrs(), remote.drop_attrs())


def test_sweep_figure_on_real_axes(tmp_path):
    """A grid of sea states is drawn on its real Hs and Tp values (cells centred on them, a
    colourbar in kW), not on row and column numbers; a site's scattered list as dots."""
    from matplotlib.collections import QuadMesh

    from mbcontrol.studies.sweep.plots import plot_sweep
    ds, result = sweep("sphere", SEAS, workers=0, **SHORT)
    fig = plot_sweep(ds, result, tmp_path / "sweep.png")
    ax = fig.axes[0]
    (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    assert ax.get_xlabel() == "peak period Tp, s" and ax.get_ylabel().endswith("Hs, m")
    lo, hi = ax.get_xlim()
    assert lo < 8.0 and 11.0 < hi and ax.get_ylim()[0] < 1.0 < 2.0 < ax.get_ylim()[1]
    texts = {t.get_text().split("\n")[0] for t in ax.texts}     # power, then its spread
    kw = ds["mean_power_W"].mean("seed").values / 1e3 if "seed" in ds["mean_power_W"].dims \
        else ds["mean_power_W"].values / 1e3
    assert {f"{v:.3g}" for v in np.ravel(kw)} <= texts
    assert any(a.get_ylabel() == "mean power, kW" for a in fig.axes)
    assert (tmp_path / "sweep.png").stat().st_size > 10_000
    # two panels a row: a page wide however many there are (a site's five were 27 in wide)
    assert fig.get_size_inches()[0] <= 11.5


def test_a_case_that_diverges_is_a_result_not_a_crash(tmp_path):
    """Reactive control of the sphere with a PTO spring of -1.5 MN/m against its 0.77 MN/m of
    hydrostatics (net -0.73 MN/m: statically unstable, as test_reactive_latching's wrong-model
    case) and no force limit diverges in every sea (pole +0.92 1/s); with no spring it runs. The diverging cases are
    recorded with their sea, seed and reason, counted in failed_cases (not invalid_cases),
    never averaged; the other cases are kept and the store written, and a rerun reuses both."""
    store = tmp_path / "store"
    run = dict(controller="reactive", settings={"damping": 4e5, "force_max": np.inf},
               vary={"stiffness": [0.0, -1.5e6]}, store=store, workers=0, **SHORT)
    ds, result = sweep("sphere", SEAS[:2], **run)
    assert result["failed_cases"] == 2 and len(result["failed"]) == 2
    for case in result["failed"]:
        assert case["stiffness"] == -1.5e6 and case["seed"] == 0
        assert "diverged" in case["reasons"], case["reasons"]
    assert result["invalid_cases"] == 0 and result["valid_cases"] == 2
    assert bool(ds["failed"].sel(stiffness=-1.5e6).all())
    assert not bool(ds["failed"].sel(stiffness=0.0).any())
    assert np.isnan(ds["mean_power_W"].sel(stiffness=-1.5e6)).all()      # never averaged
    assert (ds["mean_power_W"].sel(stiffness=0.0) > 0).all()
    assert [row["failed_cases"] for row in result["seas"]] == [1, 1]
    json.dumps(result)                                  # the contract stays JSON
    assert (store / "sweep.nc").exists()
    _, again = sweep("sphere", SEAS[:2], **run)
    assert again["computed"] == 0 and again["reused"] == 4 and again["failed_cases"] == 2


def test_random_amplitudes_give_intervals_that_hold():
    """Records with Rayleigh amplitudes (`amplitudes="random"`): each sea's 95 % interval from
    4 seeds (Student's t) against the mean of 32 further independent seeds, the brute-force
    reference; the issue asks at least 5 of 6 seas inside. The sphere with a passive 400
    kN s/m, 6 seas, 120 s records. Deterministic amplitudes keep every record's Hs exact."""
    seas = grid([1.0, 2.0, 3.0], [8.0, 10.0])
    ds, result = sweep("sphere", seas, seeds=36, controller="passive",
                       settings={"damping": 4e5}, amplitudes="random", workers=0,
                       **SHORT)
    assert result["provenance"]["amplitudes"] == "random"
    from mbcontrol.studies.sweep.study import seed_statistics
    inside = 0
    for k in range(len(seas)):
        powers = ds["mean_power_W"].isel(sea=k).values
        lo, hi = seed_statistics(powers[:4])["mean_power_ci95_W"]
        inside += lo <= np.nanmean(powers[4:]) <= hi
    assert inside >= 5, inside
    row = result["seas"][0]
    assert row["valid_seeds"] == 36 and row["mean_power_ci95_W"][0] < row["mean_power_W"] \
        < row["mean_power_ci95_W"][1]
    assert row["mean_power_stderr_W"] == pytest.approx(
        np.std(ds["mean_power_W"].isel(sea=0).values, ddof=1) / 6)
    # the spectral CV (frequency-domain solution, no simulation) against the 36 records'
    # scatter: a record's mean power is near a sum of N_eff = 1 / cv^2 exponentials (a gamma
    # law, excess kurtosis 6 / N_eff), so the sample std's relative standard error is
    # 0.5 sqrt(2 / (n - 1) + 6 / (N_eff n)); each sea within 3 of them
    for k, row in enumerate(result["seas"]):
        powers = ds["mean_power_W"].isel(sea=k).values
        cv = row["spectral_cv"]
        n_eff = 1 / cv ** 2
        assert row["effective_samples"] == pytest.approx(36 * n_eff)
        se = 0.5 * np.sqrt(2 / 35 + 6 / (n_eff * 36))
        observed = np.std(powers, ddof=1) / np.mean(powers)
        assert abs(observed / cv - 1) < 3 * se, (row["hs"], row["tp"], observed, cv)
        assert row["spectral_stderr_W"] == pytest.approx(cv * row["mean_power_W"] / 6)


def test_random_amplitudes_scatter_hs_deterministic_ones_do_not():
    fixed = [waves.irregular(2.0, 9.0, seed=s, duration=300.0) for s in range(20)]
    drawn = [waves.irregular(2.0, 9.0, seed=s, duration=300.0, amplitudes="random")
             for s in range(20)]
    hs = [4 * np.sqrt(0.5 * np.sum(w.amplitude ** 2)) for w in drawn]
    assert all(4 * np.sqrt(0.5 * np.sum(w.amplitude ** 2)) == pytest.approx(2.0) for w in fixed)
    assert np.std(hs) > 0.02 and abs(np.mean(hs) - 2.0) < 0.1       # about Hs, not at it
    assert np.array_equal(fixed[3].phase, drawn[3].phase)            # same seed, same phases
    assert drawn[0].settings["amplitudes"] == "random" and "amplitudes" not in fixed[0].settings
