"""Figures show what their titles say: `compare_runs` puts each run in a column titled by its
label, with that run's own data (the demo's closed-loop figure was once titled "passive"
while it plotted the MPC)."""
import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from mbcontrol.plotting import compare_runs  # noqa: E402


def test_each_column_is_titled_by_the_run_it_plots(tmp_path):
    t = np.linspace(0, 10, 101)
    runs = {label: xr.Dataset({"hinge": ("time", k * np.sin(t)),
                               "hinge_pto__force": ("time", k * np.cos(t))},
                              coords={"time": t})
            for k, label in enumerate(("passive, designed", "MPC, 5 N m, 45 N m/s"), start=1)}
    fig = compare_runs(runs, ["hinge", "hinge_pto__force"], title="two controllers",
                       path=tmp_path / "runs.png")
    axes = np.array(fig.axes).reshape(2, 2)
    for j, (label, ds) in enumerate(runs.items()):
        assert axes[0, j].get_title() == label
        for i, name in enumerate(("hinge", "hinge_pto__force")):
            np.testing.assert_array_equal(axes[i, j].lines[0].get_ydata(), ds[name].values)
    assert (tmp_path / "runs.png").stat().st_size > 10_000


def test_signal_labels_and_units_for_a_reader():
    from mbcontrol.plotting import signal_label
    assert signal_label("eta") == "wave elevation (up)"
    assert signal_label("hinge_pto__power") == "hinge_pto power"
    assert signal_label("barge2__Heave") == "barge2 heave (z down)"
    assert signal_label("w__barge2__Pitch") == "wave load, barge2 pitch"
    assert signal_label("u__pto") == "pto command"
    assert signal_label("hinge") == "hinge"


def test_time_series_labels_units_and_marks_the_mean_power(tmp_path):
    """A power panel carries its mean over the statistics window (after the ramp), the
    number a reader wants; every panel's label has its unit."""
    from mbcontrol import waves
    from mbcontrol.plant import build_plant
    from mbcontrol.plotting import time_series
    from mbcontrol.sim import simulate
    plant = build_plant("sphere")
    ds = simulate(plant, waves.irregular(2.0, 9.0, seed=1, duration=120.0), duration=120.0, dt=0.1)
    fig = time_series(ds, ["eta", "heave", "pto__power"])
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["wave elevation (up)\n[m]", "heave\n[m]", "pto power\n[W]"]
    start = ds.attrs["wave"]["ramp_s"]
    t, p = ds["time"].values, ds["pto__power"].values
    note = [t.get_text() for t in fig.axes[2].texts]
    assert note == [f"mean {np.mean(p[t >= start]):.3g} W (t >= {start:.3g} s; grey: not in "
                    f"the statistics)"]
    assert fig.axes[0].get_title() == "sphere, JONSWAP Hs 2 m, Tp 9 s, seed 1; controller: the " \
                                      "scene's PTO laws"
