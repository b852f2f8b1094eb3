"""Capytaine runs for a set of rigid bodies, with an on-disk cache.

:func:`compute` solves one multibody problem (full 6N×6N radiation coupling), the diffraction
problems, and the radiation problems at ω = 0 and ω = ∞ directly (ERRATA G17), then maps
everything to NED body frames at each CoG (:mod:`.frames`). Bodies without DOFs are obstacles
(:mod:`.obstacles`): in every problem's boundary, absent from the results. Results are cached
as netCDF, keyed by a hash of every input that changes them.
"""
from __future__ import annotations

import contextlib
import datetime
import hashlib
import json
import logging
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import xarray as xr

from mbcontrol.errors import HydroError

from ... import defaults
from ...cache import load_or_make

from ...console import progress_bar
from ..data import netcdf
from ..data.dataset import BODY_FRAME_UNITS
from ..data.frames import to_body_frames
from .array_bem import symmetric_array_body
from ..mesh.geometry import NED_TO_ZUP, RIGID_DOFS, BemBody, hull_mesh, lid_mesh, mirror_symmetric, validate_body
from ..mesh.obstacles import drop_seabed_faces, refine, remove_contact_faces

LOG = logging.getLogger(__name__)
CACHE_VERSION = 2  # bump when the dataset layout or content for given inputs changes: old caches miss
OBSTACLE_MESHING = 2  # bump when .obstacles changes how obstacle results are made
CONTACT_TOL = 1e-3    # m per m of panel size: a face centre this close to a facing panel touches it
REQUIRED_VARS = ("added_mass", "radiation_damping", "added_mass_inf", "added_mass_zero", "excitation_force",
                 "froude_krylov_force", "diffraction_force", "hydrostatic_stiffness", "displaced_volume",
                 "waterplane_area", "center_of_buoyancy")


def _capytaine_version() -> str:
    import capytaine
    return capytaine.__version__


def _geometry_for_key(geometry: dict) -> dict:
    g = dict(geometry)
    if g.get("type") == "mesh" and g.get("file") and Path(g["file"]).is_file():
        g["file_sha256"] = hashlib.sha256(Path(g["file"]).read_bytes()).hexdigest()
        g["file"] = Path(g["file"]).name  # the content, not the location, defines the result
    return g


def cache_key(bodies, *, rho, g, depth, omegas, headings, lid) -> str:
    """sha256 (hex) of every input that changes the dataset, plus the Capytaine version."""
    payload = {
        "bodies": [{"name": b.name, "geometry": _geometry_for_key(b.geometry),
                    "cog": [float(x) for x in b.cog], "mass": float(b.mass),
                    "panel_size": float(b.panel_size), "dofs": list(b.dofs)} for b in bodies],
        "rho": float(rho), "g": float(g), "depth": repr(float(depth)),
        "omegas": [float(w) for w in omegas], "headings": [float(h) for h in headings],
        "lid": bool(lid), "capytaine": _capytaine_version(), "cache_version": CACHE_VERSION,
    }
    if any(not b.dofs for b in bodies):  # only then: keys of scenes without obstacles stay valid
        payload["obstacle_meshing"] = OBSTACLE_MESHING
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()


def _check_inputs(bodies, rho, g, depth, omegas, headings):
    if not bodies:
        raise HydroError("compute: bodies is empty; expected at least one BemBody")
    for b in bodies:
        if not isinstance(b, BemBody):
            raise HydroError(f"compute: bodies contains {type(b).__name__}; expected BemBody")
        validate_body(b)
    if all(not b.dofs for b in bodies):
        raise HydroError("compute: every body is an obstacle (no dofs); expected at least one body with DOFs")
    names = [b.name for b in bodies]
    if len(set(names)) != len(names):
        raise HydroError(f"compute: body names {names} are not distinct")
    for label, v in (("rho", rho), ("g", g)):
        if not (math.isfinite(float(v)) and float(v) > 0):
            raise HydroError(f"compute: {label} = {v!r}; expected a finite number > 0")
    if not float(depth) > 0:
        raise HydroError(f"compute: depth = {depth!r}; expected > 0 (m) or inf")
    w = np.asarray(omegas, dtype=float).reshape(-1)
    if w.size == 0 or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise HydroError("compute: omegas must be finite and > 0 (rad/s); "
                         "ω = 0 and ω = ∞ are always solved and stored separately")
    h = np.asarray(headings, dtype=float).reshape(-1)
    if h.size == 0 or not np.all(np.isfinite(h)):
        raise HydroError(f"compute: headings = {headings!r}; expected finite angles (rad, NED)")
    return np.unique(w), np.unique(h)


def _capytaine_bodies(bodies, lid: bool, depth: float):
    """Capytaine FloatingBodies (z-up; obstacles without DOFs), rotation centre = CoG; the
    hydrostatics bodies of the moving ones; whether mirror symmetry is used; contact faces removed."""
    import capytaine as cpt

    meshes = []
    for b in bodies:
        hull, sym, waterplane = hull_mesh(b)
        if not b.dofs:       # an obstacle may stand on the sea bed; a CAD mesh may be coarse
            n = hull.nb_faces
            hull = refine(hull, b.panel_size)
            hull = drop_seabed_faces(hull, depth, b.name) if np.isfinite(depth) else hull
            sym = sym and hull.nb_faces == n
        elif hull.vertices[:, 2].min() <= -depth:
            raise HydroError(f"body '{b.name}': geometry reaches below the sea bed (depth {depth} m)")
        meshes.append([hull, lid_mesh(hull, b.panel_size, waterplane) if lid else None, sym, hull])
    removed = {}
    if any(not b.dofs for b in bodies):  # lids above come from the closed hulls
        order = [i for i, b in enumerate(bodies) if b.dofs] + [i for i, b in enumerate(bodies) if not b.dofs]
        n_moving = sum(1 for b in bodies if b.dofs)
        tol = CONTACT_TOL * min(b.panel_size for b in bodies)
        kept_m, kept_o, counts = remove_contact_faces([meshes[i][0] for i in order[:n_moving]],
                                                      [meshes[i][0] for i in order[n_moving:]], tol)
        for i, m, c in zip(order, kept_m + kept_o, counts):
            meshes[i][2] = meshes[i][2] and m is meshes[i][0]  # a changed mesh may be asymmetric
            meshes[i][0] = m
            removed[bodies[i].name] = c
    # Mirror symmetry survives the multibody join only if every body has it.
    use_sym = all(s for _, _, s, _ in meshes)
    fbs, hydro = [], []
    for b, (hull, lidm, _, closed) in zip(bodies, meshes):
        cog = NED_TO_ZUP @ np.asarray(b.cog, dtype=float)
        m, lm = hull, lidm
        if use_sym:
            m, lm = mirror_symmetric(hull), mirror_symmetric(lidm) if lidm is not None else None
        if not b.dofs:       # no DOFs, no hydrostatics: it only scatters
            fbs.append(cpt.FloatingBody(mesh=m, lid_mesh=lm, name=b.name, dofs={}))
            continue
        # Gauss-Legendre 2 integrates the waterplane moments exactly on flat quads (the default
        # one-point rule underestimates ∫x² dA by O(h²)); used for hydrostatics only.
        full = cpt.FloatingBody(mesh=closed.with_quadrature("Gauss-Legendre 2"),  # before contact removal
                                dofs=cpt.rigid_body_dofs(rotation_center=cog),
                                center_of_mass=cog, mass=float(b.mass), name=b.name)
        hydro.append(full)
        fbs.append(cpt.FloatingBody(mesh=m, lid_mesh=lm, name=b.name, center_of_mass=cog, mass=float(b.mass),
                                    dofs=cpt.rigid_body_dofs(only=list(b.dofs), rotation_center=cog)))
    return fbs, hydro, use_sym, removed


def _solve(solver, problems, *, progress: bool, n_jobs: int):
    """Solve ``problems`` (grouped by ω so each influence matrix is built and factorised once)."""
    if n_jobs != 1:         # Capytaine's own bar: off with "log.quiet" too, as ours are
        return solver.solve_all(problems, n_jobs=n_jobs,
                                progress_bar=progress and not defaults.get("log.quiet"))
    try:  # Capytaine's resolution / depth / irregular-frequency warnings, once for the whole set;
        # its log handler writes to stdout, which `--json` keeps for the JSON alone
        from capytaine.bem import problems_checks as chk
        with contextlib.redirect_stdout(sys.stderr):
            for check in (chk._check_wavelength_and_mesh_resolution, chk._check_wavelength_and_water_depth,
                          chk._check_wavelength_and_irregular_frequencies):
                check(problems)
            chk._check_ram(problems, solver.engine, 1)
    except (ImportError, AttributeError):  # private helpers: skip them if a release renames them
        pass
    groups = defaultdict(list)
    for p in problems:
        groups[float(p.omega)].append(p)
    results = []
    # One problem at a time, not solve_all per frequency: solve_all runs a memory monitor
    # thread that polls every 0.2 s and is joined on exit, up to 0.2 s per call (30 s of the
    # 97 s of BEM for array_grid's three layouts); its order and results are the same.
    for w in progress_bar(iterable=sorted(groups), desc="BEM (per frequency)", unit="ω",
                          disable=not progress):
        results += [_solve_one(solver, p) for p in groups[w]]
        _forget_symmetric_blocks()
    return results


def _solve_one(solver, problem):
    """A problem's results, or (as solve_all) its failed-results container, so that every
    failure is counted and reported together (`_failed`)."""
    try:
        return solver.solve(problem, _check_wavelength=False)
    except Exception as exc:  # noqa: BLE001 - reported by _failed with the problem
        return problem.make_failed_results_container(exc)


def _forget_symmetric_blocks():
    """Capytaine 3.0 memoises each nested block-circulant matrix's conversion (an lru_cache of 128
    on the method): with a nested symmetric mesh every frequency's matrices stay alive, 8.5 GB
    for 16 floats over 66 frequencies. Done with a frequency, let them go."""
    try:
        from capytaine.tools.block_circulant_matrices import NestedBlockCirculantMatrix
        NestedBlockCirculantMatrix.to_BlockCirculantMatrix.cache_clear()
    except (ImportError, AttributeError):
        pass


def _failed(results):
    bad = [r for r in results if type(r).__name__.startswith("Failed")]
    if bad:
        r = bad[0]
        raise HydroError(f"Capytaine failed on {len(bad)} problem(s), first: {r.problem} "
                         f"({type(r.exception).__name__}: {r.exception})")


def _assemble_data_frame(results, dof_names, omegas, bem_headings, hydro, bodies, rho, g, depth):
    """Dataset in Capytaine's z-up frame with the module's variable names."""
    n, nw, nh = len(dof_names), len(omegas), len(bem_headings)
    idx = {d: i for i, d in enumerate(dof_names)}
    iw = {float(w): i for i, w in enumerate(omegas)}
    ih = {float(h): i for i, h in enumerate(bem_headings)}
    A, B = np.full((nw, n, n), np.nan), np.full((nw, n, n), np.nan)
    A0, Ainf = np.full((n, n), np.nan), np.full((n, n), np.nan)
    FK, DF = np.full((nh, nw, n), np.nan, complex), np.full((nh, nw, n), np.nan, complex)
    for r in results:
        w = float(r.omega)
        for rec in r.records:
            i = idx[rec["influenced_dof"]]
            if "added_mass" in rec:
                j = idx[rec["radiating_dof"]]
                if w == 0.0:
                    A0[j, i] = rec["added_mass"]
                elif w == np.inf:
                    Ainf[j, i] = rec["added_mass"]
                else:
                    A[iw[w], j, i], B[iw[w], j, i] = rec["added_mass"], rec["radiation_damping"]
            else:
                k = ih[float(rec["wave_direction"])]
                FK[k, iw[w], i], DF[k, iw[w], i] = rec["Froude_Krylov_force"], rec["diffraction_force"]
    for label, arr in (("added_mass", A), ("radiation_damping", B), ("added_mass_inf", Ainf),
                       ("excitation_force", FK + DF)) + ((("added_mass_zero", A0),) if depth == np.inf else ()):
        if not np.all(np.isfinite(arr)):
            raise HydroError(f"Capytaine results: {label} has {np.count_nonzero(~np.isfinite(arr))} missing "
                             "or non-finite entries; expected every problem solved")
    # Hydrostatics about each CoG, all 6 DOFs, z-up; then restricted to the solved DOFs.
    K = np.zeros((n, n))
    vol, awp, cob = [], [], []
    for b, fb in zip(bodies, hydro):
        k6 = fb.compute_hydrostatic_stiffness(rho=rho, g=g)
        for d1 in b.dofs:
            for d2 in b.dofs:  # capytaine: (influenced, radiating)
                K[idx[f"{b.name}__{d2}"], idx[f"{b.name}__{d1}"]] = float(k6.sel(influenced_dof=d1, radiating_dof=d2))
        vol.append(float(fb.disp_volume))
        awp.append(float(fb.waterplane_area))
        cob.append(np.asarray(fb.center_of_buoyancy, dtype=float))
    mat = ("radiating_dof", "influenced_dof")
    return xr.Dataset(
        {"added_mass": (("omega",) + mat, A), "radiation_damping": (("omega",) + mat, B),
         "added_mass_zero": (mat, A0), "added_mass_inf": (mat, Ainf),
         "excitation_force": (("wave_direction", "omega", "influenced_dof"), FK + DF),
         "froude_krylov_force": (("wave_direction", "omega", "influenced_dof"), FK),
         "diffraction_force": (("wave_direction", "omega", "influenced_dof"), DF),
         "hydrostatic_stiffness": (mat, K), "displaced_volume": (("body",), np.array(vol)),
         "waterplane_area": (("body",), np.array(awp)), "center_of_buoyancy": (("body", "xyz"), np.array(cob))},
        coords={"omega": np.asarray(omegas, float), "radiating_dof": list(dof_names),
                "influenced_dof": list(dof_names), "wave_direction": np.asarray(bem_headings, float),
                "body": [b.name for b in bodies], "xyz": ["x", "y", "z"]})


def compute(bodies: list[BemBody], *, rho: float, g: float, depth: float, omegas, headings=(0.0,),
            lid: bool = True, cache_dir: str | Path | None = None, progress: bool = True,
            n_jobs: int = 1) -> xr.Dataset:
    """Radiation, diffraction and hydrostatics of ``bodies`` with Capytaine, in NED body frames.

    Parameters
    ----------
    bodies : list of BemBody (n-frame NED inputs).
    rho : water density, kg/m^3.  g : gravity, m/s^2.  depth : water depth, m (np.inf for deep water).
    omegas : wave frequencies, rad/s (finite, > 0; sorted and de-duplicated). ω = 0 and ω = ∞ are
        always solved too and stored as ``added_mass_zero`` and ``added_mass_inf`` (in finite depth
        Capytaine 3.0 cannot solve ω = 0: ``added_mass_zero`` is then NaN, with a note in its attrs).
    headings : NED wave directions β, rad: the direction waves travel to, from +x towards +y
        (starboard). Capytaine is called with -β (its y axis points to port).
    lid : put a lid on each interior waterplane against irregular frequencies.
    cache_dir : folder for ``bem_<key[:16]>.nc``; an existing file is loaded instead of solving.
    progress : show a tqdm bar (per frequency).  n_jobs : Capytaine/joblib processes.

    Returns
    -------
    xarray.Dataset, every body referred to its CoG in NED body axes (see module docs of
    :mod:`mbcontrol.hydro` for the layout). Time convention e^{-iωt}: a wave η(t) = Re(a e^{-iωt})
    at the n-frame origin (η positive up) gives the excitation wrench Re(F̂ a e^{-iωt}).
    Matrices are stored (…, radiating_dof, influenced_dof); use :func:`mbcontrol.hydro.matrix` for the usual
    row = force, column = motion layout.
    """
    omegas, headings = _check_inputs(bodies, rho, g, depth, omegas, headings)
    rho, g, depth = float(rho), float(g), float(depth)
    key = cache_key(bodies, rho=rho, g=g, depth=depth, omegas=omegas, headings=headings, lid=lid)
    if cache_dir is None:
        return _solve_bem(bodies, rho, g, depth, omegas, headings, lid, progress, n_jobs, key)
    path = Path(cache_dir) / f"bem_{key[:16]}.nc"

    def read(path):
        ds = netcdf.read_netcdf(path, required=REQUIRED_VARS)
        if ds.attrs.get("cache_key") != key:
            raise HydroError(f"cache_key attribute {ds.attrs.get('cache_key')!r} does not match "
                             f"the inputs ({key}): another solve's dataset")
        return ds

    def solve(path):
        ds = _solve_bem(bodies, rho, g, depth, omegas, headings, lid, progress, n_jobs, key)
        netcdf.write_netcdf_atomic(ds, path)

    # a second process asking for the same solve waits on the entry's lock and loads it; an
    # unreadable or foreign entry is moved aside and solved again (mbcontrol.cache)
    return load_or_make(path, read, solve, what="BEM cache entry")


def _solve_bem(bodies, rho, g, depth, omegas, headings, lid, progress, n_jobs, key) -> xr.Dataset:
    """compute's BEM solve itself (no cache), its dataset tagged with the inputs' `key`."""
    import capytaine as cpt

    fbs, hydro, use_sym, removed = _capytaine_bodies(bodies, lid, depth)
    # an array whose layout is mirror-symmetric is solved as one body on the array's planes
    array = None if use_sym else symmetric_array_body(bodies, lid)
    mb = array[0] if array else cpt.Multibody(fbs)
    dof_names = [f"{b.name}__{d}" for b in bodies for d in RIGID_DOFS if d in b.dofs]
    if list(mb.dofs) != dof_names:  # Multibody keeps the order of rigid_body_dofs
        raise HydroError(f"internal: Capytaine DOF order {list(mb.dofs)} != {dof_names}")
    env = dict(rho=rho, g=g, water_depth=depth)
    bem_headings = np.unique(-headings)  # NED β -> BEM -β (y flips)
    # Capytaine 3.0 has no finite-depth Green function at ω = 0 (kh < 0.1): A(0) is left NaN there
    specials = (0.0, np.inf) if depth == np.inf else (np.inf,)
    problems = [cpt.RadiationProblem(body=mb, omega=w, radiating_dof=d, **env)
                for w in (*specials, *omegas) for d in dof_names]
    problems += [cpt.DiffractionProblem(body=mb, omega=w, wave_direction=float(h), **env)
                 for w in omegas for h in bem_headings]
    solver = cpt.BEMSolver()
    t0 = datetime.datetime.now()
    try:
        results = _solve(solver, problems, progress=progress, n_jobs=n_jobs)
    except HydroError:
        raise
    except Exception as exc:
        raise HydroError(f"Capytaine failed ({type(exc).__name__}: {exc})") from exc
    _failed(results)
    seconds = (datetime.datetime.now() - t0).total_seconds()
    obstacles = [b.name for b in bodies if not b.dofs]
    everything, bodies = dict(zip((b.name for b in bodies), fbs)), [b for b in bodies if b.dofs]
    fbs = [everything[b.name] for b in bodies]  # per-body variables: the moving bodies only
    data = _assemble_data_frame(results, dof_names, omegas, bem_headings, hydro, bodies, rho, g, depth)
    cogs = {b.name: np.asarray(b.cog, dtype=float) for b in bodies}
    ds = to_body_frames(data, refs=cogs, cogs=cogs, z_up=True)  # rotation centre = CoG: r_k = 0
    # to_body_frames wraps -(-β) to [-π, π); give back the caller's own heading values
    user = {float((h + np.pi) % (2 * np.pi) - np.pi): float(h) for h in headings}
    ds = ds.assign_coords(wave_direction=[user[float(v)] for v in ds["wave_direction"].values]).sortby("wave_direction")
    ds["cog"] = (("body", "xyz"), np.array([cogs[b.name] for b in bodies]))
    ds["mass"] = (("body",), np.array([float(b.mass) for b in bodies]))
    ds["hull_panel_count"] = (("body",), np.array([fb.mesh.nb_faces for fb in fbs]))
    ds["lid_panel_count"] = (("body",), np.array([fb.lid_mesh.nb_faces if fb.lid_mesh is not None else 0
                                                 for fb in fbs]))
    for v, u in BODY_FRAME_UNITS.items():
        ds[v].attrs["units"] = u
    if depth != np.inf:
        ds["added_mass_zero"].attrs["note"] = "NaN: Capytaine 3.0 cannot solve ω = 0 in finite depth"
    ds["omega"].attrs.update(units="rad/s", long_name="wave angular frequency")
    ds["wave_direction"].attrs.update(units="rad", long_name="NED heading waves travel to, +x towards +y (starboard)")
    # Capytaine: 8 panel radii per wavelength. Its Multibody takes the least over the bodies;
    # the coarsest one (a CAD obstacle, say) limits the whole solve
    lam_min = max(max(fb.minimal_computable_wavelength for fb in getattr(mb, "bodies", [mb])), 1e-12)
    ds.attrs.update({
        "rho": rho, "g": g, "depth": depth, "frame": "NED body frames at CoG",
        "time_convention": "exp(-i omega t)",
        "excitation_reference": "unit wave amplitude, elevation positive up, at the n-frame origin",
        "matrix_layout": "X[radiating_dof, influenced_dof]; force_i = -sum_j X[j, i] * motion_j",
        "source": f"capytaine {_capytaine_version()}", "lid": bool(lid), "mirror_symmetry_used": bool(use_sym or array),
        "array_symmetry_planes": list(array[1]) if array else [],
        "hull_panels": {k: int(fb.mesh.nb_faces) for k, fb in everything.items()},
        "lid_panels": {k: int(fb.lid_mesh.nb_faces) if fb.lid_mesh is not None else 0
                       for k, fb in everything.items()},
        "obstacles": obstacles, "contact_faces_removed": removed,
        "omega_max_mesh": float(np.sqrt(2 * np.pi * g / lam_min)),  # deep-water ω at that wavelength, rad/s
        "cache_key": key, "solve_seconds": seconds,
        "created": datetime.datetime.now().isoformat(timespec="seconds"),
    })
    return ds

