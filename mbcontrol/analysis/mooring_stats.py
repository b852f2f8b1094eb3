"""Line tension statistics of a run with MoorDyn moorings: what a mooring designer reads.

Per line and end (the fairlead, end B, and the anchor, end A; variables
"<mooring>__line<k>__<end>_tension", N, in the run's Dataset): mean, standard deviation,
minimum, maximum, the level exceeded 1 % of the time (p99), and the most probable maximum in
a three-hour sea state (`MPM_HOURS`), mean + std sqrt(2 ln N) with N = 3 h / Tz the number of
mean up-crossings (Tz from the record's own up-crossings of its mean): the short-term
extreme of a narrow-banded Gaussian process (Rayleigh peaks), the design-load estimate of
mooring standards' quasi-static and dynamic analyses (e.g. DNV-OS-E301 uses the MPM of a
three-hour storm). It is an estimate under that assumption; the record's own max is beside
it, and a record whose max exceeds it is flagged non-Gaussian ("gaussian": false: snap
loads). A line is "slack" where its tension falls below SLACK_FRACTION of its mean: the first
such time is reported (snap loads follow slack). Lines that reached their breaking load or
the sea bed are the run's own record (sim.moordyn_events), reported by `event_notes`.
"""
from __future__ import annotations

import math
import re

import numpy as np
from .. import defaults

# MPM_HOURS: the default "mooring.mpm_hours" (mbcontrol.defaults)
# SLACK_FRACTION: the default "mooring.slack_fraction" (mbcontrol.defaults)
_NAME = re.compile(r"^(?P<mooring>.+)__line(?P<line>\d+)__(?P<end>anchor|fairlead)_tension$")


def tension_statistics(t: np.ndarray, tension: np.ndarray) -> dict:
    """Statistics of one tension record (N) sampled at times t (s); see the module docstring."""
    t, x = np.asarray(t, float), np.asarray(tension, float)
    mean, std = float(np.mean(x)), float(np.std(x))
    above = x > mean
    ups = int(np.count_nonzero(~above[:-1] & above[1:]))
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    out = {"mean_N": mean, "std_N": std, "min_N": float(np.min(x)), "max_N": float(np.max(x)),
           "p99_N": float(np.percentile(x, 99.0)), "mpm_3h_N": None, "tz_s": None,
           "slack_at_s": None}
    if ups >= 2 and std > 0:
        tz = span / ups
        crossings = defaults.get("mooring.mpm_hours") * 3600.0 / tz
        out.update(tz_s=tz, mpm_3h_N=mean + std * math.sqrt(2.0 * math.log(crossings)))
    # a shorter record's max above the Gaussian 3-hour estimate: the load is not Gaussian
    # (snap loads, a line going slack and taut), and the estimate is not to be trusted
    out["gaussian"] = out["mpm_3h_N"] is not None and out["max_N"] <= out["mpm_3h_N"]
    slack = np.flatnonzero(x < defaults.get("mooring.slack_fraction") * abs(mean))
    if slack.size:
        out["slack_at_s"] = float(t[slack[0]])
    return out


def mooring_summary(ds, mask=None) -> dict:
    """{mooring: {"line<k>": {"fairlead": stats, "anchor": stats}}} over the samples `mask`
    (None: all) of a Dataset's tension variables; {} without MoorDyn moorings."""
    t = ds["time"].values
    keep = slice(None) if mask is None else mask
    out: dict = {}
    for name in ds.data_vars:
        found = _NAME.match(str(name))
        if not found:
            continue
        line = out.setdefault(found["mooring"], {}).setdefault(f"line{found['line']}", {})
        line[found["end"]] = tension_statistics(t[keep], ds[name].values[keep])
    return out


def slack_lines(summary: dict) -> list[str]:
    """Warnings for every line end that went slack, with the time, and for every fairlead
    whose record holds more than its Gaussian 3-hour most probable maximum (snap loads)."""
    notes = []
    for mooring, lines in summary.items():
        for line, ends in lines.items():
            fairlead = ends["fairlead"]
            if fairlead["mpm_3h_N"] is not None and not fairlead["gaussian"]:
                notes.append(f"mooring '{mooring}' {line}: the record's largest fairlead tension "
                             f"{fairlead['max_N']:.4g} N exceeds its Gaussian 3-hour most "
                             f"probable maximum {fairlead['mpm_3h_N']:.4g} N: snap loads, not a "
                             f"Gaussian load; design on the record's extremes (longer runs, "
                             f"more seeds), not on the estimate")
            for end, stats in ends.items():
                if stats["slack_at_s"] is not None:
                    notes.append(f"mooring '{mooring}' {line} went slack at its {end} at "
                                 f"t = {stats['slack_at_s']:.4g} s (tension below "
                                 f"{defaults.get('mooring.slack_fraction'):.0%} of its mean {stats['mean_N']:.4g} N): "
                                 f"snap loads follow; check the line's length and pretension")
    return notes


def line_events(ds) -> dict:
    """The run's breaking loads reached and sea-bed contact (sim.moordyn_events): {mooring:
    {line: {"breaking_load_at_s", "end", "tension_N"} and/or {"bed_contact_at_s"}}}."""
    from ..results import record
    return record(ds.attrs, "moordyn_events", {}) or {}


def event_notes(events: dict) -> list[str]:
    """Warnings for every line that reached its breaking load or the sea bed, with the time."""
    notes = []
    for mooring, lines in events.items():
        for line, happened in lines.items():
            if "breaking_load_at_s" in happened:
                notes.append(f"mooring '{mooring}' {line} reached its breaking load at its "
                             f"{happened['end']} at t = {happened['breaking_load_at_s']:.4g} s "
                             f"(tension {happened['tension_N']:.4g} N); the run kept it intact, "
                             f"so what follows is not the damaged mooring's response")
            if "bed_contact_at_s" in happened:
                notes.append(f"mooring '{mooring}' {line}, clear of the sea bed at the start, "
                             f"reached it at t = {happened['bed_contact_at_s']:.4g} s")
    return notes


def tension_lines(summary: dict) -> list[str]:
    """The text report of `mooring_summary`: per mooring a header, then per line its fairlead
    and its anchor statistics in kN (mean, std, max, p99, 3-hour most probable maximum)."""
    out = []
    for mooring, lines in summary.items():
        out.append(f"mooring {mooring}, tensions in kN (fairlead; anchor): mean, std, max, p99, "
                   f"3-hour most probable max")
        for line, ends in lines.items():
            out.append(f"  {line}: " + "; ".join(_kilonewtons(ends[end])
                                                  for end in ("fairlead", "anchor")))
    return out


def _kilonewtons(stats: dict) -> str:
    mpm = stats["mpm_3h_N"]
    values = (stats["mean_N"], stats["std_N"], stats["max_N"], stats["p99_N"])
    return ", ".join(f"{v / 1e3:.4g}" for v in values) + (f", {mpm / 1e3:.4g}" if mpm else ", -")
