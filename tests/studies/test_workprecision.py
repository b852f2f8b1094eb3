"""Work-precision data and the `mbcontrol bench` command."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.cli import main
from mbcontrol.studies import workprecision as wp

from tests.helpers.kernel_fits import judged_by_kernel


@pytest.fixture(scope="module")
def chart():
    """The sphere with its kernel-judged fit, whose pole at -16.7 rad/s makes RK4 fail above
    0.169 s (tests/sim/test_stability.py): the chart must show where a method fails."""
    sea = waves.irregular(2.5, 9.67, seed=1, duration=80)
    return wp.work_precision(judged_by_kernel("sphere"), sea, duration=80, methods=("rk4", "exp-rk4", "cvodes"),
                             steps=[9.67 / 2**k for k in range(2, 7)], rtols=(1e-4, 1e-7),
                             radiation_tols=(0.2,), repeats=1)


def test_rows_are_measured_against_a_converged_reference(chart):
    assert chart.attrs["reference_error"] < 1e-9          # dopri5 at 0.019 s vs 0.0094 s
    rk4 = chart.where(chart.series == "rk4", drop=True)
    stable = rk4.stable.values.astype(bool)
    # RK4 is unstable above 0.166 s on the sphere (test_stability): 2.42, 1.21, 0.60, 0.30 s
    assert not stable[rk4.dt_s.values > 0.17].any() and stable[rk4.dt_s.values < 0.16].all()
    lawson = chart.where(chart.series == "exp-rk4", drop=True)
    errors = lawson.rms_error.values[lawson.stable.values.astype(bool)]
    assert np.all(np.diff(errors) < 0)                    # finer step, smaller error
    # the two finest steps are in the asymptotic range: ~16x per halving (order 4)
    assert 10 < errors[-2] / errors[-1] < 24, errors
    cv = chart.where(chart.series == "cvodes", drop=True)
    assert cv.rms_error.values[1] < cv.rms_error.values[0]


def test_radiation_order_is_a_model_error_with_fewer_states(chart):
    rad = chart.where(chart.series.str.startswith("radiation"), drop=True)
    assert int(rad.states.values[0]) < chart.attrs["states"]
    # a 0.2 fit of the sphere is a few % off the full model, far above the integration error
    full = chart.where((chart.series == "exp-rk4") & (chart.dt_s == rad.dt_s.values[0]),
                       drop=True)
    assert rad.rms_error.values[0] > 10 * full.rms_error.values[0]


def test_cheapest_meets_the_tolerance(chart):
    best = wp.cheapest(chart, 0.01, series=["rk4", "exp-rk4", "cvodes"])
    assert best is not None and best["rms_error"] <= 0.01
    assert best["wall_s"] == np.nanmin(chart.wall_s.where(chart.rms_error <= 0.01).values)
    # which one is cheapest is a timing (benchmarks' business); that exp-rk4 meets 1 % at a
    # step where rk4 is unstable is not: 4.3e-3 at 0.60 s (measured)
    lawson = chart.where((chart.series == "exp-rk4") & chart.stable & (chart.dt_s > 0.3),
                         drop=True)
    assert (lawson.rms_error.values <= 0.01).any(), lawson.rms_error.values


def test_bench_command_writes_chart_table_and_netcdf(tmp_path, capsys):
    import xarray as xr
    code = main(["bench", "sphere", "--wave", "jonswap", "--hs", "2", "--tp", "8",
                 "--duration", "40", "--methods", "rk4", "exp-rk4", "--radiation-tols",
                 "--repeats", "1", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0 and "cheapest within 1% RMS" in out and "error: max over joint" in out
    for name in ("work_precision.png", "work_precision.csv", "work_precision.nc"):
        assert (tmp_path / name).stat().st_size > 0
    ds = xr.open_dataset(tmp_path / "work_precision.nc")
    assert set(ds.series.values) == {"rk4", "exp-rk4"}
