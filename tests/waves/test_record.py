"""A measured elevation record as a wave (`mbcontrol.waves.from_record`): a record sampled from
a known JONSWAP sea gives that sea back (elevation, Hs, Tp) and drives the catalogue sphere
as the spectral sea does; every malformed file is refused naming the file, the line and the
column; uneven sampling is resampled with a warning that gives the numbers; a record that
does not start at rest is ramped; the shipped record (tests/waves/data/sphere_record.csv) is
what `sphere_record_text` writes."""
import dataclasses
import hashlib
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import WaveError
from mbcontrol.waves import from_record, irregular, ramp, read_elevation
from mbcontrol.waves import record as record_module

DATA = Path(__file__).parent / "data"
# a sea whose repeat period (160 s = max(duration, 20 Tp)) is a whole number of 0.25 s steps
# (640) and of peak periods (20: the JONSWAP peak 2 pi / 8 rad/s falls on the grid, so the
# periodogram's peak period is Tp exactly); its highest component, 4 wp = 3.14 rad/s, lies
# far below the record's Nyquist frequency, pi / 0.25 = 12.6 rad/s, so sampling loses nothing
HS, TP, SEED, REPEAT, DT = 1.0, 8.0, 3, 160.0, 0.25


def _sea_and_record():
    sea = irregular(HS, TP, seed=SEED, duration=REPEAT)
    t = np.arange(round(REPEAT / DT)) * DT
    return sea, t, dataclasses.replace(sea, ramp_time=0.0).elevation(t)


def test_a_record_of_a_known_sea_gives_the_sea_back(tmp_path):
    sea, t, eta = _sea_and_record()
    wave = from_record((t, eta), ramp_time=0.0)
    # at its samples: one FFT and its inverse, round-off on a 0.25 m std (measured 7e-15 m, the
    # Nyquist term making the synthesis sum in blocks); 1e-12 m leaves room for other builds
    assert np.max(np.abs(wave.elevation(t) - eta)) < 1e-12
    # between them too: the sea's components are all below the Nyquist frequency, so the
    # record's FFT finds exactly them (measured 4e-16 m over 0..160 s on a 0.05 s grid)
    fine = np.arange(0, REPEAT, 0.05)
    calm = dataclasses.replace(sea, ramp_time=0.0)
    assert np.max(np.abs(wave.elevation(fine) - calm.elevation(fine))) < 1e-12
    k = np.rint(sea.omega / wave.d_omega).astype(int) - 1       # the sea's components
    # the same amplitudes and phases: 1e-15 m is round-off beside the peak's 5e-3 m (the sea's
    # outermost components, 1e-33 m, come back as round-off)
    assert np.allclose(wave.amplitude[k], sea.amplitude, rtol=1e-10, atol=1e-15)
    big = sea.amplitude > 1e-6                  # phases of components well above round-off
    assert np.allclose(np.angle(np.exp(1j * (wave.phase[k] - sea.phase)))[big], 0, atol=1e-8)
    s = wave.settings
    # Hs: irregular scales its amplitudes so 4 sqrt(m0) = Hs exactly, and a whole repeat period
    # holds m0 exactly (Parseval); Tp: the peak on the grid (see DT above)
    assert s["hs_m"] == pytest.approx(HS, rel=1e-12) and s["tp_s"] == pytest.approx(TP, rel=1e-12)
    assert wave.period == s["tp_s"] and wave.kind == "record"
    assert (s["samples"], s["dt_s"], s["duration_s"]) == (640, DT, REPEAT)
    # a file of the same numbers (17 digits round-trip a double) gives the same wave, and
    # its settings carry the file's name and hash
    path = tmp_path / "sea.csv"
    path.write_text("time_s,eta_m\n" + "".join(f"{a:.17g},{b:.17g}\n" for a, b in zip(t, eta)))
    read = from_record(path, ramp_time=0.0)
    assert np.array_equal(read.amplitude, wave.amplitude) and read.settings["source"] == "sea.csv"
    assert read.settings["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()


def test_a_record_drives_the_sphere_as_the_spectral_sea_does():
    """The issue's check: an elevation record built from a known spectrum reproduces the
    spectral run."""
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    plant = build_plant("sphere")
    band = (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))
    sea, t, eta = _sea_and_record()
    wave = from_record((t, eta), data_band=band, ramp_time=sea.ramp_time)   # the sea's 2 Tp
    spectral = simulate(plant, sea, duration=REPEAT, dt=0.01)
    recorded = simulate(plant, wave, duration=REPEAT, dt=0.01)
    heave, again = spectral["heave"].values, recorded["heave"].values
    # the same components to 1e-16 relative; the record's others are round-off (1e-17 m):
    # the runs agree to round-off (measured 3.9e-16 m, 6e-16 of the heave's peak, 0.67 m; the
    # mean absorbed power 7409.765 W in both)
    assert np.max(np.abs(again - heave)) < 1e-9 * np.max(np.abs(heave))
    assert np.max(np.abs(recorded["eta"].values - spectral["eta"].values)) < 1e-12
    # the record reaches the Nyquist frequency (12.6 rad/s), beyond the data's 12 rad/s:
    # that part of its variance (round-off, 1e-33) is recorded as left out
    assert wave.settings["record_outside_data"] < 1e-12



def test_from_elevation_is_the_same_decomposition_on_its_own_clock():
    """`from_elevation` (arrays) and `from_record` run one decomposition: the same components,
    settings and checks; from_elevation's time is the series' own (a record starting at
    t0 = 40 s: its phases differ by omega t0), from_record's starts at the first sample."""
    from mbcontrol.waves import from_elevation
    _, t, eta = _sea_and_record()
    record = from_record((t + 40.0, eta), data_band=(0.05, 12.0), ramp_time=0.0)
    same = from_elevation(t + 40.0, eta, band=(0.05, 12.0), from_start=True)
    own = from_elevation(t + 40.0, eta, band=(0.05, 12.0))
    assert np.array_equal(same.omega, record.omega) and np.array_equal(same.phase, record.phase)
    assert np.array_equal(own.amplitude, record.amplitude)
    # the same settings but the level at the wave's t = 0 (the rest check, start_m)
    assert {**own.settings, "start_m": 0} == {**record.settings, "start_m": 0}
    assert np.max(np.abs(own.elevation(t + 40.0) - (eta - eta.mean()))) < 1e-12
    assert np.max(np.abs(record.elevation(t) - (eta - eta.mean()))) < 1e-12
    with pytest.raises(WaveError, match=r"arrays: sample 5, column 2"):
        from_elevation(t, np.where(np.arange(t.size) == 5, np.nan, eta))

GOOD_ROWS = 100                    # 100 samples at 0.2 s: 20 s, above both minimums


def _good_text(n=GOOD_ROWS, dt=0.2) -> str:
    t = np.arange(n) * dt
    rows = "".join(f"{a:.1f}, {0.3 * np.sin(2 * np.pi * a / 4):.6f}\n" for a in t)
    return "# probe 3, tank test 12\ntime (s), eta (m)\n" + rows


def _lines(text: str) -> list[str]:
    return text.splitlines(keepends=True)


def _replace_line(text: str, number: int, new: str) -> str:
    lines = _lines(text)
    lines[number - 1] = new + "\n"
    return "".join(lines)


# (file text, line named, what the message must say): line 3 is the first data row (t = 0),
# line 12 the tenth (t = 1.8 s)
BAD = {
    "not a number": (_replace_line(_good_text(), 12, "1.8, 0.1O"), 12, "column 2 (elevation (m)): '0.1O' is not a number"),
    "NaN": (_replace_line(_good_text(), 12, "1.8, nan"), 12, "'nan' is not finite"),
    "inf": (_replace_line(_good_text(), 12, "1.8\t-Inf"), 12, "'-Inf' is not finite"),
    "overflow": (_replace_line(_good_text(), 12, "1.8 1e999"), 12, "'1e999' overflows"),
    "one column": (_replace_line(_good_text(), 12, "1.8"), 12, "1 column(s)"),
    "three columns": (_replace_line(_good_text(), 12, "1.8, 0.1, 0.2"), 12, "3 column(s)"),
    "empty cell": (_replace_line(_good_text(), 12, "1.8,"), 12, "column 2 (elevation (m)): empty"),
    "time not a number": (_replace_line(_good_text(), 12, "1.8s, 0.1"), 12, "column 1 (time (s))"),
    "time goes back": (_replace_line(_good_text(), 12, "1.5, 0.1"), 12, "1.5 s is not after 1.6 s (line 11)"),
    "time repeats": (_replace_line(_good_text(), 12, "1.6, 0.1"), 12, "expected strictly increasing time"),
    "a gap": ("".join(line for i, line in enumerate(_lines(_good_text()), 1) if i not in (40, 41)),
              40, "a gap of 0.6 s before t = 7.8 s"),     # lines 40, 41 cut: 7.2 to 7.8 s
    "a second header": (_replace_line(_good_text(), 30, "time (s), eta (m)"), 30, "is not a number"),
    "not text": (_good_text()[:200] + "\udcff\n", None, "not text (UTF-8)"),
}


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_a_malformed_record_is_refused_by_file_line_and_column(case, tmp_path):
    text, line, says = BAD[case]
    path = tmp_path / "probe3.csv"
    path.write_bytes(text.encode("utf-8", "surrogateescape"))
    with pytest.raises(WaveError) as refused:
        read_elevation(path)
    message = str(refused.value)
    assert str(path) in message and says in message, message
    if line is not None:
        assert f"line {line}" in message, message
    else:
        assert re.search(r"line \d+", message), message


@pytest.mark.parametrize("text, says", [
    # 63 samples: one short of MIN_SAMPLES (64)
    (_good_text(63), "63 samples over 12.6 s; expected at least 64 samples and 10 s"),
    # 64 samples at 0.1 s: 6.4 s, short of MIN_DURATION_S (10 s)
    (_good_text(64, 0.1), "64 samples over 6.4 s"),
    ("# nothing yet\n\n", "no data rows"),
    ("time,eta\n", "no data rows"),
], ids=["too few samples", "too short", "only comments", "only a header"])
def test_a_record_too_short_is_refused(text, says, tmp_path):
    path = tmp_path / "short.txt"
    path.write_text(text)
    with pytest.raises(WaveError, match=re.escape(says)) as refused:
        from_record(path)
    assert str(path) in str(refused.value)


def test_a_file_past_the_size_limits_is_refused_without_reading_it_all(tmp_path, monkeypatch):
    path = tmp_path / "long.csv"
    path.write_text(_good_text())
    monkeypatch.setattr(record_module, "MAX_ROWS", 50)         # rows: counted while parsing
    with pytest.raises(WaveError, match=r"long.csv: line 53: more than 50 samples"):
        read_elevation(path)
    monkeypatch.setattr(record_module, "MAX_BYTES", 1000)      # bytes: refused before reading
    with pytest.raises(WaveError, match=r"long.csv: [\d,]+ bytes; expected .* at most 1,000"):
        read_elevation(path)
    with pytest.raises(WaveError, match="nowhere.csv: cannot read"):
        read_elevation(tmp_path / "nowhere.csv")


def test_arrays_are_checked_as_a_file_is():
    t = np.arange(100) * 0.2
    eta = 0.3 * np.sin(t)
    with pytest.raises(WaveError, match=r"arrays: sample 5, column 2 \(elevation \(m\)\)"):
        from_record((t, np.where(np.arange(100) == 5, np.nan, eta)))
    with pytest.raises(WaveError, match=r"arrays: sample 7, column 1 .* expected strictly"):
        from_record((np.where(np.arange(100) == 7, 1.0, t), eta))
    with pytest.raises(WaveError, match="the elevation is constant"):
        from_record((t, np.full(100, 0.2)))
    # an elevation in mm read as m: 4 std = 849 "m" at a 6.3 s peak cannot be a wave
    with pytest.raises(WaveError, match=r"steeper than a wave can be.*in metres"):
        from_record((t, 1000 * eta))


def test_uneven_sampling_is_resampled_and_says_so_with_the_numbers(tmp_path):
    # a 3 Hz logger writing milliseconds: steps of 0.333 and 0.334 s, a spread of 3e-3 of the
    # median, above UNEVEN_RTOL (1e-6); resampled onto 299.667 s / 899 steps
    n = 900
    t = np.arange(n) / 3
    path = tmp_path / "logger.txt"
    path.write_text("".join(f"{a:.3f} {0.3 * np.sin(2 * np.pi * a / 5):.9f}\n" for a in t))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        times, eta = read_elevation(path)
    (warning,) = [w for w in caught if issubclass(w.category, RuntimeWarning)]
    text = str(warning.message)
    step = float(f"{t[-1]:.3f}") / (n - 1)
    assert str(path) in text and "from 0.333 s to 0.334 s" in text, text
    assert f"uniform step of {step:.10g} s ({n} samples)" in text and "linear interpolation" in text
    assert np.allclose(np.diff(times), step, rtol=1e-12, atol=0)
    # linear interpolation between samples 1 ms off, of a 5 s sine sampled every 1/3 s: at most
    # the slope times 1 ms (0.38 mm) plus the chord's sag (a (omega h)^2 / 8 = 6.6 mm)
    assert np.max(np.abs(eta - 0.3 * np.sin(2 * np.pi * times / 5))) < 7e-3
    with pytest.warns(RuntimeWarning, match="resampled"):
        wave = from_record(path)
    assert wave.settings["resampled_from_dt_s"] == pytest.approx([0.333, 0.334], abs=1e-9)


def test_a_record_that_does_not_start_at_rest_is_ramped():
    # 20 periods of an 8 s cosine on 0.2 s steps: one component, Tz = 8 s exactly; it starts
    # at its crest (|eta| = 1.4 std, over REST_FRACTION = 0.1): a ramp of 2 Tz
    t = np.arange(800) * 0.2
    crest = from_record((t, 0.5 * np.cos(2 * np.pi * t / 8)))
    assert crest.ramp_time == pytest.approx(16.0, rel=1e-9)
    assert crest.settings["tz_s"] == pytest.approx(8.0, rel=1e-9)
    assert any("does not start at rest" in note for note in crest.settings["notes"])
    # the same sea raised from rest by the wavemaker over 3 periods needs no ramp of its own
    calm = from_record((t, 0.5 * np.cos(2 * np.pi * t / 8) * ramp(t, 24.0)))
    assert calm.ramp_time == 0.0 and calm.settings["start_m"] < 0.1 * 0.5 / np.sqrt(2)
    assert from_record((t, 0.5 * np.cos(2 * np.pi * t / 8)), ramp_time=5.0).ramp_time == 5.0
    with pytest.raises(WaveError, match="ramp_time -1"):
        from_record((t, np.cos(t)), ramp_time=-1.0)


def test_mean_band_and_repeats_are_recorded():
    # two cosines on the grid (160 s, k = 20 and k = 300: 0.785 and 11.8 rad/s), amplitudes
    # 1 and 0.5 m, on a 0.25 m offset; the hydro band 0.05..10 rad/s keeps the first: the
    # second's share of the variance, 0.125 / (0.5 + 0.125), is 20 %
    t = np.arange(1600) * 0.1
    w1, w2 = 2 * np.pi * 20 / 160, 2 * np.pi * 300 / 160
    eta = 0.25 + np.cos(w1 * t) + 0.5 * np.cos(w2 * t)
    wave = from_record((t, eta), data_band=(0.05, 10.0), duration=400.0)
    s = wave.settings
    assert s["record_outside_data"] == pytest.approx(0.2, rel=1e-12)
    assert s["mean_m"] == pytest.approx(0.25, rel=1e-12)
    assert s["repeats"] == pytest.approx(2.5)                  # a 400 s run of a 160 s record
    notes = " ".join(s["notes"])
    assert "20 % of the record's variance" in notes and "mean, 0.25 m, is left out" in notes
    assert "repeats 2.5 times" in notes
    assert np.max(np.abs(dataclasses.replace(wave, ramp_time=0).elevation(t) - np.cos(w1 * t))) < 1e-12
    with pytest.raises(WaveError, match=r"no part of the record .* hydro data's band 20\.\.30"):
        from_record((t, eta), data_band=(20.0, 30.0))


def sphere_record_text() -> str:
    """The shipped record: 300 s of a JONSWAP sea (Hs 1.5 m, Tp 8 s, seed 7) at 5 Hz, raised
    from rest over its first 24 s as a wavemaker does, with 1 mm of probe noise, written to
    0.1 mm: the sphere's guide example (notebooks/guide.md)."""
    sea = irregular(1.5, 8.0, seed=7, duration=300.0)
    t = np.arange(1500) * 0.2
    eta = dataclasses.replace(sea, ramp_time=0.0).elevation(t) * ramp(t, 24.0)
    eta = eta + 1e-3 * np.random.default_rng(7).standard_normal(t.size)
    head = ("# a synthetic tank record for the catalogue sphere: JONSWAP Hs 1.5 m, Tp 8 s, "
            "gamma 3.3, seed 7,\n# raised from rest over 24 s, 1 mm noise; written by "
            "tests/waves/test_record.py (sphere_record_text)\ntime_s,eta_m\n")
    return head + "".join(f"{a:.1f},{b:.4f}\n" for a, b in zip(t, eta))


def test_the_shipped_record_is_what_its_maker_writes():
    path = DATA / "sphere_record.csv"
    assert path.read_text() == sphere_record_text()
    wave = from_record(path, data_band=(0.05, 12.0))
    s = wave.settings
    # the sea's 1.5 m over the 276 s after the wavemaker's ramp (4 std of the whole record:
    # 1.473 m measured), Tp the raw periodogram's peak on its 300 s grid, the 39th harmonic
    # (7.69 s, the deterministic sea's peak 8 s falling between 37 and 38, the wavemaker's ramp
    # and the noise moving it); it starts at rest (|eta| < 6 mm over 3 s): no ramp
    assert s["hs_m"] == pytest.approx(1.473, abs=1e-3) and s["tp_s"] == pytest.approx(300 / 39)
    assert wave.ramp_time == 0.0 and s["samples"] == 1500 and s["duration_s"] == 300.0
