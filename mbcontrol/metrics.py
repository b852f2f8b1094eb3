"""Summaries of simulation results: amplitudes, statistics, PTO power, force and stroke.

Window: for a regular wave, the last 10 wave periods (steady state); for an irregular sea,
the record after the ramp. Amplitude is half the peak-to-peak within the window. Absorbed
power is positive.
"""
from __future__ import annotations

import json

import numpy as np

_BODY_KEYS = {"Surge": "surge_amplitude_m", "Sway": "sway_amplitude_m",
              "Heave": "heave_amplitude_m", "Roll": "roll_amplitude_rad",
              "Pitch": "pitch_amplitude_rad", "Yaw": "yaw_amplitude_rad"}


def analysis_window(ds) -> np.ndarray:
    """Boolean mask over time of the window the metrics use."""
    t = ds["time"].values
    wave = json.loads(ds.attrs.get("wave", "{}"))
    if wave.get("type") == "regular":
        start = t[-1] - 10 * wave["period"]
    else:
        start = wave.get("ramp_s", 0.0)
    mask = t >= start
    if mask.sum() < 2:
        raise ValueError(f"the record ({t[-1]:.4g} s) is too short for the metrics window "
                         f"starting at {start:.4g} s; simulate longer")
    return mask


def signal_stats(values) -> dict:
    return {"amplitude": 0.5 * float(values.max() - values.min()), "mean": float(values.mean()),
            "std": float(values.std()), "max_abs": float(np.abs(values).max())}


def summary(ds, plant) -> dict:
    """The `mbcontrol simulate --json` contract (see README)."""
    mask = analysis_window(ds)
    coords = plant.topology.tree.coordinate_names
    dofs = {name: signal_stats(ds[name].values[mask]) for name in coords}
    bodies = {}
    for body in plant.topology.bodies:
        bodies[body] = {key: 0.5 * float(np.ptp(ds[f"{body}__{dof}"].values[mask]))
                        for dof, key in _BODY_KEYS.items()}
    ptos = {}
    for pto in plant.scene.ptos:
        power = ds[f"{pto.name}__power"].values[mask]
        ptos[pto.name] = {
            "mean_power_W": float(power.mean()),
            "max_force": float(np.abs(ds[f"{pto.name}__force"].values[mask]).max()),
            "max_stroke": float(np.abs(ds[f"{pto.name}__position"].values[mask]).max()),
        }
    return {"model": ds.attrs["model"], "wave": json.loads(ds.attrs["wave"]),
            "duration_s": float(ds.attrs["duration_s"]), "dt_s": float(ds.attrs["dt_s"]),
            "wall_time_s": float(ds.attrs["wall_time_s"]), "method": ds.attrs["method"],
            "dofs": dofs, "bodies": bodies, "ptos": ptos}

