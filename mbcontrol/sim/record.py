"""The Dataset a run is recorded in (`run_dataset`): every output, the inputs u, the excitation
w, the wave elevation and the states over time, with the run record (mbcontrol.results.RunInfo)
and provenance in attrs as Python values (JSON only in files: mbcontrol.results)."""
from __future__ import annotations

import copy
import platform
from importlib import metadata

import numpy as np
import xarray as xr

from ..plant import provenance


def run_dataset(plant, t, X, U, W, Y, eta, *, wave, controller, method, dt, p, wall) -> xr.Dataset:
    """The record of a run over time t (s): outputs Y, inputs U, excitation W (each (n, k)),
    states X (n, nx; None: not recorded, as a direct-convolution run), elevation eta (m); the
    wave, controller, method, step dt (s), parameter vector p and wall time (s) in attrs."""
    data = {}
    # the wave field's rows (nonlinear Froude-Krylov) are the plant's internals, not results
    excitation = plant.disturbances[:len(plant.disturbances) - plant.wave_rows]
    for names, values in ((plant.outputs, Y), (plant.inputs, U), (excitation, W)):
        data.update({name: ("time", values[:, i], {"units": plant.units(name)})
                     for i, name in enumerate(names)})
    data["eta"] = ("time", eta, {"units": "m", "long_name": "wave elevation at the origin, up"})
    states = list(plant.states) if X is not None else []
    data["state"] = (("time", "state_name"), X if X is not None else np.zeros((t.size, 0)))
    if wave is not None:        # the wave itself, so the result can be checked against its bound
        data.update({f"wave_{name}": ("wave_component", np.asarray(getattr(wave, name), float),
                                      {"units": unit})
                     for name, unit in (("omega", "rad/s"), ("amplitude", "m"), ("phase", "rad"))})
        if wave.d_omega:
            data["wave_omega"][2]["d_omega"] = float(wave.d_omega)
        if wave.directional:    # a spread sea: each component's own direction
            data["wave_direction"] = ("wave_component", np.asarray(wave.direction, float),
                                      {"units": "rad", "long_name": "direction (NED)"})
    ds = xr.Dataset(data, coords={"time": ("time", t, {"units": "s"}),
                                  "state_name": states})
    made_by = provenance(plant)
    ds.attrs.update({
        "model": plant.name, "scene_sha256": made_by["scene_sha256"],
        "hydro_sha256": made_by["hydro_sha256"] or "none",
        "radiation_sha256": made_by["radiation_sha256"] or "none",
        "method": method, "dt_s": dt,
        "duration_s": float(t[-1]), "wall_time_s": wall,
        # the run record (mbcontrol.results.RunInfo): Python values here, JSON only in files
        # (copies: the describe() dicts may share a controller's own lists, which its next
        # reset changes)
        "wave": copy.deepcopy(wave.describe()) if wave is not None else {"type": "none"},
        "controller": copy.deepcopy(controller.describe()) if controller is not None else None,
        "parameters": dict(zip(plant.parameters, map(float, p))),
        "hydro_source": plant.hydro.source if plant.hydro else "none",
        "radiation_states": int(plant.hydro.radiation.A.shape[0]) if plant.hydro else 0,
        "conventions": "NED n-frame (z down); body DOFs are CoG displacements (m) and ZYX "
                       "Euler angles (rad); absorbed power positive",
        "versions": _versions(),
    })
    return ds


_VERSIONS: dict = {}


def _versions() -> dict:
    """Python's and the packages' versions: looked up once per process (the package metadata
    lookups cost ~2-4 ms, every run otherwise); a copy, so callers may change it."""
    if not _VERSIONS:
        _VERSIONS["python"] = platform.python_version()
        for pkg in ("mbcontrol", "casadi", "numpy", "control", "capytaine"):
            try:
                _VERSIONS[pkg] = metadata.version(pkg)
            except metadata.PackageNotFoundError:
                pass
    return dict(_VERSIONS)
