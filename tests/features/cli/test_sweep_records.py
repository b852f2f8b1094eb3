"""`mbcontrol sweep SCENE --records DIR`: a sweep whose seas are the measured elevation records
of a folder (mbcontrol.studies.sweep.records). Each record's case is the plain simulation of
that record's wave (mean power to 1e-9), its row carries the file's own Hs (4 std of the
elevation in the file), Tp (the peak of the file's periodogram) and deep-water energy flux
(rho g^2 Hs^2 Te / 64 pi, Te from that periodogram), all computed here from the file, not
read back; there is no annual energy, and the output says so; the store resumes (a second
run computes nothing, an edited file runs again); a bad file is refused, named, before
anything runs; file names are data (escaped in the text report, exact in the JSON)."""
import dataclasses
import json
import math

import numpy as np
import pytest

from mbcontrol.cli import main
from mbcontrol.waves import irregular

SEAS = {"calm.csv": (0.5, 4.0, 1), "swell 2$ `x`\n.csv": (0.8, 5.0, 2), "c.txt": (0.6, 6.0, 3)}
FLAGS = ("--dt", "0.05", "--workers", "0")


def _write(path, hs, tp, seed):
    """120 s of a JONSWAP sea at 4 Hz, written with 6 decimals, mid-sea (ramped by the reader)."""
    sea = dataclasses.replace(irregular(hs, tp, seed=seed, duration=120.0), ramp_time=0.0)
    t = np.arange(480) * 0.25
    path.write_text("time_s, eta_m\n" + "".join(f"{a:.2f}, {b:.6f}\n"
                                                for a, b in zip(t, sea.elevation(t))))


@pytest.fixture
def folder(tmp_path):
    records = tmp_path / "records"
    records.mkdir()
    for name, (hs, tp, seed) in SEAS.items():
        _write(records / name, hs, tp, seed)
    (records / ".hidden").write_text("not a record: hidden files are left out\n")
    return records


def _file_sea(path):
    """(Hs, Tp, Te) of a file, from its own periodogram (mean removed)."""
    t, eta = np.loadtxt(path, delimiter=",", skiprows=1, unpack=True)
    n, dt = t.size, t[1] - t[0]
    var = 2 * np.abs(np.fft.rfft(eta - eta.mean())[1:]) ** 2 / n ** 2
    var[-1] /= 2
    omega = 2 * np.pi * np.arange(1, var.size + 1) / (n * dt)
    return (4 * np.std(eta), 2 * np.pi / omega[np.argmax(var)],
            2 * np.pi * np.sum(var / omega) / np.sum(var))


def test_a_record_case_is_its_records_simulation_and_the_store_resumes(folder, tmp_path,
                                                                       capsys):
    store, png = tmp_path / "store", tmp_path / "records.png"
    code = main(["sweep", "sphere", "--records", str(folder), "--store", str(store),
                 "--plot", str(png), "--json", *FLAGS])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    s = json.loads(captured.out)
    assert (s["cases"], s["computed"], s["reused"], s["valid_cases"]) == (3, 3, 0, 3)
    assert s["annual_energy_MWh"] is None and s["weighted_mean_power_W"] is None
    assert s["notes"][0].startswith("no annual energy: measured records carry no occurrence")
    rows = {r["record"]: r for r in s["seas"]}
    assert sorted(rows) == sorted(SEAS)                     # exact names, the hidden file out
    from mbcontrol.analysis import summary
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    from mbcontrol.waves import from_record
    plant = build_plant("sphere")
    band = (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))
    water = plant.scene.water
    assert math.isinf(water.depth)
    for name, row in rows.items():
        hs, tp, te = _file_sea(folder / name)
        assert row["hs"] == pytest.approx(hs, rel=1e-9)
        assert row["tp"] == pytest.approx(tp, rel=1e-9) and row["te"] == pytest.approx(te)
        assert row["duration_s"] == 120.0 and row["weight"] is None
        # deep water: J = rho g^2 Hs^2 Te / (64 pi) for any spectrum
        assert row["energy_flux_W_per_m"] == pytest.approx(
            water.rho * water.g ** 2 * hs ** 2 * te / (64 * math.pi), rel=1e-9)
        own = summary(simulate(plant, from_record(folder / name, data_band=band),
                               duration=120.0, dt=0.05), plant)
        assert row["mean_power_W"] == pytest.approx(own["ptos"]["pto"]["mean_power_W"],
                                                    rel=1e-9)
        assert row["capture_width_m"] == pytest.approx(row["mean_power_W"]
                                                       / row["energy_flux_W_per_m"])
    assert png.stat().st_size > 20_000
    import xarray as xr
    with xr.open_dataset(store / "sweep.nc") as ds:
        assert sorted(ds["record"].values.tolist()) == sorted(SEAS)
    # resumed: nothing computed; the text report names each record, escaped (the newline in
    # a name cannot start a row of its own)
    assert main(["sweep", "sphere", "--records", str(folder), "--store", str(store),
                 *FLAGS]) == 0
    out = capsys.readouterr().out
    assert "3 cases (0 computed, 3 reused)" in out
    assert "swell 2$ `x`\\n.csv" in out and "swell 2$ `x`\n" not in out
    assert "note: no annual energy" in out and "weighted mean power" not in out
    # an edited record is a new case (its key holds the file's hash); the others are reused
    _write(folder / "calm.csv", 0.55, 4.0, 1)
    assert main(["sweep", "sphere", "--records", str(folder), "--store", str(store),
                 "--json", *FLAGS]) == 0
    again = json.loads(capsys.readouterr().out)
    assert (again["computed"], again["reused"]) == (1, 2)
    new = {r["record"]: r for r in again["seas"]}
    assert new["c.txt"]["mean_power_W"] == rows["c.txt"]["mean_power_W"]
    assert new["calm.csv"]["hs"] == pytest.approx(_file_sea(folder / "calm.csv")[0], rel=1e-9)


def test_a_bad_file_is_refused_by_name_before_anything_runs(folder, tmp_path, capsys,
                                                           monkeypatch):
    (folder / "notes.csv").write_text("time, eta\n0, 0.1\n0.25, x\n")
    from mbcontrol.studies.sweep import runner

    def never(case):
        raise AssertionError("a case ran")
    monkeypatch.setattr(runner, "run_case", never)
    store = tmp_path / "store"
    code = main(["sweep", "sphere", "--records", str(folder), "--store", str(store), *FLAGS])
    err = capsys.readouterr().err
    assert code == 1
    assert "1 of 4 files are not usable elevation records; nothing was run" in err
    assert "notes.csv: line 3, column 2 (elevation (m)): 'x' is not a number" in err
    assert not store.exists()


@pytest.mark.parametrize("argv, message", [
    (("--seeds", "2"), "--seeds 2 with --records: a record is one realisation"),
    (("--amplitudes", "random"), "--amplitudes random with --records"),
    (("--tp", "8"), "--tp with --records"),
    (("--spread", "20"), "--spread with --records"),
])
def test_what_a_record_cannot_take_is_refused(folder, capsys, argv, message):
    assert main(["sweep", "sphere", "--records", str(folder), *argv, *FLAGS]) == 1
    assert message in capsys.readouterr().err


def test_a_folder_that_is_not_one_is_refused(tmp_path, capsys):
    assert main(["sweep", "sphere", "--records", str(tmp_path / "none"), *FLAGS]) == 1
    assert "not a folder; expected a folder of elevation records" in capsys.readouterr().err
    assert main(["sweep", "sphere", "--records", str(tmp_path), *FLAGS]) == 1
    assert "no files; expected elevation records" in capsys.readouterr().err
