"""The radiation fits' store: each fit on disk under a name made of what it depends on (the
data, the DOFs, the tolerance, the bands, the method, the fitting code and, for a fit judged by
a device's response, the device), shipped with the catalogue (models/radiation_fits, made by
models/generate_hydro.py --ship-fits) or cached; a fit made for another device is reused when it
meets the tolerance in this one."""
from __future__ import annotations

import dataclasses
import hashlib
import json
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from ... import defaults
from ...atomic import atomic_path
from ...cache import UNREADABLE, ServedLog, cache_dir, read_entry, reason_of
from ...console import status
from ...errors import HydroError
from . import (array_fit, array_passivity, fit_error, group_fit, kernel, passive_order, passivity, radiation,
               response_error, sdp, vector_fit)
from .radiation import RadiationModel, fit_radiation
from .response_error import Device


def fit_band_limit(data: xr.Dataset, scene_limit: float = np.inf) -> float | None:
    """Highest frequency the radiation fit uses: the scene's fit_omega_max, and for our own
    BEM runs no higher than where the mesh is still resolved.

    Above `omega_max_mesh` (fewer than 8 panels per wavelength) panel-method damping loses
    accuracy and even passivity; third-party files carry irregular-frequency spikes the scene
    can exclude. Fitting either would spend states on numerical artefacts.
    """
    limit = min(float(data.attrs.get("omega_max_mesh", np.inf)), float(scene_limit))
    return limit if np.isfinite(limit) else None


_FITS_SERVED = ServedLog("fits_served")


def recording_served_fits():
    """`with recording_served_fits() as names:` the radiation fit files asked for while it is
    active, in order (models/generate_hydro.py --ship-fits); off otherwise."""
    return _FITS_SERVED.recording()


def cached_fit(data: xr.Dataset, dofs, tol, source: str, omega_max: float = np.inf, response_band=None,
                method: str = "coupled", device: Device | None = None):
    """fit_radiation (``method`` "coupled", judged by ``device``'s response when given) or
    fit_radiation_columns ("columns": the kernel's own error) with an on-disk cache keyed by the
    data, the DOFs, the tolerance, the bands, the method and the device."""
    if method not in ("coupled", "columns"):
        raise HydroError(f"radiation fit method {method!r}: expected 'coupled' or 'columns'")
    tol = defaults.get("hydro.radiation_tol") if tol is None else tol
    digest = hashlib.sha256()
    for var in ("added_mass", "radiation_damping", "added_mass_inf"):
        digest.update(np.ascontiguousarray(data[var].values).tobytes())
    # the fitting code is part of the key: a changed algorithm never serves an old fit
    for module in (radiation, kernel, fit_error, vector_fit, group_fit, passive_order, passivity, sdp,
                   response_error):
        digest.update(Path(module.__file__).read_bytes())
    band = fit_band_limit(data, omega_max)
    response_band = None if response_band is None else [float(x) for x in response_band]
    digest.update(json.dumps([list(dofs), tol, band] + ([response_band] if response_band else [])).encode())
    device = device if method == "coupled" else None
    if method == "columns":
        for module in (array_fit, array_passivity):
            digest.update(b"columns" + Path(module.__file__).read_bytes())
    base = digest.hexdigest()
    # judged by a device: the data's part of the name, then the device's
    name = (f"radiation_{base[:20]}.npz" if device is None else
            f"radiation_{base[:16]}_{hashlib.sha256(json.dumps(device.key()).encode()).hexdigest()[:12]}.npz")
    path = cache_dir() / name
    _FITS_SERVED.note(name)
    model = _load_fit(name) or (_reused_fit(base[:16], data, band, tol, device) if device is not None else None)
    if model is not None:
        if not path.exists() and not (shipped_fits_dir() / name).exists():
            _save_fit(path, model)             # a reused fit, under this device's name from now on
        return model
    started = time.perf_counter()
    # a label "FILE ([hydro] source of SCENE)" names the file; a plain path, its name
    label = Path(source.split(" (")[0]).name if isinstance(source, str) else source
    status(f"fitting the radiation model of {label} ({len(dofs)} DOFs, tolerance "
           f"{tol:g}, {method}): typically 5-90 s, once; cached afterwards", __name__)
    judged = {"device": device} if device is not None else {}
    fitter = fit_radiation if method == "coupled" else array_fit.fit_radiation_columns
    model = fitter(data, dofs=list(dofs), tol=tol, omega_max=band, response_band=response_band, **judged)
    status(f"radiation model fitted in {time.perf_counter() - started:.1f} s: "
           f"{model.order} states, error {model.fit_error:.2%}", __name__)
    _save_fit(path, model)
    return model


def _load_fit(name: str) -> RadiationModel | None:
    """The fit called ``name``, shipped (models/radiation_fits, made by generate_hydro.py) or
    cached; None if neither has it. An unreadable cache file (truncated, foreign) is moved
    aside with a warning (mbcontrol.cache.read_entry) so that the fit is made again."""
    shipped = shipped_fits_dir() / name
    if shipped.exists():
        try:
            return _read_fit(shipped)
        except (UNREADABLE + (HydroError,)) as exc:     # in the package: not ours to move
            raise HydroError(f"{shipped}: shipped radiation fit unreadable ({reason_of(exc)}); "
                             f"reinstall mbcontrol") from exc
    return read_entry(cache_dir() / name, _read_fit, what="radiation fit cache entry")


def _read_fit(path: Path, quiet: bool = False) -> RadiationModel:
    with np.load(path, allow_pickle=False) as z:
        return model_from_arrays(z, quiet=quiet)


def _reused_fit(base: str, data, band, tol: float, device: Device) -> RadiationModel | None:
    """A fit of the same data, DOFs, tolerance and code, made for another device (a drivetrain or
    a spring changed, a DOF frozen), that meets ``tol`` in this one: it is as good a fit here as a
    new one, and takes milliseconds instead of a refit. Its report is this device's; the first
    found that passes is used, shipped ones first (an unreadable cached one is moved aside)."""
    for folder in (shipped_fits_dir(), cache_dir()):
        for candidate in sorted(folder.glob(f"radiation_{base}_*.npz")):
            if folder == cache_dir():
                model = read_entry(candidate, lambda p: _read_fit(p, quiet=True),
                                   what="radiation fit cache entry", then="not using it")
            else:
                try:
                    model = _read_fit(candidate, quiet=True)
                except UNREADABLE:
                    model = None
            if model is None:
                continue
            worst = response_error.response_error_on(device, data, model, band)
            if worst["error"] <= tol:
                report = dict(model.report, fit_error=worst["error"], response_error=worst["error"],
                              response_worst=worst, tol_met=True, made_for_another_device=candidate.name)
                return dataclasses.replace(model, fit_error=worst["error"], report=report)
    return None


def _save_fit(path: Path, model: RadiationModel) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, A=model.A, B=model.B, C=model.C, D=model.D, dofs=np.array(model.dofs),
                 order=model.order, fit_error=model.fit_error, entry_errors=model.entry_errors,
                 report=json.dumps(model.report, default=_jsonable))


def shipped_fits_dir() -> Path:
    """The radiation fits shipped with the catalogue (models/radiation_fits), keyed as the
    cache is: by the data, the DOFs, the tolerance, the band and the fitting code itself, so a
    shipped fit serves exactly the fit it replaces and a stale one is never found."""
    from importlib.resources import files
    try:
        return Path(str(files("mbcontrol.models"))) / "radiation_fits"
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[3] / "models" / "radiation_fits"   # the repository's


def model_from_arrays(z, quiet: bool = False) -> RadiationModel:
    model = RadiationModel(A=z["A"], B=z["B"], C=z["C"], D=z["D"],
                           dofs=tuple(str(d) for d in z["dofs"]), order=int(z["order"]),
                           fit_error=float(z["fit_error"]), entry_errors=z["entry_errors"],
                           report=json.loads(str(z["report"])))
    if not quiet and model.report.get("tol_met") is False and "limited_by" in model.report:  # as loud as a fresh fit
        warnings.warn(radiation.RadiationFitWarning(radiation.miss_message(model.report)), stacklevel=4)
    return model


def _jsonable(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist() if obj.dtype.kind != "c" else [obj.real.tolist(), obj.imag.tolist()]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, complex):
        return [obj.real, obj.imag]
    return str(obj)
