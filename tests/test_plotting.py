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
