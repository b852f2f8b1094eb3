"""A scene's own BEM results ([hydro] source: a WAMIT .out, a BEMIO .h5 or a Capytaine .nc):
read, checked and repaired by `mbcontrol.hydro.readers`, mapped to the scene's body frames at
its CoGs, and cached like a BEM run, so that a WEC-Sim user's files work as they are.

The cache key is the file's content, the bodies and DOFs taken, their CoGs and the reader's
options: an edited file or a moved CoG converts again; the same ones load in milliseconds.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import xarray as xr

from ..cache import cache_dir, exclusive
from ..console import status
from ..errors import HydroError
from .data.netcdf import read_netcdf, write_netcdf_atomic
from .readers import read_hydro, to_scene_frames


def converted_source(scene) -> tuple[str, xr.Dataset]:
    """(description, body-frame dataset) of the scene's [hydro] source, converted once and
    cached. The dataset's attrs say what was read ("converted_from") and what the readers
    repaired ("notes", "cleaning")."""
    h = scene.hydro
    path = Path(h.source)
    if not path.is_file():
        raise HydroError(f"{scene.path}: [hydro] source {str(path)!r} (relative to the scene's "
                         f"folder): no such file; expected a WAMIT .out, BEMIO .h5 or Capytaine "
                         f".nc file")
    # only the DOFs the scene declares (e.g. heave for sliders): asymmetric or non-passive
    # data in DOFs the scene never moves must not block it
    bodies = list(h.source_bodies) or [b.name for b in scene.bodies if b.hydro]
    dofs = [f"{b}__{d}" for b in bodies for d in h.dofs]
    cogs = {b.name: [float(x) for x in b.cog] for b in scene.bodies if b.hydro}
    key = _key(path, bodies, dofs, cogs, h.source_options)
    cached = cache_dir() / f"source_{key}.nc"
    with exclusive(cached):
        if not cached.exists():
            status(f"reading {path.name} ([hydro] source of {scene.name}): checked, repaired "
                   f"where needed and mapped to the body frames; cached afterwards", __name__)
            data = read_hydro(path, body_names=bodies, dofs=dofs, **h.source_options)
            framed = to_scene_frames(data, {b: np.asarray(c) for b, c in cogs.items()})
            framed.attrs["converted_from"] = path.name
            write_netcdf_atomic(framed, cached)
    return f"{path} ([hydro] source of {scene.path})", read_netcdf(cached)


def _key(path: Path, bodies, dofs, cogs, options) -> str:
    digest = hashlib.sha256(path.read_bytes())
    digest.update(json.dumps([bodies, dofs, cogs, options], sort_keys=True, default=str).encode())
    for module in ("readers", "data"):   # the converting code: a changed reader converts again
        folder = Path(__file__).parent / module
        for file in sorted(folder.glob("*.py")):
            digest.update(file.read_bytes())
    return digest.hexdigest()[:20]
