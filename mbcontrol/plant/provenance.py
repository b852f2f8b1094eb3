"""What made a plant, as content hashes: the record that makes a result traceable to its
inputs and keys every cache of results (sweep stores) so that changed inputs never serve old
results."""
from __future__ import annotations

import functools
import hashlib
import weakref

import numpy as np

# A cache, not state: a plant's content hashes, computed once per plant object (a plant's
# scene and hydro data do not change) and dropped with it
_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def provenance(plant) -> dict:
    """{"version": the package's, "scene_sha256": the scene's content with its resolved
    parameters and the files it names (`Scene.digest`), "hydro_sha256": the BEM data the
    plant uses, "radiation_sha256": its fitted radiation model, and "masses": {body: how} for
    masses taken from the BEM data (mass = "displaced" without geometry)}; computed once per plant."""
    if plant not in _CACHE:
        hydro = plant.hydro
        _CACHE[plant] = {
            "version": _version(),
            "scene_sha256": plant.scene.digest(),
            "hydro_sha256": _dataset_digest(hydro.data) if hydro is not None else None,
            "radiation_sha256": _arrays_digest(hydro.radiation.A, hydro.radiation.B,
                                               hydro.radiation.C, hydro.radiation.D)
            if hydro is not None else None,
        }
        masses = {b.name: f"{b.mass:.8g} kg, {b.mass_from}" for b in plant.scene.bodies if b.mass_from}
        if masses:      # mass = "displaced": taken from the BEM data when they were read
            _CACHE[plant]["masses"] = masses
    return dict(_CACHE[plant])


@functools.cache
def _version() -> str:
    from importlib import metadata
    try:
        return metadata.version("mbcontrol")
    except metadata.PackageNotFoundError:          # run from a source tree, not installed
        return "unknown"


def _dataset_digest(data) -> str:
    """sha256 over an xarray Dataset's variables and coordinates, names and values."""
    h = hashlib.sha256()
    for name in sorted(map(str, data.variables)):
        values = np.asarray(data[name].values)
        h.update(name.encode())
        h.update(str(values.dtype).encode() + str(values.shape).encode())
        h.update(values.tobytes() if values.dtype != object else str(values.tolist()).encode())
    return h.hexdigest()


def _arrays_digest(*arrays) -> str:
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(np.asarray(a, float))
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    return h.hexdigest()
