"""A buoy record to the budget's resource term and the electrical annual energy of a sweep:
NDBC hours to site seas by hand-computed moments, year or month blocks, and a drivetrain's
electrical energy against the records it comes from."""
import math
import warnings

import numpy as np
import pytest

from mbcontrol.errors import InputError
from mbcontrol.studies.sweep import SeaState, ndbc_resource, sweep
from mbcontrol.studies.sweep.resource import hourly_sea_states

H = 8766 / 1e6
SEAS = [SeaState(1.0, 8.0, weight=0.5, te=7.0), SeaState(3.0, 12.0, weight=0.5, te=10.0)]


def _ndbc(path, rows):
    """An NDBC file of two frequencies, 0.1 and 0.2 Hz, and flat spectra S (m^2/Hz): by the
    trapezoid, m0 = 0.1 S and m-1 = 0.75 S, so Hm0 = 4 sqrt(0.1 S), Te = 7.5 s."""
    lines = ["#YY  MM DD hh  .100  .200"]
    lines += [f"{y} {m:02d} {d:02d} {h:02d} {s:.4f} {s:.4f}" for y, m, d, h, s in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_hours_are_assigned_by_their_moments(tmp_path):
    path = _ndbc(tmp_path / "b.txt", [(96, 1, 1, 0, 2.5), (96, 1, 1, 1, 999.0),
                                      (96, 1, 1, 2, 22.5)])
    when, hm0, te = hourly_sea_states(path)
    assert when == [(1996, 1), (1996, 1)]                # the 999 row dropped
    assert hm0 == pytest.approx([2.0, 6.0]) and te == pytest.approx([7.5, 7.5])


def test_years_or_months_become_blocks(tmp_path):
    # Hm0 2 m (S 2.5) is nearer sea 0 ((2-1)/2 vs (3-2)/2 ties: Te 7.5 is nearer 7), 6 m sea 1
    hours = lambda y, m, n, s: [(y, m, 1 + k // 24, k % 24, s) for k in range(n)]  # noqa: E731
    one = _ndbc(tmp_path / "y96.txt", hours(96, 1, 24 * 8, 2.5) + hours(96, 2, 24 * 8, 22.5)
                + hours(96, 3, 24, 2.5))
    r = ndbc_resource([one], SEAS)
    assert r.kind == "month" and list(r.weights) == ["1996-01", "1996-02"]
    assert r.weights["1996-01"].tolist() == [1.0, 0.0] and r.weights["1996-02"].tolist() == [0, 1]
    assert "1996-03 left out: 24 valid hours" in r.notes[0]
    short = _ndbc(tmp_path / "y97.txt", hours(97, 1, 24 * 121, 22.5))
    with pytest.raises(InputError, match="1 years with enough valid hours"):
        ndbc_resource([one, short], SEAS)           # 1996 has 17 days: left out
    y98 = _ndbc(tmp_path / "y98.txt", hours(98, 1, 24 * 31, 2.5) + hours(98, 2, 24 * 90, 22.5))
    r = ndbc_resource([short, y98], SEAS)
    assert r.kind == "year" and list(r.weights) == ["1997", "1998"]
    assert r.weights["1998"] == pytest.approx([31 / 121, 90 / 121])
    with pytest.raises(InputError, match="--resource .*missing.txt: no such file"):
        ndbc_resource([tmp_path / "missing.txt"], SEAS)


def test_drivetrain_sweep_reports_electrical_energy(tmp_path):
    """The electrical annual energy is H sum w P_e over the records' electrical power, below
    the absorbed, with its own interval and budget."""
    from tests.helpers.drivetrain_scenes import with_drivetrain
    scene = with_drivetrain(tmp_path, "sphere")
    seas = [SeaState(1.5, 8.0, weight=0.4), SeaState(2.0, 10.0, weight=0.6)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds, s = sweep(str(scene), seas, duration=130.0, dt=0.1, progress=False)
    pe = ds["mean_electrical_power_W"].mean("seed").values
    assert s["annual_electrical_energy_MWh"] == pytest.approx(H * np.sum([0.4, 0.6] * pe),
                                                              rel=1e-12)
    assert s["annual_electrical_energy_MWh"] < s["annual_energy_MWh"]   # winding loss (this
    # drivetrain at the scene damper loses more than it absorbs: a negative electrical energy)
    lo, hi = s["annual_electrical_energy_ci95_MWh"]
    assert lo < s["annual_electrical_energy_MWh"] < hi
    assert s["annual_electrical_energy_budget"]["energy"].startswith("electrical")
    assert math.isfinite(s["annual_electrical_energy_budget"]["combined_std_MWh"])
