"""The `mbcontrol simulate --json` contract: a run's metrics with its physics verdict and its
provenance, in one dict (`summary`)."""
from __future__ import annotations

import copy

import numpy as np

from ..results import jsonable, record, run_info
from .metrics import _BODY_KEYS, analysis_window, pto_metrics, signal_stats, statistics_window
from .mooring_stats import event_notes, line_events, mooring_summary, slack_lines
from .validity import assess


def summary(ds, plant) -> dict:
    """The `mbcontrol simulate --json` contract (see README)."""
    mask = analysis_window(ds)
    stats_window = statistics_window(ds)
    coords = plant.topology.tree.coordinate_names
    dofs = {name: signal_stats(ds[name].values[mask]) for name in coords}
    bodies = {}
    for body in plant.topology.bodies:
        bodies[body] = {key: 0.5 * float(np.ptp(ds[f"{body}__{dof}"].values[mask]))
                        for dof, key in _BODY_KEYS.items()}
    verdict = _verdict(ds, plant)
    run = copy.deepcopy(run_info(ds))      # the summary is the caller's to change
    ptos = {pto.name: jsonable({**pto_metrics(ds, pto), "valid": verdict["valid"],
                                "invalid_reasons": verdict["invalid_reasons"]})
            for pto in plant.scene.ptos}
    moorings, events = mooring_summary(ds, mask), line_events(ds)
    return {"model": ds.attrs["model"], "valid": verdict["valid"],
            "invalid_reasons": verdict["invalid_reasons"],
            "validity_warnings": verdict["warnings"] + slack_lines(moorings)
            + event_notes(events), "wave": run.wave,
            "duration_s": float(ds.attrs["duration_s"]), "dt_s": float(ds.attrs["dt_s"]),
            "wall_time_s": float(ds.attrs["wall_time_s"]), "method": ds.attrs["method"],
            "window_start_s": stats_window["start_s"], "window_end_s": stats_window["end_s"],
            "window_periods": stats_window["periods"], "window": stats_window["note"],
            "controller": run.controller, "estimator": run.estimator,
            "provenance": {k: ds.attrs.get(k) for k in ("scene_sha256", "hydro_sha256",
                                                        "radiation_sha256")},
            "dofs": dofs, "bodies": bodies, "ptos": ptos, **({"moorings": jsonable(moorings)}
                                                              if moorings else {}),
            **({"mooring_events": jsonable(events)} if events else {}),
            "validity": jsonable(verdict["checks"])}


def _verdict(ds, plant) -> dict:
    """The Dataset's validity verdict: the one in its attrs, else assessed now."""
    if "valid" in ds.attrs:
        return {"valid": bool(ds.attrs["valid"]),
                "invalid_reasons": list(record(ds.attrs, "invalid_reasons", [])),
                "warnings": list(record(ds.attrs, "validity_warnings", [])),
                "checks": copy.deepcopy(record(ds.attrs, "validity", {}))}
    return assess(ds, plant)
