"""Readers of hydrodynamic data from other BEM codes: WAMIT ``.out``, BEMIO ``.h5``, Capytaine ``.nc``.

Every reader returns the same DATA-FRAME dataset, the layout :func:`mbcontrol.hydro.compute`
assembles before mapping to body frames:

- SI units, time convention e^{-iωt} (Capytaine's), z-up data frame (x forward, y port, origin
  on the undisturbed free surface); wave_direction in that frame (rad, +x towards +y);
- coords ``omega`` (rad/s, ascending, finite, > 0), ``radiating_dof``/``influenced_dof``
  (``<body>__<Surge|Sway|Heave|Roll|Pitch|Yaw>``), ``wave_direction``, ``body``, ``xyz``;
- ``added_mass``, ``radiation_damping`` (omega, radiating_dof, influenced_dof);
  ``added_mass_zero``, ``added_mass_inf`` (NaN when the file lacks them; see attrs notes),
  ``hydrostatic_stiffness`` (radiating_dof, influenced_dof), as stored about the file's
  reference point; matrix_layout: X[radiating_dof, influenced_dof], force_i = -Σ_j X[j, i] motion_j;
- ``excitation_force`` (+ ``froude_krylov_force``/``diffraction_force`` when the file has them)
  (wave_direction, omega, influenced_dof), complex, per m of wave amplitude;
- ``displaced_volume`` (body), ``center_of_buoyancy``, ``reference_point``, ``cog`` (when known)
  (body, xyz) in the data frame; ``waterplane_area`` (body) when the file gives it;
- attrs: rho, g, depth (inf for deep water), source "<format> <path>", time_convention,
  notes (every conversion and repair), cleaning (what :func:`clean` changed).

:func:`to_scene_frames` then maps such a dataset to NED body frames at the scene's CoGs.

Every reader ends with :func:`clean`; its options (``force_symmetric``, ``negative_damping``,
``dofs``, ``omega_range``, tolerances) pass through the readers' keyword arguments. Measured on
the reference files (../shared/data): sphere.out reads as is (asymmetry 6e-5; its heave damping
is slightly negative above 11.5 rad/s and set to 0, with a warning). wavestar.h5 is reciprocal
to 5e-5 up to 10 rad/s but not above 15 rad/s (0.16 % in A at 23.4 rad/s) and has irregular-
frequency spikes above 30 rad/s: read it with ``omega_range=(0, 10)`` or ``force_symmetric=True``.
rm3.out is not reciprocal (2 % in A, 24 % in B between float and spar roll/pitch; 0.4 % in the
heave pair) and its symmetrised B is indefinite over 0.6-2.7 rad/s: ``force_symmetric=True,
negative_damping="project"`` for all 12 DOFs, or ``dofs=[<float>__Heave, <spar>__Heave],
force_symmetric=True`` for heave only.
"""
from __future__ import annotations

from importlib import import_module
from pathlib import Path

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError
from mbcontrol.hydro.data.frames import to_body_frames, zup_to_ned

from ...lazy import face

# the readers load on first use: a plant built from stored data needs only the physical checks
_WHERE = {"read_wamit": ("wamit", "read_wamit"), "read_bemio": ("bemio", "read_bemio"),
          "read_capytaine": ("capytaine_nc", "read_capytaine"), "clean": ("checks", "clean"),
          "HydroCleaningWarning": ("checks", "HydroCleaningWarning")}

__all__ = ["read_wamit", "read_bemio", "read_capytaine", "read_hydro", "clean", "to_scene_frames",
           "HydroCleaningWarning"]

_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


def _sniff(path: Path) -> str:
    """'wamit', 'bemio' or 'capytaine' from the file's content."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8192)
    except OSError as exc:
        raise HydroError(f"{path}: unreadable ({type(exc).__name__}: {exc})") from exc
    if head.startswith(b"CDF"):
        return "capytaine"
    if head.startswith(_HDF5_MAGIC):
        import h5py
        try:
            with h5py.File(path, "r") as f:
                return "bemio" if "body1" in f else "capytaine"
        except Exception as exc:
            raise HydroError(f"{path}: unreadable HDF5 file ({type(exc).__name__}: {exc})") from exc
    if b"WAMIT" in head or b"Wave period" in head:
        return "wamit"
    raise HydroError(f"{path}: unknown hydrodynamic data format; expected a WAMIT .out, a BEMIO .h5 "
                     "or a Capytaine/mbcontrol .nc file")


def read_hydro(path, **kw) -> xr.Dataset:
    """Read any supported file: ``.out`` -> WAMIT, ``.h5``/``.hdf5`` -> BEMIO, ``.nc`` -> Capytaine or
    mbcontrol; other extensions are recognised by content. ``kw`` go to the reader (and to clean)."""
    path = Path(path)
    if not path.is_file():
        raise HydroError(f"{path}: no such file (expected hydrodynamic data: WAMIT .out, BEMIO .h5, Capytaine .nc)")
    ext = path.suffix.lower()
    kind = {".out": "wamit", ".h5": "bemio", ".hdf5": "bemio", ".nc": "capytaine"}.get(ext) or _sniff(path)
    module, name = _WHERE[{"wamit": "read_wamit", "bemio": "read_bemio", "capytaine": "read_capytaine"}[kind]]
    return getattr(import_module(f"{__name__}.{module}"), name)(path, **kw)


def to_scene_frames(ds_data: xr.Dataset, cogs_ned: dict) -> xr.Dataset:
    """Map a reader's data-frame dataset to NED body frames at the scene's CoGs.

    ``cogs_ned`` : body name -> CoG in the n-frame (NED), m. The reference points come from
    ``ds_data["reference_point"]`` (z up, converted to NED as (x, -y, -z)); then
    :func:`mbcontrol.hydro.to_body_frames` applies ERRATA G10-G13. In the result ``cog`` holds
    the CoGs used (NED) and ``reference_point`` the data's reference points in NED; a CoG given
    by the file is kept as ``source_cog`` (NED).
    """
    if "reference_point" not in ds_data:
        raise HydroError(f"{ds_data.attrs.get('source', 'dataset')}: no 'reference_point'; "
                         "expected the data-frame dataset of a reader")
    bodies = [str(b) for b in ds_data["body"].values]
    missing = [b for b in bodies if b not in cogs_ned]
    if missing:
        raise HydroError(f"{ds_data.attrs.get('source', 'dataset')}: no CoG given for bod(y/ies) {missing} "
                         f"(cogs_ned has {sorted(cogs_ned)}); expected one per body of the data")
    refs_zup = ds_data["reference_point"].transpose("body", "xyz").values
    refs = {b: zup_to_ned(refs_zup[k]) for k, b in enumerate(bodies)}
    cogs = {b: np.asarray(cogs_ned[b], dtype=float).reshape(3) for b in bodies}
    out = to_body_frames(ds_data, refs, cogs, z_up=True)
    out["reference_point"] = (("body", "xyz"), np.array([refs[b] for b in bodies]))
    out["reference_point"].attrs["units"] = "m (n-frame, NED)"
    if "cog" in ds_data:
        out["source_cog"] = (("body", "xyz"), zup_to_ned(ds_data["cog"].transpose("body", "xyz").values))
        out["source_cog"].attrs["units"] = "m (n-frame, NED); the CoG stated in the file"
    out["cog"] = (("body", "xyz"), np.array([cogs[b] for b in bodies]))
    out["cog"].attrs["units"] = "m (n-frame, NED)"
    out["center_of_buoyancy"].attrs["units"] = "m (n-frame, NED)"
    out["wave_direction"].attrs.update(units="rad", long_name="NED heading waves travel to, +x towards +y (starboard)")
    return out


__getattr__, __dir__ = face(__name__, globals(), _WHERE)
