"""The flume dataset of ../shared/data/tank (Sundsdal et al. 2025) as identification runs.

File names follow `SPPH[_R]`: S the series (1 calibration: waves alone; 3 sway, heave and roll
free; 4 sway and heave; 5 sway and roll; 6 heave and roll), PP the frequency index (01-14), H
the height code (1: 24 mm, 2: 40 mm nominal), R a repetition. `load_runs(files)` turns model
runs into `Run`s for `mbcontrol.studies.identify`:

- the steady window from the flume's geometry and the run's own wavemaker start (found in
  WM_Position): it opens when the ramp's end (RAMP_PERIODS after the paddle starts, at the
  group velocity c_g of finite depth) has passed the model plus SETTLE_PERIODS for the model's
  transient, and closes when waves reflected by the model have come back from the paddle,
  3 x / c_g after the paddle started (x = 7 m); whole periods only; a run with fewer than
  MIN_PERIODS, or whose record ends inside the window, is refused with the numbers. The beach's
  echo arrives earlier, (2 x_beach - x) / c_g, and the calibration windows stop before it (a probe
  sees nothing else to reflect); the model windows need not: in the calibration runs at
  4.95-7.0 rad/s the harmonic at WP_4 and WP_6 changes by 0.1-1.5 % when the echo arrives (one
  run, 1101_1 at WP_4, by 15 %), while the model reflects a large share of the wave, whose
  return from the paddle is what ends the window. Stopping at the echo would leave under two
  periods at 4.95-5.43 rad/s, the roll and heave resonances;
- the incident wave at the model from the calibration runs of the same PP and H: the first
  harmonic at each probe (in its own steady window), carried to x = 7 m as a progressive wave
  e^{i(k x - omega t)} and averaged over probes and repetitions (their spread is reported),
  related to the paddle's first harmonic, and applied to the model run's own paddle motion so
  the two runs need no common clock;
- the free DOFs of the series as channels (Sway m, Heave m, Roll rad), each checked (missing,
  NaN or flat: a tracking failure), and the plant the series needs: the blocked joint frozen
  (`Fidelity(freeze=...)`) and, with heave blocked, 0.3 kg more moving in sway.
"""
from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np

from ... import waves
from .costs import harmonic, whole_periods
from .problem import Run
from .records import RecordError, channel_problem, read_csv, require_quantity

DEPTH, G = 1.0, 9.81                    # m, m/s^2
MODEL_X = 7.0                           # m from the wavemaker
BEACH_X = 11.5                          # m, the middle of the parabolic beach (13.63 m - 2.1 m)
PROBES = {"WP_1": 3.00, "WP_2": 4.95, "WP_3": 5.20, "WP_4": 5.50, "WP_6": 8.50}   # m
RAMP_PERIODS = 5                        # the wavemaker's ramp (README)
SETTLE_PERIODS = 2                      # for the model's own transient after the ramp
MIN_PERIODS = 3                         # whole periods a steady window must hold
OMEGA = {1: 4.143, 2: 4.952, 3: 5.075, 4: 5.194, 5: 5.311, 6: 5.425, 7: 5.646, 8: 5.860,
         9: 6.065, 10: 7.004, 11: 7.830, 12: 8.578, 13: 9.265, 14: 9.905}           # rad/s
HEIGHT = {1: 0.024, 2: 0.040}           # m, nominal
SERIES = {3: ("Sway", "Heave", "Roll"), 4: ("Sway", "Heave"), 5: ("Sway", "Roll"),
          6: ("Heave", "Roll")}
QUANTITY = {"Sway": "length", "Heave": "length", "Roll": "angle", "WM_Position": "length"}
FREEZE = {3: (), 4: ("roll",), 5: ("heave",), 6: ("sway",)}     # joints of flume_section.toml
SCENE_PARAMETERS = {5: {"sway_extra_mass": 0.3}}                 # kg: the heave block rides in sway
_NAME = re.compile(r"^(?P<series>\d)(?P<pp>\d\d)(?P<h>\d)(?:_(?P<rep>\d+))?$")


def parse_name(path) -> dict:
    """{series, pp, omega (rad/s), height_code, height (m), repetition} from `SPPH[_R]`."""
    path = Path(path)
    stem = path.name.split(".")[0]
    m = _NAME.match(stem)
    if not m or int(m["pp"]) not in OMEGA or int(m["h"]) not in HEIGHT:
        raise RecordError(f"{path}: name {stem!r} does not follow the flume convention SPPH[_R] "
                          f"(S series 1-6, PP 01-14, H 1 or 2, R a repetition), e.g. 4021_1")
    pp, h = int(m["pp"]), int(m["h"])
    return {"series": int(m["series"]), "pp": pp, "omega": OMEGA[pp], "height_code": h,
            "height": HEIGHT[h], "repetition": int(m["rep"]) if m["rep"] else 0}


def wavemaker_start(record, share: float = 0.05) -> float:
    """Time (s) the paddle starts: WM_Position first leaves its still level by `share` of its
    largest excursion."""
    require_quantity(record, "WM_Position", "length")
    t, wm = record.time, record.channel("WM_Position")
    still = np.median(wm[: max(10, int(0.5 / np.median(np.diff(t))))])
    excursion = np.abs(wm - still)
    if excursion.max() <= 0:
        raise RecordError(f"{record.path}: WM_Position never moves; expected a wavemaker start")
    return float(t[np.argmax(excursion > share * excursion.max())])


def steady_window(start: float, omega: float, x: float = MODEL_X) -> tuple[float, float]:
    """(open, close) s: ramp passed plus the settling periods, until the model's reflection is
    back from the paddle (see the module notes); not yet cut to whole periods."""
    period, cg = 2 * math.pi / omega, waves.group_velocity(omega, DEPTH, G)
    return start + x / cg + (RAMP_PERIODS + SETTLE_PERIODS) * period, start + 3 * x / cg


def _paddle(record, start, omega):
    """The paddle's first harmonic (complex) over whole periods after its ramp."""
    period = 2 * math.pi / omega
    t0 = start + (RAMP_PERIODS + 1) * period
    return harmonic(record.time, record.channel("WM_Position"), omega, t0,
                    min(t0 + 10 * period, record.time[-1]))


def incident_transfer(paths, omega: float) -> tuple[complex, float]:
    """(H, spread): the incident wave's first harmonic at the model per unit paddle harmonic,
    from calibration runs, and the relative spread of the estimates (over probes and runs)."""
    k, period = waves.wavenumber(omega, DEPTH, G), 2 * math.pi / omega
    estimates = []
    for path in paths:
        record = read_csv(path)
        start = wavemaker_start(record)
        paddle = _paddle(record, start, omega)
        for probe, x in PROBES.items():
            if probe not in record.channels or channel_problem(record, probe):
                continue
            require_quantity(record, probe, "length")
            t0 = start + x / waves.group_velocity(omega, DEPTH, G) + (RAMP_PERIODS + 1) * period
            t1 = start + (2 * BEACH_X - x) / waves.group_velocity(omega, DEPTH, G)   # before the beach's echo
            try:
                a = harmonic(record.time, record.channels[probe], omega, t0, t1)
            except ValueError:
                continue
            # progressive wave, Re(A e^{i omega t}) with A(x) = A(x_p) e^{-i k (x - x_p)}
            estimates.append(a * np.exp(-1j * k * (MODEL_X - x)) / paddle)
    if not estimates:
        raise RecordError(f"calibration {', '.join(map(str, paths))}: no probe gave a steady "
                          f"harmonic at omega = {omega} rad/s")
    estimates = np.array(estimates)
    mean = complex(np.mean(estimates))
    return mean, float(np.std(np.abs(estimates)) / abs(mean))


def calibration_files(folder, pp: int, height_code: int) -> list[Path]:
    """The calibration runs 1PPH and 1PPH_R in `folder`."""
    folder = Path(folder)
    if not folder.is_dir():
        raise RecordError(f"{folder}: no calibration folder (the 1PPH[_R] runs of waves alone, "
                          f"by default `calibration` beside the data files' folder); give it "
                          f"with --calibration DIR (calibration= in Python)")
    found = sorted(p for p in folder.glob(f"1{pp:02d}{height_code}*.csv*")
                   if _NAME.match(p.name.split(".")[0]))
    if not found:
        raise RecordError(f"{folder}: no calibration run 1{pp:02d}{height_code}[_R].csv[.xz] "
                          f"for frequency index {pp:02d} and height code {height_code}")
    return found


def load_run(path, calibration, *, channels: dict | None = None,
             transfers: dict | None = None) -> Run:
    """One model run as a `Run` (see the module notes); RecordError names file and channel.
    transfers: a dict shared by calls (load_runs) that keeps each calibration's
    `incident_transfer`, so that runs of one frequency and height read their calibration
    runs once."""
    path = Path(path)
    info = parse_name(path)
    if info["series"] not in SERIES:
        raise RecordError(f"{path}: series {info['series']} is not a model run; expected one of "
                          f"{sorted(SERIES)} (1 is a calibration run)")
    record = read_csv(path)
    omega, free = info["omega"], SERIES[info["series"]]
    start = wavemaker_start(record)
    open_, close = steady_window(start, omega)
    if record.time[-1] < close:
        raise RecordError(f"{path}: the record ends at {record.time[-1]:.2f} s, before its steady "
                          f"window closes ({open_:.2f}-{close:.2f} s: the ramp's passage to the "
                          f"reflections' return); a cut record is not used")
    try:
        open_, close, n = whole_periods(record.time, omega, open_, close)
    except ValueError:
        n = 0
    if n < MIN_PERIODS:
        raise RecordError(f"{path}: {n} whole wave period(s) ({2 * math.pi / omega:.3f} s) between "
                          f"the ramp's passage ({open_:.2f} s) and the reflections' return "
                          f"({close:.2f} s); expected at least {MIN_PERIODS} for a steady "
                          f"harmonic")
    names = channels or {c: c for c in free}
    for channel in free:
        require_quantity(record, channel, QUANTITY[channel])
        problem = channel_problem(record, channel, (open_, close))
        if problem:
            raise RecordError(f"{path}: {problem}")
    files = tuple(calibration_files(calibration, info["pp"], info["height_code"]))
    transfers = {} if transfers is None else transfers
    if (files, omega) not in transfers:
        transfers[files, omega] = incident_transfer(files, omega)
    transfer, spread = transfers[files, omega]
    incident = transfer * _paddle(record, start, omega)
    return Run(name=path.name.split(".")[0], omega=omega, amplitude=abs(incident),
               phase=float(np.angle(incident)), window=(open_, close), time=record.time,
               channels={names[c]: record.channels[c] for c in free},
               group=f"series {info['series']}", freeze=FREEZE[info["series"]],
               scene_parameters=dict(SCENE_PARAMETERS.get(info["series"], {})), source=str(path),
               notes={"periods": n, "calibration_spread": spread, **info})


def load_runs(paths, calibration=None, *, drop_bad: bool = False) -> list[Run]:
    """Runs from files; calibration: the folder of 1PPH files (default: `calibration` beside
    the data files' folder). drop_bad: skip unusable runs with one warning listing each and
    why, instead of raising at the first."""
    paths = [Path(p) for p in paths]
    if not paths:
        raise RecordError("no data files given")
    calibration = Path(calibration) if calibration else paths[0].parent.parent / "calibration"
    runs, dropped = [], []
    transfers: dict = {}      # runs of one frequency and height share their calibration runs
    for path in paths:
        try:
            runs.append(load_run(path, calibration, transfers=transfers))
        except RecordError as exc:
            if not drop_bad:
                raise
            dropped.append(str(exc))
    if not runs:
        raise RecordError(f"no usable run among the {len(paths)} file(s) given" + (
            ":\n  " + "\n  ".join(dropped) if dropped else ""))
    if dropped:
        warnings.warn(f"dropped {len(dropped)} run(s):\n  " + "\n  ".join(dropped), stacklevel=2)
    return runs
