"""Farms: the power of many coupled devices against as many devices alone (the q-factor).

A farm is a scene whose [parameters] lay out N copies of a device (``array_grid``: n x n floats,
spacing, stagger, Froude scale); the same scene with other parameter values (``n = 1``) is the
device alone. :func:`farm_sweep` runs both over the same seas, seeds and varied quantities
(``--vary direction=0,45`` for headings) on Dask and adds

    q = P_farm / (N_farm / N_alone × P_alone)

per sea state (and varied value): the interaction factor of wave-farm studies (q > 1:
constructive interference, q < 1: the devices shade each other), and the same ratio of the annual
energies. The isolated device is simulated, not assumed: same controller, seas, seeds, duration.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .sweep import sweep


def device_count(model: str, scene_params: dict | None) -> int:
    """The number of PTOs of the scene with these parameters (one per device)."""
    from ..scene import load_scene
    scene = load_scene(model, scene_params or None)
    if not scene.ptos:
        raise InputError(f"{scene.name}: a farm needs a PTO per device; the scene has none")
    return len(scene.ptos)


def farm_sweep(model: str, seas, *, scene_params: dict, isolated: dict, **kwargs):
    """(Dataset, summary) of the farm's sweep with the isolated device's run beside it.

    scene_params : the farm's scene parameters; isolated : the parameters that make the lone
    device out of it (e.g. {"n": 1}), applied on top of scene_params. kwargs : as
    :func:`mbcontrol.studies.sweep.sweep` (seeds, vary, controller, settings, duration, dt,
    workers, store, ...); a store gets an ``isolated`` subfolder. Adds to the Dataset
    ``isolated_mean_power_W`` (one device, W) and ``q_factor``; to the summary ``farm``:
    devices, isolated_devices, isolated_scene_params, q_factor per sea (lists over varied
    values), annual_energy_isolated_MWh (N devices alone) and q_annual, wall_time_s of both."""
    store = kwargs.pop("store", None)
    ds, summary = sweep(model, seas, scene_params=scene_params, store=store, **kwargs)
    alone_params = {**scene_params, **isolated}
    alone, alone_summary = sweep(model, seas, scene_params=alone_params,
                                 store=None if store is None else f"{store}/isolated", **kwargs)
    n_farm, n_alone = device_count(model, scene_params), device_count(model, alone_params)
    per_device = alone["mean_power_W"] / n_alone
    q = ds["mean_power_W"].mean("seed") / (n_farm * per_device.mean("seed"))
    ds["isolated_mean_power_W"] = per_device
    ds["q_factor"] = q
    ds["q_factor"].attrs.update(long_name="farm power / (devices x power of one device alone)")
    rows = [np.asarray(q.isel(sea=k).values, float) for k in range(len(seas))]
    aep_alone = alone_summary["annual_energy_MWh"]
    summary["farm"] = {
        "devices": n_farm, "isolated_devices": n_alone, "isolated_scene_params": alone_params,
        "q_factor": [float(r) if r.ndim == 0 else r.tolist() for r in rows],
        "annual_energy_isolated_MWh": None if aep_alone is None else aep_alone * n_farm / n_alone,
        "q_annual": (None if aep_alone in (None, 0.0) or summary["annual_energy_MWh"] is None
                     else summary["annual_energy_MWh"] / (aep_alone * n_farm / n_alone)),
        "isolated_invalid_cases": alone_summary["invalid_cases"],
        "isolated_wall_time_s": alone_summary["wall_time_s"],
    }
    for row, qk in zip(summary["seas"], summary["farm"]["q_factor"]):
        row["q_factor"] = qk
    summary["wall_time_s"] += alone_summary["wall_time_s"]
    return ds, summary
