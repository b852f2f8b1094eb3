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
    assert r.units == {"Roll": "rad"}                                 # converted on reading
    np.testing.assert_allclose(r.channels["Roll"], 0.1 * np.sin(t), rtol=1e-12)
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
    # 4021_1's steady window is 31.6-36.2 s (200 Hz): cut at 25 s and at 34 s, inside it
    for rows, end in ((5000, "25.00"), (6800, "34.00")):
        short = _copy(RUNS / "4021_1.csv.xz", tmp_path / "scenario_c" / "4021_1.csv", rows=rows)
        with pytest.raises(RecordError, match=rf"4021_1.csv: the record ends at {end} s, before "
                                              r"its steady window closes \(31.6\d-36.2\d s"):
            load_run(short, CALIBRATION)
    # at 4.143 rad/s (PP 01) the reflections are back before the ramp has passed the model
    early = _copy(RUNS / "4021_1.csv.xz", tmp_path / "scenario_c" / "4011_1.csv")
    with pytest.raises(RecordError, match=r"4011_1.csv: 0 whole wave period\(s\) \(1.517 s\) .* "
                                          r"expected at least 3"):
        load_run(early, CALIBRATION)
    with pytest.raises(RecordError, match="no calibration run 1021"):
        load_run(RUNS / "4021_1.csv.xz", tmp_path)


def _rewrite(src: Path, dst: Path, columns: dict) -> Path:
    """A plain-CSV copy of a tank file with columns renamed and their values transformed:
    columns = {old header: (new header, function of the value)}."""
    with lzma.open(src, "rt") as fh:
        lines = fh.read().splitlines()
    header = lines[0].split(",")
    edits = {header.index(old): (new, f) for old, (new, f) in columns.items()}
    for k, (new, _) in edits.items():
        header[k] = new
    body = []
    for line in lines[1:]:
        values = line.split(",")
        for k, (_, f) in edits.items():
            values[k] = repr(f(float(values[k])))
        body.append(",".join(values))
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_text("\n".join([",".join(header), *body]) + "\n")
    return dst


def test_units_in_headers_are_converted_and_checked(tmp_path):
    """Sway stored in mm under "Sway [mm]" and roll in degrees under "Roll [deg]" load as the
    run in m and rad, and fit to the same value (the issue: 50.6 instead of 32.6, silently); an
    unknown unit or a channel of the wrong kind is refused naming the file and the column."""
    from mbcontrol.studies.identify import fit
    from mbcontrol.studies.identify.setup import flume_identification
    src = RUNS / "5081_1.csv.xz"
    mm = _rewrite(src, tmp_path / "scenario_c" / "5081_1.csv",
                  {"Sway [m]": ("Sway [mm]", lambda v: 1e3 * v),
                   "Roll [rad]": ("Roll [deg]", math.degrees)})
    a, b = load_run(src, CALIBRATION), load_run(mm, CALIBRATION)
    assert a.window == b.window and b.amplitude == pytest.approx(a.amplitude, rel=1e-12)
    for channel in ("Sway", "Roll"):
        np.testing.assert_allclose(b.channels[channel], a.channels[channel], rtol=1e-12)
    values = [fit(flume_identification("flume_section", None, runs=[run],
                                       fit=["sway_rig__viscous"]), "gauss-newton").values
              for run in (a, b)]
    assert values[1]["sway_rig__viscous"] == pytest.approx(values[0]["sway_rig__viscous"],
                                                           rel=1e-9)
    inches = _rewrite(src, tmp_path / "in" / "5081_1.csv", {"Sway [m]": ("Sway [in]", float)})
    with pytest.raises(RecordError, match=r"5081_1.csv: column 'Sway' has unit 'in', which "
                                          r"mbcontrol does not know; expected one of .*mm"):
        load_run(inches, CALIBRATION)
    metres = _rewrite(src, tmp_path / "m" / "5081_1.csv", {"Roll [rad]": ("Roll [m]", float)})
    with pytest.raises(RecordError, match=r"5081_1.csv: channel 'Roll' is in 'm'; expected "
                                          r"angle units \(.*deg.*rad"):
        load_run(metres, CALIBRATION)


def test_every_refusal_is_listed_and_a_missing_calibration_folder_named(tmp_path):
    bad = [_copy(RUNS / name, tmp_path / "scenario_c" / name.replace(".xz", ""),
                 edit=("Roll [rad]", "nan")) for name in ("5081_1.csv.xz", "5081_2.csv.xz")]
    with pytest.raises(RecordError, match=r"(?s)no usable run among the 2 file\(s\) given:.*"
                                          r"5081_1.csv: channel 'Roll' has \d+ NaN.*"
                                          r"5081_2.csv: channel 'Roll' has \d+ NaN"):
        load_runs(bad, CALIBRATION, drop_bad=True)
    with pytest.raises(RecordError, match=r"no calibration folder .* --calibration DIR"):
        load_runs([RUNS / "5081_1.csv.xz"], tmp_path / "nowhere")
