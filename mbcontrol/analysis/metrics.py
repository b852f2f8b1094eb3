"""Summaries of simulation results: amplitudes, statistics, PTO power, force and stroke.

Window: for a regular wave, the last 10 wave periods (steady state); for an irregular sea,
the record after the ramp (as WEC-Sim's statistics leave out its ramp); in both, no earlier
than the end of the controller's warm-up (`warm_up_s` in its describe(), e.g. an MPC's
passive start-up before its predictor's first fit). `statistics_window(ds)` says which, and
the summary records it ("window_start_s", "window"). Amplitude is half the peak-to-peak
within the window. Absorbed power is positive.

PTO power is taken from the work the PTO does over each step, not from the sampled power
-F v: a controller's force is held over each step (zero-order hold), and then the work
-F_k (x_{k+1} - x_k) is exact while the mean of -F_k v_k misses -F a dt / 2 per step (6 % of
the power of reactive control on the sphere at dt = 0.01 s). A force the plant computes
continuously (the scene's own PTO law, no controller) is integrated by the trapezoidal rule.
"""
from __future__ import annotations

import math

import numpy as np

from .. import defaults
from ..errors import InputError
from ..results import record, run_info


_BODY_KEYS = {"Surge": "surge_amplitude_m", "Sway": "sway_amplitude_m",
              "Heave": "heave_amplitude_m", "Roll": "roll_amplitude_rad",
              "Pitch": "pitch_amplitude_rad", "Yaw": "yaw_amplitude_rad"}


def analysis_window(ds) -> np.ndarray:
    """Boolean mask over time of the window the metrics use (see `statistics_window`)."""
    t = ds["time"].values
    info = statistics_window(ds)
    start = info["start_s"]
    mask = t >= start - 1e-9
    if mask.sum() < 2:
        raise InputError(f"the record ({t[-1]:.4g} s) is too short for the metrics window "
                         f"starting at {start:.4g} s ({info['note']}); simulate at least "
                         f"{info['shortest_duration_s']:.4g} s (--duration)")
    return mask


def statistics_window(ds) -> dict:
    """Where the statistics start and whether the window can be trusted:
    {"start_s", "end_s", "periods" (wave periods in the window, None without a period),
    "note" (why there), "problem" (None, or why the window cannot give steady statistics),
    "shortest_duration_s" (the shortest run whose window would do)}.

    The window never starts before the wave's ramp has ended nor before the controller's
    warm-up has (the run record's controller, mbcontrol.results.RunInfo). A regular wave: its
    last "stats.min_periods" periods; a sea: the record after the ramp. A caller may set the start,
    ds.attrs["statistics_from_s"] with its reason in ds.attrs["statistics_note"] (design scores
    a sea over its last whole repeat period, as the bounds it is compared with). A window that
    overlaps the ramp or the warm-up, or holds fewer than "stats.min_periods" periods, has a
    "problem": `validity.assess` marks the result invalid with it."""
    t = ds["time"].values
    end = float(t[-1])
    run = run_info(ds)
    wave = record(ds.attrs, "wave", {})
    ramp, warm_up = float(wave.get("ramp_s", 0.0) or 0.0), float(run.warm_up_s or 0.0)
    # periods a window holds at least (a regular wave's, a sea's peak period; 10 by default):
    # a regular wave's steady state is read over its last 10 periods, and a sea's mean power
    # over fewer peak periods than that scatters by tens of percent between seeds
    n_periods = int(defaults.get("stats.min_periods"))
    earliest = max(ramp, warm_up)
    period = _wave_period(wave)
    if run.statistics_from_s is not None:
        start, note = run.statistics_from_s, str(run.statistics_note or "set by the caller")
    elif wave.get("type") == "regular":
        start, note = max(end - n_periods * period, earliest), f"the last {n_periods} wave periods"
    else:
        start = earliest
        note = f"after the wave's ramp ({ramp:.4g} s)" if ramp > 0 else "the whole record"
    if warm_up:
        note += f", and after the controller's warm-up ({warm_up:.4g} s)"
    periods = None if not period else (end - start) / period
    shortest = earliest + n_periods * (period or 0.0)
    problem = None
    if end <= start:
        problem = (f"the record ends at {end:.4g} s, before its statistics window would start "
                   f"({start:.4g} s: the wave's ramp and any warm-up come first)")
    elif start < earliest - 1e-9:
        problem = (f"the statistics window starts at {start:.4g} s, before the "
                   f"{'ramp' if ramp >= warm_up else 'controller warm-up'} ends at "
                   f"{earliest:.4g} s")
    elif periods is not None and periods < n_periods * (1 - 1e-6):
        problem = (f"the statistics window ({start:.4g} s to {end:.4g} s, after the ramp and "
                   f"any warm-up) holds {periods:.3g} wave periods of {period:.4g} s, fewer "
                   f"than the {n_periods} steady statistics need (stats.min_periods)")
    return {"start_s": start, "end_s": end, "periods": periods,
            "note": f"statistics over t >= {start:.4g} s: {note}", "problem": problem,
            "shortest_duration_s": max(shortest, start + n_periods * (period or 0.0))}


def _wave_period(wave: dict) -> float | None:
    """The period (s) a window is counted in: a regular wave's, else a sea's peak period, else
    None (a measured record, a spectrum given without one)."""
    for key in ("period", "tp"):
        value = wave.get(key)
        if isinstance(value, (int, float)) and value > 0:
            return float(value)
    return None


def signal_stats(values) -> dict:
    return {"amplitude": 0.5 * float(values.max() - values.min()), "mean": float(values.mean()),
            "std": float(values.std()), "max_abs": float(np.abs(values).max())}


def step_power(ds, pto: str) -> tuple[np.ndarray, np.ndarray]:
    """(t_k, P_k): the PTO's mean absorbed power over each step [t_k, t_k+1), W, from its work.

    Held force (a controller ran): P_k = -F_k (x_k+1 - x_k) / dt, exact. Otherwise the
    trapezoidal rule on the sampled force.
    """
    t = ds["time"].values
    force, x = ds[f"{pto}__force"].values, ds[f"{pto}__position"].values
    held = record(ds.attrs, "controller") is not None
    f = force[:-1] if held else 0.5 * (force[:-1] + force[1:])
    return t[:-1], -f * np.diff(x) / np.diff(t)


def electrical_power(power, efficiency: float) -> np.ndarray:
    """Electrical power (W) from mechanical absorbed power: eta P when absorbing, P / eta when
    the PTO drives the body (reactive power is bought back at a loss), as WECCCOMP scores it."""
    power = np.asarray(power, float)
    return np.where(power > 0, efficiency * power, power / efficiency)


def _drivetrain_metrics(ds, name: str, steps, samples, power, drive) -> dict:
    """With a drivetrain model: electrical power = the machine's absorbed power (from work,
    as mean_power_W) less the winding loss of each step's held current; its mean, the mean
    winding loss, the peak current (A) and voltage (V) and, with the scene's drivetrain, how
    far they and the peak electrical power pass its current_max, voltage_max, power_max."""
    loss = ds[f"{name}__winding_loss"].values[:-1][steps]
    out = {"mean_electrical_power_W": float((power - loss).mean()),
           "mean_winding_loss_W": float(loss.mean()),
           "max_current_A": float(np.abs(ds[f"{name}__current"].values[samples]).max()),
           "max_voltage_V": float(np.abs(ds[f"{name}__voltage"].values[samples]).max()),
           "max_electrical_power_W": float(np.abs(power - loss).max())}
    if drive is not None:
        for key, limit in (("current", drive.current_max), ("voltage", drive.voltage_max),
                           ("electrical_power", drive.power_max)):
            peak = out["max_current_A" if key == "current" else "max_voltage_V"
                       if key == "voltage" else "max_electrical_power_W"]
            out[f"{key}_violation"] = float(max(peak - limit, 0.0))
    return out


def pto_metrics(ds, pto, start: float | None = None, end: float | None = None) -> dict:
    """Power, force and stroke metrics of one PTO over [start, end) s (default: the analysis
    window). `pto` is a scene Pto (its limits and efficiency are used) or a PTO name.

    Keys: mean_power_W (mechanical, absorbed > 0, from work), mean_electrical_power_W (from
    the drivetrain model when the PTO has one, with mean_winding_loss_W, max_current_A and
    max_voltage_V; else with the PTO's efficiency), mean_abs_power_W, papr (peak |P| over mean P; inf when mean P <= 0),
    p98_W (98th percentile of |P|), max_force, f98, max_stroke, z98 (98th percentiles of |F|
    and |x|; F the force the limit acts on, force_max_on: the machine's or the hull's),
    force_max / stroke_max (the PTO's limits), force_violation / stroke_violation
    (worst excess over the limit, 0 if none) and violation_fraction (share of samples outside
    either limit). Force and stroke are in the PTO's units (N, m or N m, rad).
    """
    name = pto if isinstance(pto, str) else pto.name
    force_max = getattr(pto, "force_max", math.inf)
    stroke_max = getattr(pto, "stroke_max", math.inf)
    efficiency = getattr(pto, "efficiency", 1.0)
    t_step, p_step = step_power(ds, name)
    t = ds["time"].values
    if start is None and end is None:
        mask = analysis_window(ds)
        start = float(t[mask][0])
    lo = -np.inf if start is None else start - 1e-9
    hi = np.inf if end is None else end - 1e-9
    steps = (t_step >= lo) & (t_step < hi)
    samples = (t >= lo) & (t < hi)
    if steps.sum() < 1:
        raise InputError(f"empty metrics window [{start}, {end}) s in a {t[-1]:.4g} s record")
    power = p_step[steps]
    # the force the limit acts on: the machine's, or with force_max_on "hull" the force the
    # drivetrain puts on the hull (the plant's <pto>__hull_force)
    on_hull = getattr(pto, "force_max_on", "machine") == "hull" and f"{name}__hull_force" in ds
    force = np.abs(ds[f"{name}__hull_force" if on_hull else f"{name}__force"].values[samples])
    stroke = np.abs(ds[f"{name}__position"].values[samples])
    mean = float(power.mean())
    outside = (force > force_max * (1 + 1e-9)) | (stroke > stroke_max * (1 + 1e-9))
    electrical = _drivetrain_metrics(ds, name, steps, samples, power,
                                     getattr(pto, "drivetrain", None)) \
        if f"{name}__winding_loss" in ds else \
        {"mean_electrical_power_W": float(electrical_power(power, efficiency).mean())}
    return {
        "mean_power_W": mean,
        **electrical,
        "mean_abs_power_W": float(np.abs(power).mean()),
        "papr": float(np.abs(power).max() / mean) if mean > 0 else math.inf,
        "p98_W": float(np.percentile(np.abs(power), 98)),
        "max_force": float(force.max()), "f98": float(np.percentile(force, 98)),
        "max_stroke": float(stroke.max()), "z98": float(np.percentile(stroke, 98)),
        "force_max": force_max, "force_max_on": "hull" if on_hull else "machine",
        "stroke_max": stroke_max, "efficiency": efficiency,
        "force_violation": float(max(force.max() - force_max, 0.0)),
        "stroke_violation": float(max(stroke.max() - stroke_max, 0.0)),
        "violation_fraction": float(outside.mean()),
        # the run's physics verdict when it has one (mbcontrol.analysis.validity.assess)
        **({"valid": bool(ds.attrs["valid"]),
            "invalid_reasons": record(ds.attrs, "invalid_reasons", [])}
           if "valid" in ds.attrs else {}),
    }


def wecccomp_score(ds, pto, start: float = 25.0, end: float | None = None) -> dict:
    """The WEC Control Competition's evaluation criterion, scored over t > start (25 s):

        EC = P_e / (2 + F98 / F_max + z98 / z_max - mean|P| / P98)

    P_e: mean electrical power (efficiency applied both ways, W); F98, z98, P98: 98th
    percentiles of |force|, |stroke| and |mechanical power|; F_max, z_max: the PTO's limits,
    which must be finite. Returns the pto_metrics over the window plus "EC" (W).
    """
    m = pto_metrics(ds, pto, start, end)
    if not (math.isfinite(m["force_max"]) and math.isfinite(m["stroke_max"])):
        raise InputError(f"PTO {getattr(pto, 'name', pto)!r}: the WECCCOMP score needs finite "
                         f"force_max and stroke_max in the scene")
    denominator = (2 + m["f98"] / m["force_max"] + m["z98"] / m["stroke_max"]
                   - m["mean_abs_power_W"] / m["p98_W"])
    return {**m, "EC": m["mean_electrical_power_W"] / denominator}
