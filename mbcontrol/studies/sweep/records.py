"""Measured seas as a sweep's cases (`mbcontrol sweep SCENE --records DIR`): each file of a
folder is one sea, a measured free-surface elevation record (`waves.from_record`: two columns,
time s and elevation m), run like a sea state's case (same controller, store, checks, rows).

Every file is read and checked before any case runs (with the hydro data's band and the run's
duration, as the case will read it); the files that cannot be used are refused together, each
by its WaveError naming the file. A case carries its record's path (where to read it, not part
of its key) and the SHA-256 of its bytes (part of its key: an edited file is a new case, a
moved one is not); a case reads the file again where it runs (a Dask worker must see the
folder, as it sees the scene) and refuses a file changed since it was checked.

A record's row in the table: Hs = 4 sqrt(m0) (4 std of its elevation, mean removed), Tp the
peak of its periodogram (one record's raw spectrum, as `from_record` reports it), Te =
m_-1 / m0, and its energy flux J = rho g sum_k var_k c_g(omega_k) from its own components (all
of them, as Hs) in the scene's water, so that P / J is its capture width. A record has no
occurrence weight: the sweep has no annual energy (said in its notes). File names are data:
rows and JSON carry them as they are, text notes escaped (`textsafe.plain_text`).
Tests: tests/features/cli/test_sweep_records.py.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import InputError, WaveError
from ...textsafe import plain_text, shown
from ...waves import SeaState, from_record, group_velocities, read_elevation

NO_ANNUAL_ENERGY = ("no annual energy: measured records carry no occurrence weights (the "
                    "share of the year each sea stands for), so weighted_mean_power_W and "
                    "annual_energy_MWh are null; each row is that record's sea as measured")
HOW_SEAS_ARE_NAMED = ("records: each row's Hs is 4 std of its record's elevation, Tp the peak "
                      "of its periodogram (one record's raw spectrum: a noisy estimate), Te "
                      "m-1/m0 and the energy flux its own spectrum's in the scene's water")


@dataclass(frozen=True)
class MeasuredSea:
    """One record of the folder: its file name, absolute path and content hash, its sea
    (hs, tp, te in m and s; j W/m), the run's duration (s) and what reading it noted."""
    name: str
    path: str
    sha256: str
    hs: float
    tp: float
    te: float
    j: float
    duration: float
    notes: tuple = ()

    @property
    def sea(self) -> SeaState:
        return SeaState(self.hs, self.tp, math.nan, te=self.te, j=self.j)


def measured_seas(folder, plant, duration: float | None, *, seeds: int, amplitudes: str,
                  seas) -> list[MeasuredSea] | None:
    """The seas of a folder of records (`read_records`) after `check_options`; None without a
    folder (a sweep over sea states)."""
    if folder is None:
        return None
    check_options(seeds=seeds, amplitudes=amplitudes, seas=seas)
    return read_records(folder, plant, duration)


def check_options(*, seeds: int, amplitudes: str, seas) -> None:
    """What a sweep over records cannot take: seeds, random amplitudes, a spread (a record is
    one realisation, measured at a point)."""
    if seeds != 1:
        raise InputError(f"--seeds {seeds} with --records: a record is one realisation of its "
                         f"sea (no seed); expected --seeds 1")
    if amplitudes != "deterministic":
        raise InputError("--amplitudes random with --records: a record's amplitudes are the "
                         "measured ones; leave --amplitudes out")
    if seas:
        raise InputError("--records gives the seas: no other seas (--hs, --seas) with it")


def record_files(folder) -> list[Path]:
    """Every file of the folder (hidden ones left out), by name."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"--records {shown(str(folder))}: not a folder; expected a folder of "
                         f"elevation records, one file per sea")
    files = sorted(p for p in folder.iterdir() if p.is_file() and not p.name.startswith("."))
    if not files:
        raise InputError(f"--records {shown(str(folder))}: no files; expected elevation "
                         f"records (two columns, time s and elevation m), one file per sea")
    return files


def read_records(folder, plant, duration: float | None = None) -> list[MeasuredSea]:
    """The folder's records, each checked as its case will read it (the hydro data's band;
    `duration` s, or each record's own length when None); WaveError listing every file that
    cannot be used, before anything runs."""
    omega = plant.hydro.omega
    band = (float(omega[0]), float(omega[-1]))
    water = plant.scene.water
    out, bad = [], []
    for path in record_files(folder):
        try:
            wave = from_record(path, data_band=band, duration=duration)
            with warnings.catch_warnings():        # the same file: warned once, just above
                warnings.simplefilter("ignore", RuntimeWarning)
                t, eta = read_elevation(path)
        except WaveError as exc:
            bad.append(plain_text(exc))      # a file name is data: escaped for the terminal
            continue
        s = wave.settings
        te, j = _flux(t, eta, water.depth, water.rho, water.g)
        out.append(MeasuredSea(path.name, str(path.resolve()), s["sha256"], float(s["hs_m"]),
                               float(s["tp_s"]), te, j,
                               float(duration if duration is not None else s["duration_s"]),
                               tuple(plain_text(n) for n in s.get("notes", ()))))
    if bad:
        raise WaveError(f"--records {shown(str(folder))}: {len(bad)} of "
                        f"{len(bad) + len(out)} files are not usable elevation records; "
                        f"nothing was run:\n  " + "\n  ".join(bad))
    return out


def _flux(t, eta, depth: float, rho: float, g: float) -> tuple[float, float]:
    """(Te s, J W/m) of a record from its periodogram (mean removed, every component)."""
    n = t.size
    dt = float(t[-1] - t[0]) / (n - 1)
    spectrum = np.fft.rfft(eta - np.mean(eta))
    var = 2 * np.abs(spectrum[1:]) ** 2 / n ** 2
    if n % 2 == 0:
        var[-1] /= 2                                   # the Nyquist term is one cosine
    omega = np.arange(1, spectrum.size) * (2 * np.pi / (n * dt))
    te = 2 * np.pi * float(np.sum(var / omega) / np.sum(var))
    return te, float(rho * g * np.sum(var * group_velocities(omega, depth, g)))


def with_records(cases, records) -> list:
    """The sweep's cases (built on the records' seas) each given its record and duration."""
    return [dataclasses.replace(c, record=records[c.index[0]].path,
                                record_sha256=records[c.index[0]].sha256,
                                duration=records[c.index[0]].duration) for c in cases]


def record_wave(plant, case):
    """A record case's wave where it runs: the file read again with the hydro data's band,
    refused if it changed since the sweep checked it; its direction as `sea_wave` chooses."""
    omega = plant.hydro.omega
    with warnings.catch_warnings():                 # an uneven step was said at the check
        warnings.simplefilter("ignore", RuntimeWarning)
        wave = from_record(case.record, data_band=(float(omega[0]), float(omega[-1])),
                           duration=case.duration)
    if wave.settings["sha256"] != case.record_sha256:
        raise WaveError(f"{shown(case.record)}: the record changed after the sweep checked it "
                        f"(SHA-256 {wave.settings['sha256'][:12]}..., checked "
                        f"{case.record_sha256[:12]}...); expected the file unchanged while the "
                        f"sweep runs: run the sweep again")
    headings = plant.hydro.data["wave_direction"].values
    direction = math.radians(case.direction_deg) if case.direction_deg is not None else \
        float(headings[0]) if len(headings) == 1 else 0.0
    return dataclasses.replace(wave, direction=direction)


def label_summary(summary: dict, records) -> None:
    """The summary of a sweep over records (in place): per sea "record" (its file name),
    "record_sha256" and "duration_s"; each invalid or failed case's "record"; the notes on
    what a record's row means, the missing annual energy and what reading each file noted."""
    for row, r in zip(summary["seas"], records):
        row.update(record=r.name, record_sha256=r.sha256, duration_s=r.duration)
    by_sea = {(r.hs, r.tp): r.name for r in reversed(records)}
    for case in summary["invalid"] + summary["failed"]:
        case["record"] = by_sea.get((case["hs"], case["tp"]))
    summary["notes"] = [NO_ANNUAL_ENERGY, HOW_SEAS_ARE_NAMED] + summary["notes"] + [
        note for r in records for note in r.notes]
