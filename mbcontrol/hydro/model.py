"""The hydrodynamics a plant needs, restricted to the DOFs its joints can move.

`HydroModel` holds body-frame BEM data (NED, at each CoG, stored in exp(-i omega t) as
Capytaine's; see mbcontrol.hydro) for the active DOFs and the radiation state-space model fitted to them. Fits are cached on disk
(keyed by the data, the DOFs, the tolerance, the fit band and the fitting code), written to a
temporary file and renamed.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..cache import cache_dir, rebuilt_once
from ..console import status
from ..errors import HydroError
from ..lti import phasor
from ..scene import DOF_NAMES, Scene
from ..waves import Wave, coefficient_series, excitation_series, interpolate_complex
from .data.netcdf import read_netcdf
from .mesh.geometry import BemBody
from .data.headings import axisymmetric_headings, excitation_over_headings, heading_matrix, headings_remedy
from .fit.radiation import RadiationModel, coupled_groups
from .fit.band import default_fit_band
from .fit.response_error import Device
from .fit.store import (cached_fit, fit_band_limit, model_from_arrays,  # noqa: F401 (the model's face)
                         recording_served_fits, shipped_fits_dir)
from .fit.ssforms import modal_blocks
from .readers.physical import DAMPING_EIG_TOL, check_physical
from .readers.layout import force_first, kind_scales

if TYPE_CHECKING:                  # the data are read by data.netcdf; here only named
    import xarray as xr


@dataclass(frozen=True)
class HydroModel:
    dofs: tuple[str, ...]
    data: xr.Dataset                   # body-frame BEM data on `dofs`
    radiation: RadiationModel
    source: str
    fit_omega_max: float = np.inf      # rad/s, the scene's radiation fit band limit
    response_band: tuple | None = None  # rad/s, where the fit is judged per frequency (scene)
    fit_method: str = "coupled"        # "coupled" (module radiation) or "columns" (module array_fit)
    device: Device | None = None       # the plant around the kernel, whose response judged the fit

    def _matrix(self, name: str) -> np.ndarray:
        """(..., influenced, radiating) array: rows are the DOFs the force acts on."""
        da = self.data[name].sel(influenced_dof=list(self.dofs), radiating_dof=list(self.dofs))
        dims = [d for d in da.dims if d not in ("influenced_dof", "radiating_dof")]
        return da.transpose(*dims, "influenced_dof", "radiating_dof").values

    @property
    def added_mass_inf(self) -> np.ndarray:
        return self._matrix("added_mass_inf")

    @property
    def omega(self) -> np.ndarray:
        return self.data["omega"].values

    def added_mass(self) -> np.ndarray:
        return self._matrix("added_mass")

    def radiation_damping(self) -> np.ndarray:
        return self._matrix("radiation_damping")

    def hydrostatic_stiffness(self) -> np.ndarray:
        return self._matrix("hydrostatic_stiffness")

    def excitation_coefficients(self, direction: float = 0.0) -> np.ndarray:
        """Complex excitation per unit amplitude (n_omega, n_dof; N/m or N m/m) as stored,
        exp(-i omega t): for the time-domain synthesis (mbcontrol.waves); phasors in the public
        exp(+i omega t) convention come from `excitation_phasor`."""
        directions = self.data["wave_direction"].values
        i = int(np.argmin(np.abs(directions - direction)))
        if abs(directions[i] - direction) > 1e-6:
            raise HydroError(f"{self.source}: no excitation data for wave direction "
                             f"{direction:.4g} rad; the data has {np.round(directions, 4)}: "
                             f"{headings_remedy(self.source, directions, [direction])}")
        da = self.data["excitation_force"].isel(wave_direction=i)
        return da.sel(influenced_dof=list(self.dofs)).transpose("omega", "influenced_dof").values

    def excitation_phasor(self, omega, direction=0.0) -> np.ndarray:
        """The excitation per unit wave amplitude (n, n_dof; N/m or N m/m) as exp(+i omega t)
        phasors, the public convention (mbcontrol.lti): F(t) = Re[F e^{+i omega t}] for the
        elevation Re[e^{+i omega t}] at the n-frame origin. The one place the stored
        exp(-i omega t) data are converted; arguments and errors as `excitation_at`."""
        return phasor(self.excitation_at(omega, direction))

    def excitation_at(self, omega, direction=0.0) -> np.ndarray:
        """Complex excitation per unit amplitude (n, n_dof), exp(-i omega t) as stored (the
        public exp(+i omega t) phasors: `excitation_phasor`), at frequencies
        omega (rad/s, n) travelling in `direction` (rad, NED): one float (the data's heading,
        matched exactly, as `excitation_coefficients`) or one direction per frequency (a spread
        sea's components), interpolated between the data's headings (module headings).
        Frequencies are interpolated linearly, never extrapolated (ValueError outside the
        band); a direction outside the data's headings raises HydroError."""
        omega = np.asarray(omega, float)
        if np.ndim(direction) == 0:
            return interpolate_complex(self.omega, self.excitation_coefficients(direction), omega)
        direction = np.asarray(direction, float)
        if direction.shape != omega.shape:
            raise HydroError(f"{self.source}: one wave direction per frequency expected, got "
                             f"{direction.size} directions for {omega.size} frequencies")
        weights = heading_matrix(self.data["wave_direction"].values, direction, self.source)
        data = self.data["excitation_force"].sel(influenced_dof=list(self.dofs)).transpose(
            "wave_direction", "omega", "influenced_dof").values
        per_heading = np.zeros((data.shape[0], omega.size, data.shape[2]), complex)
        for j in np.flatnonzero(np.any(weights != 0, axis=0)):
            per_heading[j] = interpolate_complex(self.omega, data[j], omega)
        return excitation_over_headings(per_heading, weights)

    def excitation(self, wave: Wave, t) -> np.ndarray:
        try:
            if wave.directional:
                return coefficient_series(wave, self.excitation_at(wave.omega, wave.direction), t)
            return excitation_series(wave, self.omega, self.excitation_coefficients(
                wave.direction), t)
        except HydroError:
            raise
        except ValueError as exc:
            raise HydroError(f"{self.source}: {exc}") from None

    def stiffness_by_body(self) -> dict[str, np.ndarray]:
        """6x6 hydrostatic stiffness at each body's CoG (zeros on DOFs not in the data)."""
        G = self.hydrostatic_stiffness()
        out: dict[str, np.ndarray] = {}
        for i, dof_i in enumerate(self.dofs):
            body, name_i = dof_i.split("__")
            for j, dof_j in enumerate(self.dofs):
                body_j, name_j = dof_j.split("__")
                if body_j == body:
                    block = out.setdefault(body, np.zeros((6, 6)))
                    block[DOF_NAMES.index(name_i), DOF_NAMES.index(name_j)] = G[i, j]
        return out

    def buoyancy(self, water) -> dict:
        """body -> (rho g V in N, centre of buoyancy at rest in the n-frame, m)."""
        if "displaced_volume" not in self.data or "center_of_buoyancy" not in self.data:
            return {}
        bodies = {d.split("__")[0] for d in self.dofs}
        out = {}
        for body in self.data["body"].values.tolist():
            if body in bodies:
                volume = float(self.data["displaced_volume"].sel(body=body))
                centre = self.data["center_of_buoyancy"].sel(body=body).transpose("xyz").values
                out[body] = (water.rho * water.g * volume, centre)
        return out

    def radiation_matrices(self):
        """(A_r, B_r, C_r, D_r) in real modal form: same input-output map, sparse A_r."""
        r = self.radiation
        order = [r.dofs.index(d) for d in self.dofs]
        B, C, D = r.B[:, order], r.C[order, :], r.D[np.ix_(order, order)]
        if self.fit_method == "columns":   # already real block-diagonal, poles shared by columns
            return r.A, B, C, D
        return (*modal_blocks(r.A, B, C), D)

    def restricted(self, dofs) -> "HydroModel":
        dofs = tuple(dofs)
        if dofs == self.dofs:
            return self
        missing = [d for d in dofs if d not in self.dofs]
        if missing:
            raise HydroError(f"{self.source}: the plant moves {missing} but the hydro model "
                             f"only has {list(self.dofs)}")
        return HydroModel(dofs, self.data, cached_fit(self.data, dofs, None, self.source,
                                                       self.fit_omega_max, self.response_band,
                                                       self.fit_method),
                          self.source, self.fit_omega_max, self.response_band, self.fit_method)

    def frequency_domain_matrices(self, omega):
        """A(omega), B(omega) interpolated to omega (n, n_dof, n_dof), for FD solutions."""
        return (interpolate_complex(self.omega, self.added_mass(), np.asarray(omega)).real,
                interpolate_complex(self.omega, self.radiation_damping(),
                                    np.asarray(omega)).real)


def load_hydro_model(scene: Scene, dofs, tol: float | None = None, device=None) -> HydroModel:
    """Body-frame data for `dofs` (from scene.hydro.file, or a cached BEM run) and its fit.
    device: a callable (source, data) -> Device, the plant around the kernel whose response
    judges the fit (mbcontrol.plant.device_around), or None to judge the kernel itself."""
    tol = scene.hydro.radiation_tol if tol is None else tol
    source, data = load_hydro_data(scene, dofs)
    judge, band = device(source, data) if device is not None else None, scene.hydro.fit_omega_max
    if judge is not None and not np.isfinite(band) and "converted_from" in data.attrs:
        band = default_fit_band(scene.name, judge, data, dofs)   # a user's own BEM file
    return fit_hydro_model(data, dofs, tol, source, band, scene.hydro.response_band,
                           fit_method(scene.hydro.radiation_fit, dofs, data), judge)


ARRAY_BODIES = 9   # "auto" fits column by column from this many bodies (module array_fit)


def fit_method(setting: str, dofs, data: xr.Dataset | None = None) -> str:
    """The radiation fit a scene's [hydro] radiation_fit asks for on ``dofs``: "coupled" or
    "columns"; "auto" is "columns" when the DOFs belong to at least ARRAY_BODIES bodies that
    radiation couples (with ``data``, the largest coupled group's bodies: bodies solved without
    interaction are fitted group by group, and identical ones share a fit)."""
    def bodies(group):
        return len({str(d).split("__")[0] for d in group})
    if setting != "auto" or bodies(dofs) < ARRAY_BODIES:
        return "coupled" if setting == "auto" else setting
    if data is not None and max(map(bodies, coupled_groups(data, list(dofs)))) < ARRAY_BODIES:
        return "coupled"
    return "columns"


def load_hydro_data(scene: Scene, dofs) -> tuple[str, xr.Dataset]:
    """(source, body-frame BEM dataset) holding at least `dofs`, without a radiation fit.

    First match wins: the precomputed [hydro] file when it exists; the scene's own BEM results
    ([hydro] source: WAMIT, BEMIO or Capytaine, converted once and cached, mbcontrol.hydro.source);
    a (cached) Capytaine run on [hydro] omega. A scene with both source and omega uses the source
    and says so; one whose file is missing, with neither, is told what to do."""
    h = scene.hydro
    supplied = True
    if h.file and Path(h.file).exists():
        source = h.file
        data = read_netcdf(source)
    elif h.source and (Path(h.source).is_file() or not h.file):
        if h.omega:
            status(f"{scene.name}: [hydro] source {Path(h.source).name} is used; [hydro] omega "
                   f"(BEM frequencies for Capytaine) is not (remove one of them)", __name__)
        # its cache entry, if unreadable, is set aside by read_netcdf: converted again, once
        from .source import converted_source       # here: a [hydro] file needs no reader
        source, data = rebuilt_once(lambda: converted_source(scene, dofs))
    elif h.file and not h.omega:
        raise HydroError(_missing_file(scene))
    else:
        source, data = _run_bem(scene, dofs)
        supplied = False
    # every source passes the same physical gate (module readers.physical); a cut at an
    # interaction radius is non-passive by construction (module bem.neighbours records by how much)
    check_physical(data, f"{source} ([hydro] of {scene.path})", eig_tol=(
        DAMPING_EIG_TOL if h.interaction_radius == np.inf or supplied else np.inf))
    if supplied:
        _check_interaction(scene, data, source)
    _check_dofs(data, dofs, source)
    if scene.hydro.axisymmetric:           # one heading serves all (module headings)
        data = axisymmetric_headings(data, f"{scene.path}: [hydro] axisymmetric: {source}")
    return source, data


COUPLING_ZERO = 1e-9   # scaled |A_ij|, |B_ij| below this between two bodies: no coupling (exact zeros when solved apart)


def _check_interaction(scene: Scene, data: xr.Dataset, source: str) -> None:
    """Refuse supplied data ([hydro] file or source) that couple bodies the scene says do not
    interact ([hydro] interaction = false, or farther apart than interaction_radius, horizontal
    distance of the geometry centres as in module bem.neighbours). The data cannot be uncoupled
    after the fact: a coupled BEM solve's excitation holds the waves the other bodies scatter,
    and each body's own A, B hold its neighbours' reflections, so zeroing the cross blocks would
    leave half a coupled model. A Capytaine run on [hydro] omega solves the bodies as asked."""
    h = scene.hydro
    if h.interaction and h.interaction_radius == np.inf:
        return
    dofs = [str(d) for d in data["radiating_dof"].values]
    bodies = [d.split("__")[0] for d in dofs]
    centres = {b.name: np.asarray(b.geometry.center if b.geometry else b.cog, float)[:2]
               for b in scene.bodies}
    strength = np.zeros((len(dofs), len(dofs)))
    for var in ("added_mass", "radiation_damping", "added_mass_inf"):
        x = np.abs(force_first(data[var])).reshape(-1, len(dofs), len(dofs))
        if not np.all(np.isfinite(x)):
            continue
        s = np.sqrt(kind_scales(dofs, np.diagonal(x, axis1=1, axis2=2).max(0)))
        strength = np.maximum(strength, (x / np.outer(s, s)).max(0))
    for i, j in zip(*np.nonzero(strength > COUPLING_ZERO)):
        a, b = bodies[i], bodies[j]
        if a == b or (h.interaction and a in centres and b in centres
                      and np.hypot(*(centres[a] - centres[b])) <= h.interaction_radius * (1 + 1e-9)):
            continue
        setting = ("interaction = false" if not h.interaction
                   else f"interaction_radius = {h.interaction_radius:g} m")
        raise HydroError(
            f"{scene.path}: [hydro] {setting}, but the hydro data {source} couple bodies {a!r} and {b!r} "
            f"(radiation between {dofs[i]} and {dofs[j]}, {strength[i, j]:.3g} of the diagonal scale). "
            "Supplied BEM data cannot be uncoupled afterwards (their excitation and each body's own "
            "coefficients include the other bodies' waves). Remove the [hydro] interaction setting to "
            "use the coupled data as they are, or remove [hydro] file/source and give [hydro] omega "
            "so that Capytaine solves the bodies as asked")


def _missing_file(scene: Scene) -> str:
    """Why a scene's [hydro] file is not there, and what to do (a copied catalogue scene
    still names the catalogue's data file, read beside the copy)."""
    from ..scene import catalogue_dir
    path = Path(scene.hydro.file)
    text = (f"{scene.path}: [hydro] file {path.name!r} (read as {path}, relative to the scene's "
            f"folder): no such file. ")
    if scene.hydro.source:
        text += f"Its [hydro] source {scene.hydro.source} is not there either. "
    shipped = catalogue_dir() / path.name
    if shipped.exists() and shipped != path:
        text += (f"The catalogue has one of that name, for its own geometry: copy it beside "
                 f"your scene (cp {shipped} {path.parent}/) or set file = \"{shipped}\"; ")
    return text + ("or remove `file` and give [hydro] omega (rad/s) to compute the data with "
                   "Capytaine from the bodies' geometry, or [hydro] source = \"FILE\" to use your own "
                   "BEM results (a WAMIT .out, BEMIO .h5 or Capytaine .nc file)")


def fit_hydro_model(data: xr.Dataset, dofs, tol: float | None, source: str,
                    fit_omega_max: float = np.inf, response_band=None, method: str = "coupled",
                    device: Device | None = None) -> HydroModel:
    """A HydroModel of `data` on `dofs`, its radiation fitted to `tol` (cached on disk).

    For callers that change the data first (e.g. mbcontrol.plant.fidelity drops the coupling between
    bodies): the cache key is the data itself, so a changed dataset never serves an old fit.
    """
    _check_dofs(data, dofs, source)
    fit = cached_fit(data, tuple(dofs), tol, source, fit_omega_max, response_band, method, device)
    return HydroModel(tuple(dofs), data, fit, source, fit_omega_max, response_band, method, device)


def _run_bem(scene: Scene, dofs):
    if not scene.hydro.omega:
        raise HydroError(f"{scene.path}: hydro.omega: expected BEM frequencies to compute the "
                         f"hydrodynamics of the scene's geometry (or a hydro.file)")
    # here: a plant from stored data needs no BEM solver
    from .bem.isolated import compute_isolated
    from .bem.neighbours import compute_within
    from .bem.solve import compute
    bodies = []
    for body in scene.bodies:
        # solve only what the joints can move (and the scene allows): no more than needed
        body_dofs = tuple(d.split("__")[1] for d in dofs if d.split("__")[0] == body.name
                          and d.split("__")[1] in scene.hydro.dofs)
        if body.hydro and body_dofs:
            bodies.append(BemBody(name=body.name, geometry=geometry_dict(body.geometry),
                                      cog=body.cog, mass=body.mass,
                                      panel_size=scene.hydro.panel_size, dofs=body_dofs))
    bodies += obstacle_bodies(scene)
    solve = compute if scene.hydro.interaction else compute_isolated
    if scene.hydro.interaction_radius < np.inf:
        solve = functools.partial(compute_within, radius=scene.hydro.interaction_radius)
    data = solve(bodies, rho=scene.water.rho, g=scene.water.g, depth=scene.water.depth,
                       omegas=np.array(scene.hydro.omega), headings=scene.hydro.headings,
                       lid=scene.hydro.lid, cache_dir=cache_dir())
    what = "BEM" if scene.hydro.interaction else "BEM, bodies solved alone,"
    if scene.hydro.interaction_radius < np.inf:
        what = f"BEM, each body with its neighbours within {scene.hydro.interaction_radius:g} m,"
    return f"{what} of {scene.path}", data


def obstacle_bodies(scene: Scene, panel_size: float | None = None) -> list[BemBody]:
    """The scene's obstacles as BemBodies without DOFs (mass unused), panels of `panel_size`
    (m; default the scene's)."""
    return [BemBody(name=o.name, geometry=geometry_dict(o.geometry), cog=o.geometry.center,
                    mass=0.0, panel_size=panel_size or scene.hydro.panel_size, dofs=())
            for o in scene.obstacles]


def geometry_dict(geometry) -> dict:
    g = {"type": geometry.kind, "center": list(geometry.center)}
    for key in ("size", "radius", "length", "file"):
        value = getattr(geometry, key)
        if value is not None:
            g[key] = list(value) if isinstance(value, tuple) else value
    if geometry.profile is not None:
        g["profile"] = [list(point) for point in geometry.profile]
    if geometry.kind == "cylinder":
        g["axis"] = geometry.axis
    return g


def _check_dofs(data: xr.Dataset, dofs, source: str) -> None:
    for var in ("added_mass", "radiation_damping", "added_mass_inf", "excitation_force",
                "hydrostatic_stiffness"):
        if var not in data:
            raise HydroError(f"{source}: missing variable {var!r}")
    have = set(data["radiating_dof"].values.tolist())
    missing = [d for d in dofs if d not in have]
    if missing:
        raise HydroError(f"{source}: the scene's joints move {missing}, but the hydro data "
                         f"has only {sorted(have)}")
