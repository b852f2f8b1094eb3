"""Nonlinear hydrostatics and Froude-Krylov forces: the undisturbed incident pressure over each
body's instantaneous wetted surface ([hydro] hydrostatics = froude_krylov = "nonlinear").

The pressure is p = rho g z + p_dyn (Pa; NED, z down), p_dyn the linear incident-wave pressure
taken to the instantaneous free surface by Wheeler stretching, so p vanishes on the incident
surface and the wetted surface ends there. Radiation and diffraction stay linear: the
disturbance w carries the BEM excitation minus the linear Froude-Krylov force of this same
surface model, so for small waves the plant is the linear one (tests/features/plant/test_nonlinear_fk.py).

Two paths (`[hydro] nonlinear_path`):
  analytic  bodies of revolution with a vertical axis (mbcontrol.hydro.mesh.axisymmetric):
            volume integrals in closed form, the local free surface flat across the body; a
            sphere at any pose (its pressure forces pass through its centre), other bodies of
            revolution only when they cannot rotate (their pressure moment is not modelled).
  panels    any closed surface (mbcontrol.hydro.mesh.panels): the pressure at every panel
            point, clipped at the instantaneous surface, compiled with the plant.
  auto      analytic for a sphere, panels otherwise.

A fixed-step run integrates the pressure at every Runge-Kutta stage, or with [hydro]
nonlinear_update = "step" once per step (mbcontrol.plant.held_pressure: about 3x faster on a
mesh, an error of order dt that tests/plant/test_held_pressure.py measures).

The wave enters as rows of w (w__field_<body>_<i>): time series of Chebyshev coefficients of
the incident field about the body's rest position (mbcontrol.waves.local_field), synthesised
by the same FFT as the excitation, so the compiled step never sums wave components.
Long-crested seas only, in the direction [hydro] nonlinear_direction.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..errors import HydroError, SceneError, WaveError
from ..hydro import axisymmetric_fk as axisymmetric_model
from ..hydro import (body_panels, calm_water_function, geometry_dict,
                     pressure_wrench_function)
from ..hydro import buoyancy_potential as primitive_potential
from ..scene import DOF_NAMES
from ..waves import LocalField, band_field, wavenumber

WAVE_GRIDS_KEPT = 64        # frequency grids x directions whose rows a plant keeps
FIELD_TOL = 1e-3            # truncation of the field's series per unit amplitude (m of head)
MAX_ORDER = 24              # Chebyshev terms per direction at most
MIN_REACH_M = 5.0           # the field covers at least this horizontal excursion from rest
FIXED_REACH_M = 1e-3        # ... and this little for a body whose CoG cannot move horizontally


@dataclass(frozen=True, eq=False)
class PressureBody:
    """One body's nonlinear pressure model and its rows of w."""
    body: str
    path: str                       # "analytic" | "panels"
    model: object                   # AxisymmetricFK (analytic) or Panels (panels)
    field: LocalField | None        # panels in waves
    n_rows: int                     # rows of w it reads (0: calm water)
    cog: np.ndarray                 # CoG at rest, n-frame, m
    centre: np.ndarray              # analytic: geometric centre at rest, n-frame, m
    reach: float                    # m: horizontal excursion the field covers
    omega_max: float = math.inf     # rad/s: components above it stay linear (zero rows)
    linear_fk: np.ndarray | None = None   # (6, n_rows): wrench per row at rest (set after build)
    surface: ca.Function | None = None    # panels in waves: (rows, R, r_cog) -> wrench
    # ... and the most of the field's box any point uses (LocalField.usage), in one pass: for
    # the outputs (the range costs f 12 % more: apart)
    surface_range: ca.Function | None = None
    calm: ca.Function | None = None       # not a sphere: (R, r_cog) -> calm water's wrench, J
    rest_potential: float = 0.0           # J: calm water's rho g int_wet z dV at rest

    def row_coefficients(self, omega) -> np.ndarray:
        """(n_omega, n_rows) complex rows per unit amplitude, exp(-i omega t); zero above
        omega_max, so those components' linear Froude-Krylov force is not removed either."""
        omega = np.asarray(omega, float)
        source = self.field if self.path == "panels" else self.model
        rows = source.row_coefficients(omega)
        rows[omega > self.omega_max * (1 + 1e-12)] = 0.0
        return rows

    def wrench(self, rows, R, r_cog, rho: float, g: float):
        """(force, moment about the current CoG), n-frame axes, N and N m; CasADi SX."""
        if self.path == "analytic":
            centre = r_cog + ca.mtimes(R, ca.DM(self.centre - self.cog))
            force, moment_c = self.model.wrench(rows, centre, rho, g)
            return force, moment_c + ca.cross(centre - r_cog, force)
        if self.surface is None:                           # calm water
            return tuple(self.calm.call([R, r_cog])[:2])
        return tuple(self.surface.call([rows, R, r_cog]))   # the scene's rho and g


def with_nonlinear_pressure(scene):
    """The scene with [hydro] hydrostatics = froude_krylov = "nonlinear" (the model that covers
    large motions); SceneError naming the body when a hydro body has no [body.geometry]."""
    if scene.hydro is None:
        raise SceneError(f"{scene.path}: the nonlinear pressure needs hydro bodies; this scene "
                         f"has no [hydro] table")
    bare = [b.name for b in scene.bodies if b.hydro and b.geometry is None]
    if bare:
        raise SceneError(f"{scene.path}: body '{bare[0]}': the nonlinear hydrostatics and "
                         f"Froude-Krylov forces integrate over the body's surface; expected a "
                         f"[body.geometry] table (a mesh file, a primitive or a profile)")
    hydro = dataclasses.replace(scene.hydro, hydrostatics="nonlinear", froude_krylov="nonlinear")
    return dataclasses.replace(scene, hydro=hydro)


def pressure_bodies(scene, topo, hydro) -> tuple[PressureBody, ...]:
    """The nonlinear pressure models of the scene's hydro bodies (empty for linear hydrostatics)."""
    if scene.hydro.hydrostatics != "nonlinear":
        return ()
    waves = scene.hydro.froude_krylov == "nonlinear"
    k_max = _k_max(scene)
    out = []
    for body in scene.bodies:
        if not body.hydro:
            continue
        geometry = geometry_dict(body.geometry)
        path = _path(scene, topo, body, geometry)
        out.append(_build(scene, body, geometry, path, waves, k_max, _drifts(topo, body)))
    return tuple(_with_linear_fk(b, scene.water) for b in out)


DEFAULT_OMEGA_MAX = 4.0     # rad/s: without a response band, components above stay linear


def omega_max(scene) -> float:
    """rad/s: wave components above it keep linear Froude-Krylov forces (their field rows are
    zero and their BEM excitation whole), so the series need not resolve short waves that
    carry little of a sea's energy: [hydro] nonlinear_omega_max, else response_band's top."""
    settings = scene.hydro
    if settings.nonlinear_omega_max is not None:
        return settings.nonlinear_omega_max
    return settings.response_band[1] if settings.response_band else DEFAULT_OMEGA_MAX


def _k_max(scene) -> float:
    return float(wavenumber(omega_max(scene), scene.water.depth, scene.water.g))


def _path(scene, topo, body, geometry) -> str:
    chosen = scene.hydro.nonlinear_path
    if chosen == "auto":
        return "analytic" if geometry["type"] == "sphere" else "panels"
    if chosen == "analytic" and geometry["type"] != "sphere":
        tree, k = topo.tree, topo.body_index(body.name)
        q = ca.SX.sym("q", tree.n_q)
        if ca.depends_on(ca.vec(tree.rotation(q, k)), q):
            raise SceneError(f"{scene.path}: [hydro] nonlinear_path = \"analytic\": body "
                             f"'{body.name}' can rotate, and the analytic path models the "
                             f"pressure moment of a sphere only; use nonlinear_path = \"panels\" "
                             f"(or \"auto\")")
    return chosen


def _drifts(topo, body) -> bool:
    """Whether the body's CoG can move horizontally (else the field needs no reach)."""
    tree, k = topo.tree, topo.body_index(body.name)
    q = ca.SX.sym("q", tree.n_q)
    return bool(ca.depends_on(tree.cog(q, k)[:2], q))


def _extent(points: np.ndarray) -> tuple[float, float]:
    """(horizontal half-width, vertical extent) of body points about the CoG, m."""
    return float(np.max(np.hypot(points[0], points[1]))), float(np.ptp(points[2]))


def _build(scene, body, geometry, path, waves: bool, k_max: float, drifts: bool) -> PressureBody:
    cog = np.asarray(body.cog, float)
    settings = scene.hydro
    panels = body_panels(geometry, cog, panel_size=settings.nonlinear_panel_size)
    half, height = _extent(panels.points)
    reach = settings.nonlinear_reach or (max(MIN_REACH_M, half) if drifts else FIXED_REACH_M)
    direction = settings.nonlinear_direction
    centre = np.asarray(geometry.get("center", cog), float)
    if path == "analytic":
        try:
            model = axisymmetric_model(geometry, cog, direction, half_width=reach, k_max=k_max,
                                       water_depth=scene.water.depth, g=scene.water.g)
        except HydroError as exc:
            raise SceneError(f"{scene.path}: [hydro] nonlinear_path: body '{body.name}': {exc}") \
                from None
        rows = model.n_rows if waves else 0
        calm = None if geometry["type"] == "sphere" else _calm_function(body.name, panels,
                                                                        scene.water)
        return PressureBody(body.name, path, model, None, rows, cog, centre, reach,
                            omega_max(scene), calm=calm, rest_potential=_rest(calm, cog))
    field = None
    if waves:
        # the deepest the stretched depth of a point gets: its depth at rest plus the body's
        # height and reach, and never past the sea bed
        depth_range = min(max(float(np.max(panels.points[2] + cog[2])), 0.0) + height + reach,
                          scene.water.depth)
        # along the sea: the body's extent at rest plus the reach (its motion, rotation
        # included); every point is checked against the box (LocalField.usage)
        along = float(np.max(np.abs(np.array([math.cos(direction), math.sin(direction)])
                                    @ panels.points[:2])))
        field = _field(cog, direction, along + reach, depth_range, k_max, scene.water)
    calm = _calm_function(body.name, panels, scene.water)
    return PressureBody(body.name, path, panels, field, field.n_rows if field else 0, cog,
                        centre, reach, omega_max(scene),
                        surface=_surface_function(body.name, panels, field, scene.water, False)
                        if field else None,
                        surface_range=_surface_function(body.name, panels, field, scene.water,
                                                        True) if field else None,
                        calm=calm, rest_potential=_rest(calm, cog))


def _rest(calm: ca.Function | None, cog) -> float:
    """Calm water's potential at rest (J), a number: the outputs subtract it, so it is not
    summed over the points at every sample."""
    return 0.0 if calm is None else float(calm(np.eye(3), cog)[2])


def _surface_function(name: str, panels, field: LocalField, water, ranged: bool) -> ca.Function:
    """The panel wrench in waves (and if `ranged` the most of the field's box a point uses)
    as one compiled call (mbcontrol.hydro.mesh.surface_sums)."""
    def pressure_of(rows):
        if ranged:
            return lambda x, y, z: field.pressure_and_usage(rows, x, y, z, water.rho, water.g)
        return lambda x, y, z: field.pressure(rows, x, y, z, water.rho, water.g)

    return pressure_wrench_function(panels, pressure_of, field.n_rows, f"pressure_wrench_{name}"
                                    + "_ranged" * ranged, largest=ranged)


def _calm_function(name: str, panels, water) -> ca.Function:
    return calm_water_function(panels, water.rho, water.g, f"calm_water_{name}")


def _field(cog, direction, half_width, depth_range, k_max, water) -> LocalField:
    """The fewest rows whose truncation per unit amplitude stays below FIELD_TOL at every
    wavenumber up to k_max (each direction's order grows only as its own tail needs)."""
    omega_max = math.sqrt(water.g * k_max * (math.tanh(k_max * water.depth)
                                              if math.isfinite(water.depth) else 1.0))
    return band_field(float(cog[0]), float(cog[1]), float(direction), float(half_width),
                      float(depth_range), np.linspace(omega_max / 20, omega_max, 40),
                      water_depth=water.depth, g=water.g, tol=FIELD_TOL, max_order=MAX_ORDER)


def _with_linear_fk(b: PressureBody, water) -> PressureBody:
    """Attach the wrench per row at rest (force; moment about the CoG; n-frame = body axes):
    the linear Froude-Krylov force of this surface model is linear_fk @ row coefficients."""
    if b.n_rows == 0:
        return b
    rows = ca.SX.sym("rows", b.n_rows)
    force, moment = b.wrench(rows, ca.DM.eye(3), ca.DM(b.cog), water.rho, water.g)
    jac = ca.Function("j", [rows], [ca.jacobian(ca.vertcat(force, moment), rows)])
    return dataclasses.replace(b, linear_fk=np.array(jac(np.zeros(b.n_rows))))


def linear_froude_krylov(bodies, omega, dofs) -> np.ndarray:
    """(n_omega, len(dofs)) complex linear Froude-Krylov force per unit amplitude of the
    surface models on the hydro DOFs `dofs` ("<body>__<Dof>"), body axes at the CoG."""
    out = np.zeros((np.size(omega), len(dofs)), complex)
    index = {d: i for i, d in enumerate(dofs)}
    for b in bodies:
        if b.n_rows == 0:
            continue
        per_dof = b.row_coefficients(omega) @ b.linear_fk.T          # (n_omega, 6)
        for j, dof in enumerate(DOF_NAMES):
            if f"{b.body}__{dof}" in index:
                out[:, index[f"{b.body}__{dof}"]] = per_dof[:, j]
    return out


def _posed(scene, topo, q, rows, bodies):
    """Per nonlinear body: (b, its scene body, body index, R, r_cog, its field rows)."""
    tree, start = topo.tree, 0
    for b in bodies:
        k = topo.body_index(b.body)
        yield b, scene.body(b.body), k, tree.rotation(q, k), tree.cog(q, k), \
            rows[start:start + b.n_rows] if b.n_rows else ca.DM.zeros(0)
        start += b.n_rows


def _wrench(b: PressureBody, mine, R, r_cog, calm, rho, g, ranged: bool):
    """(force, moment, range) of the pressure (n-frame, about the CoG): in waves on panels
    from one call, with the field's range if `ranged` (else None); calm: b.calm's outputs at
    the pose (panels)."""
    if b.surface is not None:
        if ranged:
            return tuple(b.surface_range.call([mine, R, r_cog]))
        return (*b.surface.call([mine, R, r_cog]), None)
    if b.path == "panels":                                  # calm water
        return calm[0], calm[1], None
    return (*b.wrench(mine, R, r_cog, rho, g), None)


def pressure_load(scene, topo, q, rows, bodies):
    """The generalised pressure and weight load of the nonlinear bodies (n_s, SX): what the
    plant's f needs, each surface summed once (its wrench alone; `pressure_loads` for the
    outputs)."""
    tree, rho, g = topo.tree, scene.water.rho, scene.water.g
    tau = ca.SX.zeros(tree.n_s)
    for b, body, k, R, r_cog, mine in _posed(scene, topo, q, rows, bodies):
        calm = b.calm.call([R, r_cog]) if b.path == "panels" and b.surface is None else None
        force, moment, _ = _wrench(b, mine, R, r_cog, calm, rho, g, ranged=False)
        force += ca.DM([0.0, 0.0, body.mass * g])                # weight acts at the CoG
        tau += tree.generalized_force(q, k, ca.vertcat(R.T @ force, R.T @ moment))
    return tau


def pressure_loads(scene, topo, q, s, rows, bodies):
    """(tau, potential, wave power, ranges) for the plant's outputs: the generalised pressure
    and weight loads of the nonlinear bodies; the calm-water potential relative to rest (J:
    hydrostatic and weight); the power the incident wave's pressure does beyond calm water's
    (W), for the energy audit; per body in waves, "<body>__field_range" (above 1 outside the
    field). Each surface is summed once: its outputs serve the load, the power and the range."""
    tree, rho, g = topo.tree, scene.water.rho, scene.water.g
    tau, tau_wave, energy, ranges = ca.SX.zeros(tree.n_s), ca.SX.zeros(tree.n_s), 0, {}
    for b, body, k, R, r_cog, mine in _posed(scene, topo, q, rows, bodies):
        calm = b.calm.call([R, r_cog]) if b.path == "panels" else None
        force, moment, largest = _wrench(b, mine, R, r_cog, calm, rho, g, ranged=True)
        force += ca.DM([0.0, 0.0, body.mass * g])                # weight acts at the CoG
        tau += tree.generalized_force(q, k, ca.vertcat(R.T @ force, R.T @ moment))
        if b.n_rows:                 # the wave's part: what the pressure adds to calm water's
            still, still_moment = calm[:2] if calm else b.wrench(ca.DM.zeros(b.n_rows), R,
                                                                  r_cog, rho, g)
            tau_wave += tree.generalized_force(q, k, ca.vertcat(
                R.T @ (force - still), R.T @ (moment - still_moment)))
            ranges[f"{b.body}__field_range"] = largest if largest is not None \
                else field_range(b, mine, R, r_cog)
        energy += _calm_potential(b, body, R, r_cog, rho, g, calm[2] if calm else None) \
            - body.mass * g * (r_cog[2] - b.cog[2])
    return tau, energy, ca.dot(tau_wave, s), ranges


def field_range(b: PressureBody, rows, R, r_cog):
    """How much of its incident field's box a body on the analytic path uses (dimensionless;
    above 1 it is outside and the series hold their edge values): the centre's offset along
    the sea over the half-width, or its depth below the local surface over the deepest the
    series cover. (Panels: the most any point uses, `LocalField.usage`, from b.surface.)"""
    along = ca.DM([math.cos(b.model.direction), math.sin(b.model.direction)])
    centre = r_cog + ca.mtimes(R, ca.DM(b.centre - b.cog))
    xi = ca.dot(along, centre[:2] - ca.DM(b.centre[:2])) / b.model.half_width
    previous, current, eta = 1, xi, rows[0]       # eta at the axis: Chebyshev rows in xi
    for m in range(1, b.model.n_xi):
        eta += rows[m] * current
        previous, current = current, 2 * xi * current - previous
    deepest = b.model.pieces[-1][1]
    return ca.fmax(ca.fabs(xi), (centre[2] + eta) / deepest)


def _calm_potential(b: PressureBody, body, R, r_cog, rho, g, now=None):
    """rho g int_wet z dV (J) in calm water, relative to rest: exact for a sphere, else the
    panel rule's rho g sum max(z, 0)^2 / 2 n_z (the wet volume closed by the plane z = 0,
    where the integrand vanishes); `now`, the panel rule's value at the pose if known."""
    geometry = geometry_dict(body.geometry)
    if geometry["type"] == "sphere":
        now = primitive_potential(geometry, b.cog, R, r_cog, rho, g)
        rest = primitive_potential(geometry, b.cog, np.eye(3), b.cog, rho, g)
        return now - float(rest)
    return (b.calm.call([R, r_cog])[2] if now is None else now) - b.rest_potential


def field_names(bodies) -> list[str]:
    """Disturbance names of the field rows, in w's order after the excitation."""
    return [f"w__field_{b.body}_{i}" for b in bodies for i in range(b.n_rows)]


def check_wave(plant, wave) -> None:
    """Refuse a sea the field was not built for: short-crested, or from another direction."""
    where = f"{plant.scene.path}: [hydro] froude_krylov = \"nonlinear\""
    if wave.directional:
        raise WaveError(f"{where}: the incident field is long-crested; a spread sea "
                        f"(--spread) is not supported with nonlinear Froude-Krylov forces yet")
    built = plant.scene.hydro.nonlinear_direction
    if abs(math.remainder(float(wave.direction) - built, 2 * math.pi)) > 1e-9:
        raise WaveError(f"{where}: the field is built for waves travelling to {built:.6g} rad "
                        f"([hydro] nonlinear_direction); this sea travels to "
                        f"{float(wave.direction):.6g} rad. Set nonlinear_direction to it")


def wave_coefficients(plant, wave) -> np.ndarray:
    """`ProcessPlant.wave_coefficients` with nonlinear Froude-Krylov forces: the BEM excitation
    less the surface models' linear Froude-Krylov force, then the field's rows. Kept per
    frequency grid and direction (closed forms per component: a run asks again for its last
    output sample, and seeds of a sea share them)."""
    from .workspace import derived
    omega = np.ascontiguousarray(wave.omega, float)
    kept = derived(plant, ("plant.nonlinear.wave_coefficients",), dict)
    key = (hashlib.sha256(omega.tobytes() + np.asarray(wave.direction, float).tobytes())
           .hexdigest(), omega.size)
    if key not in kept:
        check_wave(plant, wave)
        coeffs = plant.hydro.excitation_at(wave.omega, wave.direction)
        dofs = [d[len("w__"):] for d in plant.disturbances[:coeffs.shape[1]]]
        coeffs = coeffs - linear_froude_krylov(plant.pressure, wave.omega, dofs)
        if len(kept) >= WAVE_GRIDS_KEPT:
            kept.clear()
        rows = np.hstack([coeffs] + [b.row_coefficients(wave.omega)
                                     for b in plant.pressure if b.n_rows])
        rows.setflags(write=False)                      # shared by every run that asks
        kept[key] = rows
    return kept[key]
