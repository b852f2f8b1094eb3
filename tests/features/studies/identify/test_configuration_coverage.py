"""Identification's 95 % prediction intervals on a configuration the fit never saw (issue 58):
each of the flume's three scenario-C configurations (series 4: roll blocked; 5: heave blocked;
6: sway clamped) is predicted by a model fitted on the other two, its intervals calibrated on
those two alone (CV+ over their series). Reference: the measured amplitudes of the left-out
series. The issue's goal: at least 90 % of held-out amplitudes inside their intervals, with a
median half-width of at most 35 % of the predicted amplitude. Pooled over the three folds:
60 of 62 (96.8 %), median 23.5 % (notebooks/guide.md gives the commands). The test runs the
hardest fold, series 5 left out (both misses are its sway at 7.8 and 8.6 rad/s: 24 of 26),
to keep the suite's time; the other two folds held 16 of 16 and 20 of 20."""
import json
import statistics
from pathlib import Path

import pytest

from mbcontrol.cli import main

RUNS = Path(__file__).resolve().parents[5] / "shared" / "data" / "tank" / "scenario_c"
if not RUNS.exists():
    pytest.skip(f"tank data not found at {RUNS}", allow_module_level=True)
FITTED_ON = {"4": "56", "5": "46", "6": "45"}


def _left_out(capsys, series: str) -> dict:
    fitted = [str(p) for s in FITTED_ON[series] for p in sorted(RUNS.glob(f"{s}*.csv.xz"))]
    held = [str(p) for p in sorted(RUNS.glob(f"{series}*.csv.xz"))]
    code = main(["identify", "flume_section", "--data", *fitted, "--validate", *held,
                 "--drop-bad", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_a_whole_configuration_left_out_is_covered(capsys):
    s = _left_out(capsys, "5")
    assert s["calibration"]["folds"] == "leave one series out"   # whole configurations
    inside, rows = s["prediction_coverage"]["inside"], s["prediction_coverage"]["rows"]
    half_widths = [(p["interval_95"][1] - p["interval_95"][0]) / 2 / abs(p["model"])
                   for p in s["predictions"]]
    assert rows == 26                    # every held-out amplitude of series 5
    assert inside / rows >= 0.90, f"{inside} of {rows} inside"
    assert statistics.median(half_widths) <= 0.35
