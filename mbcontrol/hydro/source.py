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
_SAID: set = set()      # (scene, conversion) whose mapping this process has said


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
                f"Add frame = \"z-up\" at the top of the scene (converted to NED on load), or "
                f"write it in mbcontrol's NED (x forward, y to starboard, z down, origin on the "
                f"still water): every point with y and z negated (a CoG 0.72 m below the water "
                f"is z = 0.72)")


# a scene CoG mirrored in z from the file's own, within 1 cm or 5 %: written z-up
FRAME_TOL_M, FRAME_TOL = 0.01, 0.05


def converted_source(scene, dofs=None) -> tuple[str, xr.Dataset]:
    """(description, body-frame dataset) of the scene's [hydro] source, converted once and
    cached. ``dofs``: the body DOFs wanted ("<scene body>__<Dof>", e.g. those the joints move,
    mbcontrol.plant.active_hydro_dofs); None: the scene's [hydro] dofs of every hydro body. Data
    of DOFs the scene never moves are not read: their defects (asymmetry, negative damping)
    cannot block it. The dataset's attrs say what was read ("converted_from"), what the readers
    repaired ("notes", "cleaning"), how the bodies were matched ("body_mapping") and each scene
    body's displaced volume in the file ("displaced_volumes": {body: [m^3, file body]})."""
    h = scene.hydro
    path = Path(h.source)
    if not path.is_file():
        raise HydroError(f"{scene.path}: [hydro] source {str(path)!r} (relative to the scene's "
                         f"folder): no such file; expected a WAMIT .out, BEMIO .h5 or Capytaine "
                         f".nc file")
    named = list(h.source_bodies)
    cogs = {b.name: [float(x) for x in b.cog] for b in scene.bodies if b.hydro}
    wanted = sorted(f"{b}__{d}" for b in cogs for d in h.dofs if dofs is None or f"{b}__{d}" in dofs)
    key = _key(path, named or ["<by position>"], wanted, cogs, h.source_options)
    cached = cache_dir() / f"source_{key}.nc"
    with exclusive(cached):
        if not cached.exists():
            status(f"reading {path.name} ([hydro] source of {scene.name}): checked, repaired "
                   f"where needed and mapped to the body frames; cached afterwards", __name__)
            write_netcdf_atomic(_converted(scene, path, named, wanted, cogs), cached)
    data = read_netcdf(cached)
    if not named and (scene.path, key) not in _SAID:   # said once a run: the user did not choose it
        _SAID.add((scene.path, key))
        status(f"{scene.name}: {_mapping_text(json.loads(data.attrs['body_mapping']))}", __name__)
    return f"{path} ([hydro] source of {scene.path})", data


def _converted(scene, path: Path, named: list, wanted: list, cogs: dict) -> xr.Dataset:
    """The source read (only the ``wanted`` DOFs), its bodies mapped to the scene's (by name or
    position) and to body frames at the scene's CoGs, checked for a z-up scene."""
    h = scene.hydro
    # defects above the radiation fit's band are repaired with a warning, not refused
    options = {**({"band_max": h.fit_omega_max} if math.isfinite(h.fit_omega_max) else {}),
               **h.source_options}
    mapping, volumes = {}, {}
    if named:
        def select(ds):
            _volumes(ds, {b: b for b in named}, volumes)
            return [d for d in wanted if d.split("__")[0] in named]
        data = read_hydro(path, body_names=named, dofs=select, **options)
        mapping.update({b: {"scene_body": b, "by": "[hydro] source_bodies"} for b in named})
    else:
        data = _renamed(read_hydro(path, dofs=_by_position(scene, mapping, wanted, volumes), **options),
                        mapping)
        data.attrs["notes"] = list(data.attrs["notes"]) + [_mapping_text(mapping)]
    framed = to_scene_frames(data, {b: np.asarray(c) for b, c in cogs.items()
                                    if b in set(str(x) for x in data["body"].values)})
    _check_frame(scene, path, framed)
    framed.attrs["converted_from"] = path.name
    framed.attrs["body_mapping"] = json.dumps(mapping)
    framed.attrs["displaced_volumes"] = json.dumps(volumes)
    return framed


def _volumes(ds, to_scene: dict, volumes: dict) -> None:
    """Fill ``volumes`` (scene body -> [displaced volume m^3, file body]) from a reader's dataset
    before its DOFs are selected: a body the joints hold still still gets its mass."""
    if "displaced_volume" not in ds:
        return
    for body in [str(b) for b in ds["body"].values]:
        if body in to_scene:
            volumes[to_scene[body]] = [float(ds["displaced_volume"].sel(body=body)), body]


def _by_position(scene, mapping: dict, wanted: list, volumes: dict):
    """The reader's DOF selector: matches the file's bodies to the scene's hydro bodies by
    position (module docs), fills ``mapping`` (file body -> scene body, distance) and
    ``volumes`` (module _volumes), and keeps the ``wanted`` DOFs (scene names) of the matches."""
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
                        f"NED (z down): add frame = \"z-up\" to the scene" if not near and mirrored else "")
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
        _volumes(ds, {body: m["scene_body"] for body, m in mapping.items()}, volumes)
        return [f"{body}__{d.split('__')[1]}" for body, m in mapping.items() for d in wanted
                if d.split("__")[0] == m["scene_body"]]
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


def with_displaced_masses(scene, dofs=None):
    """The scene with each ``mass = "displaced"`` body that has no geometry given rho x the
    displaced volume its BEM body has in the scene's data ([hydro] file when it exists, as
    load_hydro_data reads it, else [hydro] source, matched as module docs say); the scene itself
    when there is none. Each resolved mass is said once (console status) and kept in the body's
    ``mass_from`` (volume, rho, file, BEM body), which enters the scene's digest and the plant's
    provenance. ``dofs``: as converted_source takes them."""
    import dataclasses
    from ..errors import SceneError
    from ..scene import DISPLACED_PENDING
    pending = [b.name for b in scene.bodies if b.mass_from == DISPLACED_PENDING]
    if not pending:
        return scene
    h = scene.hydro
    if h.file and Path(h.file).is_file():
        data, name = read_netcdf(h.file), Path(h.file).name
        volumes = {str(b): [float(data["displaced_volume"].sel(body=b)), str(b)]
                   for b in data["body"].values} if "displaced_volume" in data else {}
    else:
        _, data = converted_source(scene, dofs)
        name, volumes = Path(h.source).name, json.loads(data.attrs.get("displaced_volumes", "{}"))
    rho, bodies = scene.water.rho, []
    for body in scene.bodies:
        if body.name in pending:
            if body.name not in volumes or not volumes[body.name][0] > 0:
                raise SceneError(
                    f"{scene.path}: body '{body.name}': mass = \"displaced\", but {name} states no "
                    f"displaced volume > 0 for it (got {volumes.get(body.name, ['none'])[0]}); "
                    f"expected a floating or submerged BEM body, or give the mass in kg")
            volume, of = volumes[body.name]
            how = (f"displaced: rho {rho:g} kg/m^3 x {volume:.7g} m^3, the displaced volume of BEM "
                   f"body {of!r} in {name}")
            status(f"{scene.name}: body '{body.name}' mass = {rho * volume:.8g} kg ({how})", __name__)
            body = dataclasses.replace(body, mass=rho * volume, mass_from=how)
        bodies.append(body)
    return dataclasses.replace(scene, bodies=tuple(bodies))
