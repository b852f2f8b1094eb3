"""A scene's own BEM results ([hydro] source: a WAMIT .out, a BEMIO .h5 or a Capytaine .nc):
read, checked and repaired by `mbcontrol.hydro.readers`, mapped to the scene's body frames at
its CoGs, and cached like a BEM run, so that a WEC-Sim user's files work as they are.

Which BEM body is which scene body: ``[hydro] source_bodies`` names them in file order; without
it each BEM body is matched by position (its CoG in the file, else its reference point, against
the scene's CoGs): the one scene body within MATCH_RADIUS of it. Two candidates, none, or two
BEM bodies on one scene body are refused with the distances; the mapping is said (console
status) and kept in the data's notes, which ``mbcontrol hydro SCENE`` prints.

The cache key is the file's content, the bodies and DOFs taken, their CoGs and the reader's
options: an edited file or a moved CoG converts again; the same ones load in milliseconds.
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import xarray as xr

from ..cache import cache_dir, exclusive
from ..console import status
from ..errors import HydroError
from .data.frames import zup_to_ned
from .data.netcdf import read_netcdf, write_netcdf_atomic
from .readers import read_hydro, to_scene_frames

# A BEM body matches a scene body whose CoG lies within MATCH_RADIUS x V^(1/3) of its point
# (V its displaced volume; 0.5: half the body's size, far less than the spacing of two bodies
# that cannot overlap; the shipped files place their bodies exactly at the scene CoGs, 0 m).
MATCH_RADIUS = 0.5
MATCH_FLOOR = 0.05      # m: the radius of a body without displaced volume (a fixed, dry part)


def _check_frame(scene, path, framed) -> None:
    """A scene written z-up (WEC-Sim's convention) rather than NED is refused: the file states
    each body's CoG, and a scene CoG that is its mirror in z (|z| more than FRAME_TOL apart from
    it, within FRAME_TOL of -z) is that CoG written z-up."""
    from ..errors import SceneError
    if "source_cog" not in framed:
        return
    for body in framed["body"].values:
        stated = float(framed["source_cog"].sel(body=body).values[2])
        given = float(framed["cog"].sel(body=body).values[2])
        tol = max(FRAME_TOL_M, FRAME_TOL * abs(stated))
        if abs(stated) > tol and abs(given + stated) <= tol < abs(given - stated):
            raise SceneError(
                f"{scene.path}: body '{body}': cog z = {given:g} m, but {path.name} states its "
                f"CoG at z = {stated:g} m in mbcontrol's frame ({-stated:g} m z-up, as the file "
                f"writes it): the scene looks written z-up, as WEC-Sim's input files are. "
                f"mbcontrol scenes are NED (x forward, y to starboard, z down, origin on the "
                f"still water): write every point with y and z negated (a CoG 0.72 m below "
                f"the water is z = 0.72)")


# a scene CoG mirrored in z from the file's own, within 1 cm or 5 %: written z-up
FRAME_TOL_M, FRAME_TOL = 0.01, 0.05


def converted_source(scene) -> tuple[str, xr.Dataset]:
    """(description, body-frame dataset) of the scene's [hydro] source, converted once and
    cached. The dataset's attrs say what was read ("converted_from"), what the readers
    repaired ("notes", "cleaning") and how the bodies were matched ("body_mapping")."""
    h = scene.hydro
    path = Path(h.source)
    if not path.is_file():
        raise HydroError(f"{scene.path}: [hydro] source {str(path)!r} (relative to the scene's "
                         f"folder): no such file; expected a WAMIT .out, BEMIO .h5 or Capytaine "
                         f".nc file")
    named = list(h.source_bodies)
    cogs = {b.name: [float(x) for x in b.cog] for b in scene.bodies if b.hydro}
    key = _key(path, named or ["<by position>"], list(h.dofs), cogs, h.source_options)
    cached = cache_dir() / f"source_{key}.nc"
    with exclusive(cached):
        if not cached.exists():
            status(f"reading {path.name} ([hydro] source of {scene.name}): checked, repaired "
                   f"where needed and mapped to the body frames; cached afterwards", __name__)
            # only the DOFs the scene declares (e.g. heave for sliders): asymmetric or non-passive
            # data in DOFs the scene never moves must not block it
            # defects above the radiation fit's band are repaired with a warning, not refused
            options = {**({"band_max": h.fit_omega_max} if math.isfinite(h.fit_omega_max) else {}),
                       **h.source_options}
            if named:
                data = read_hydro(path, body_names=named, dofs=[f"{b}__{d}" for b in named for d in h.dofs],
                                  **options)
                mapping = {b: {"scene_body": b, "by": "[hydro] source_bodies"} for b in named}
            else:
                mapping = {}
                data = _renamed(read_hydro(path, dofs=_by_position(scene, mapping), **options),
                                mapping)
                data.attrs["notes"] = list(data.attrs["notes"]) + [_mapping_text(mapping)]
            framed = to_scene_frames(data, {b: np.asarray(c) for b, c in cogs.items()})
            _check_frame(scene, path, framed)
            framed.attrs["converted_from"] = path.name
            framed.attrs["body_mapping"] = json.dumps(mapping)
            write_netcdf_atomic(framed, cached)
    data = read_netcdf(cached)
    if not named:      # said at every load: the user did not choose it
        status(f"{scene.name}: {_mapping_text(json.loads(data.attrs['body_mapping']))}", __name__)
    return f"{path} ([hydro] source of {scene.path})", data


def _by_position(scene, mapping: dict):
    """The reader's DOF selector: matches the file's bodies to the scene's hydro bodies by
    position (module docs), fills ``mapping`` (file body -> scene body, distance) and keeps the
    scene's [hydro] dofs of every matched body."""
    def select(ds) -> list[str]:
        points = ds["cog"] if "cog" in ds and np.all(np.isfinite(ds["cog"].values)) else ds["reference_point"]
        which = "CoG" if points.name == "cog" else "reference point"
        cogs = {b.name: np.asarray(b.cog, float) for b in scene.bodies if b.hydro}
        claimed: dict[str, str] = {}
        for body in [str(b) for b in ds["body"].values]:
            point = zup_to_ned(points.sel(body=body).transpose("xyz").values)   # data frame -> NED
            volume = float(ds["displaced_volume"].sel(body=body)) if "displaced_volume" in ds else 0.0
            radius = max(MATCH_RADIUS * abs(volume) ** (1 / 3), MATCH_FLOOR)
            dist = {name: float(np.linalg.norm(point - c)) for name, c in cogs.items()}
            near = [name for name, d in sorted(dist.items(), key=lambda kv: kv[1]) if d <= radius]
            listing = ", ".join(f"{n!r} {d:.3g} m" for n, d in sorted(dist.items(), key=lambda kv: kv[1]))
            where = (f"BEM body {body!r} of {Path(scene.hydro.source).name} ({which} at NED "
                     f"{np.round(point, 4).tolist()} m)")
            if len(near) != 1:
                problem = ("is farther than" if not near else "has more than one scene body within")
                mirrored = [n for n, c in cogs.items()
                            if np.linalg.norm(point - c * np.array([1.0, -1.0, -1.0])) <= radius]
                hint = (f"; scene body {mirrored[0]!r} with y and z negated lies within it: the scene "
                        f"looks written z-up, as WEC-Sim's input files are, and mbcontrol scenes are "
                        f"NED (z down)" if not near and mirrored else "")
                raise HydroError(
                    f"{scene.path}: [hydro] source_bodies is not given and {where} {problem} {radius:.3g} m "
                    f"(half its size, V^(1/3)/2) of a scene body's CoG; candidates: {listing}{hint}. Name "
                    f"the scene body of each BEM body, in file order: [hydro] source_bodies = [...]")
            if near[0] in claimed:
                raise HydroError(
                    f"{scene.path}: [hydro] source_bodies is not given and BEM bodies {claimed[near[0]]!r} "
                    f"and {body!r} both lie nearest scene body {near[0]!r}; name the scene body of each "
                    f"BEM body, in file order: [hydro] source_bodies = [...]")
            claimed[near[0]] = body
            mapping[body] = {"scene_body": near[0], "by": f"position ({which})", "distance_m": dist[near[0]]}
        unmatched = [name for name in cogs if name not in claimed]
        if unmatched:
            raise HydroError(
                f"{scene.path}: [hydro] source_bodies is not given and the hydro bodies {unmatched} of the "
                f"scene have no BEM body of {Path(scene.hydro.source).name} near their CoG (the file has "
                f"{list(mapping)}); give [hydro] source_bodies, or set hydro = false on dry bodies")
        return [f"{body}__{d}" for body in mapping for d in scene.hydro.dofs]
    return select


def _renamed(ds: xr.Dataset, mapping: dict) -> xr.Dataset:
    """The file's body names replaced by the scene's, in bodies and DOF names at once."""
    to = {b: m["scene_body"] for b, m in mapping.items()}
    dof = lambda d: f"{to[str(d).split('__')[0]]}__{str(d).split('__')[1]}"  # noqa: E731
    return ds.assign_coords(body=[to[str(b)] for b in ds["body"].values],
                            radiating_dof=[dof(d) for d in ds["radiating_dof"].values],
                            influenced_dof=[dof(d) for d in ds["influenced_dof"].values])


def _mapping_text(mapping: dict) -> str:
    pairs = ", ".join(f"{b!r} -> {m['scene_body']!r} ({m['distance_m']:.3g} m)" for b, m in mapping.items())
    return (f"BEM bodies matched to scene bodies by {next(iter(mapping.values()))['by']}, as "
            f"[hydro] source_bodies is not given (name them there to choose): {pairs}")


def _key(path: Path, bodies, dofs, cogs, options) -> str:
    digest = hashlib.sha256(path.read_bytes())
    digest.update(json.dumps([bodies, dofs, cogs, options], sort_keys=True, default=str).encode())
    for module in ("readers", "data"):   # the converting code: a changed reader converts again
        folder = Path(__file__).parent / module
        for file in sorted(folder.glob("*.py")):
            digest.update(file.read_bytes())
    digest.update(Path(__file__).read_bytes())   # and this module's mapping
    return digest.hexdigest()[:20]
