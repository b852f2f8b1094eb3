"""Measured records and the flume dataset loader: readers, steady windows from the flume's
geometry, the incident wave from the calibration runs, and bad data refused with the file and
channel named. Real files from ../shared/data/tank (see its README)."""
import lzma
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from mbcontrol.studies.identify import RecordError, read_csv, read_netcdf
from mbcontrol.studies.identify.flume import (MODEL_X, RAMP_PERIODS, SETTLE_PERIODS, load_run,
                                              load_runs, parse_name, steady_window)
from mbcontrol.waves import group_velocity, wavenumber

TANK = Path(__file__).resolve().parents[4] / "shared" / "data" / "tank"
RUNS, CALIBRATION = TANK / "scenario_c", TANK / "calibration"
if not RUNS.exists():
    pytest.skip(f"tank data not found in {TANK}", allow_module_level=True)


def _copy(src: Path, dst: Path, edit=None, rows=None) -> Path:
    """A plain-CSV copy of a tank file, cut to `rows` data rows, one column edited."""
    with lzma.open(src, "rt") as fh:
        lines = fh.read().splitlines()
    header, body = lines[0], lines[1:rows + 1 if rows else None]
    if edit:
        column, value = edit
        k = header.split(",").index(column)
        body = [",".join(value if i == k else v for i, v in enumerate(line.split(",")))
                for line in body]
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text("\n".join([header, *body]) + "\n")
    return dst


def test_csv_record_units_and_column_map():
    r = read_csv(RUNS / "6081_1.csv.xz", {"Heave": "heave", "Roll": "roll"}, time="Time")
    assert sorted(r.channels) == ["heave", "roll"] and r.units == {"heave": "m", "roll": "rad"}
    assert np.allclose(np.diff(r.time[:5]), 0.005)                 # 200 Hz (README)
    with pytest.raises(RecordError, match=r"6081_1.csv.xz: no column\(s\) \['Pitch'\]"):
        read_csv(RUNS / "6081_1.csv.xz", {"Pitch": "pitch"})


def test_netcdf_record(tmp_path):
    t = np.arange(0, 5, 0.01)
    ds = xr.Dataset({"roll_deg": ("t", np.degrees(0.1 * np.sin(t)), {"units": "deg"})},
                    coords={"t": ("t", t, {"units": "s"})})
    ds.to_netcdf(tmp_path / "run.nc")
    r = read_netcdf(tmp_path / "run.nc", {"roll_deg": "Roll"}, time="t")
    assert r.units == {"Roll": "deg"} and r.channels["Roll"].shape == t.shape
    with pytest.raises(RecordError, match="no time coordinate 'time'"):
        read_netcdf(tmp_path / "run.nc")


def test_names_follow_the_convention(tmp_path):
    assert parse_name(RUNS / "5131_2.csv.xz") == {
        "series": 5, "pp": 13, "omega": 9.265, "height_code": 1, "height": 0.024, "repetition": 2}
    bad = _copy(RUNS / "4021_1.csv.xz", tmp_path / "run_a.csv", rows=10)
    with pytest.raises(RecordError, match=r"run_a.csv: name 'run_a' does not follow the flume "
                                          r"convention SPPH\[_R\]"):
        load_run(bad, CALIBRATION)


def test_group_velocity_and_steady_window_by_hand():
    # k h = 1.7563 at 4.143 rad/s in 1 m: omega^2 = g k tanh(k h) (solved here by bisection)
    w = 4.143
    lo, hi = 0.1, 10.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if 9.81 * mid * math.tanh(mid) < w ** 2 else (lo, mid)
    assert wavenumber(w, 1.0) == pytest.approx(lo, rel=1e-12)
    cg = w / lo * 0.5 * (1 + 2 * lo / math.sinh(2 * lo))
    assert group_velocity(w, 1.0) == pytest.approx(cg, rel=1e-12)
    opens, closes = steady_window(10.0, w)
    period = 2 * math.pi / w
    assert opens == pytest.approx(10.0 + MODEL_X / cg + (RAMP_PERIODS + SETTLE_PERIODS) * period)
    assert closes == pytest.approx(10.0 + 3 * MODEL_X / cg)
    # the README's warning: at the lowest frequency about one period is steady (here 0.45:
    # the settling periods take the rest), at the highest about 30
    assert (closes - opens) / period < 1.0
    assert (steady_window(0.0, 9.905)[1] - steady_window(0.0, 9.905)[0]) * 9.905 / 2 / math.pi > 25


def test_a_run_with_its_incident_wave():
    run = load_run(RUNS / "6081_1.csv.xz", CALIBRATION)
    assert sorted(run.channels) == ["Heave", "Roll"] and run.freeze == ("sway",)
    assert run.notes["periods"] == 8
    # 24 mm nominal waves: the calibrated amplitude at the model within 3 % of 12 mm, and the
    # probes and the two calibration repetitions agree within 2 %
    assert run.amplitude == pytest.approx(0.012, rel=0.03)
    assert run.notes["calibration_spread"] < 0.02
    five = load_run(RUNS / "5061_1.csv.xz", CALIBRATION)
    assert five.scene_parameters == {"sway_extra_mass": 0.3} and five.freeze == ("heave",)


def test_flat_channel_is_refused_or_dropped_with_its_reason():
    with pytest.raises(RecordError, match=r"4061_2.csv.xz: channel 'Sway' is flat .* a tracking "
                                          r"failure"):
        load_run(RUNS / "4061_2.csv.xz", CALIBRATION)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        runs = load_runs([RUNS / "4061_1.csv.xz", RUNS / "4061_2.csv.xz"], drop_bad=True)
    assert [r.name for r in runs] == ["4061_1"]
    assert any("dropped 1 run(s)" in str(w.message) and "4061_2.csv.xz: channel 'Sway' is flat"
               in str(w.message) for w in caught)


def test_nan_channel_and_short_run_are_refused(tmp_path):
    nan = _copy(RUNS / "5081_1.csv.xz", tmp_path / "scenario_c" / "5081_1.csv",
                edit=("Roll [rad]", "nan"))
    with pytest.raises(RecordError, match=r"5081_1.csv: channel 'Roll' has \d+ NaN"):
        load_run(nan, CALIBRATION)
    short = _copy(RUNS / "4021_1.csv.xz", tmp_path / "scenario_c" / "4021_1.csv", rows=5000)
    with pytest.raises(RecordError, match=r"4021_1.csv: no whole wave period .* too short for a "
                                          r"steady window"):
        load_run(short, CALIBRATION)
    with pytest.raises(RecordError, match="no calibration run 1021"):
        load_run(RUNS / "4021_1.csv.xz", tmp_path)
