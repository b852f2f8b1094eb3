"""ProcessPlant: the scene's nonlinear equations of motion as CasADi Functions.

    q' = K(q) s
    M^g(q) s' = -C^g(q,s) s - mu^g - restoring + P tau_exc + PTO + friction + mooring + drag
    chi' = A_r chi + B_r nu_h ,  mu_h = C_r chi + D_r nu_h ,  nu_h = (P^T s)[hydro DOFs]

with M^g = P (M_RB + A_inf) P^T (ERRATA section 4). The state is x = [q, s, chi]; inputs are
u (one force command per PTO) and w (the excitation wrench on each hydro DOF, body axes at the
CoG); parameters p (PTO, friction, mooring, drag coefficients) stay symbolic.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..errors import UnknownName
from ..hydro import Device, HydroModel, RadiationModel, load_hydro_model, with_displaced_masses
from ..multibody import Topology, build_topology
from ..scene import DOF_NAMES, Scene, load_scene
from . import checks, loads, nonlinear
from .held_pressure import HeldPressure, held_pressure
from .mechanical import dof_selector, mechanical_matrices
from .moordyn_loads import (coupled_points, moordyn_loads, moordyn_names, moored_rest,
                            say_moored_rest)
from .ownership import linear_params
from .pieces import (kinetic_energy, momentum_value, plant_parts, radiation_as_data,
                     radiation_value, sparse_constant)
from .rest import preloads
from .units import DRIVETRAIN_SIGNALS, drivetrain_signals, signal_unit


@dataclass(frozen=True, eq=False)      # identity semantics: derived data is kept per plant
class ProcessPlant:
    """x' = f(x, u, w, p), y = h(x, u, w, p) with named signals; built once, immutable."""
    scene: Scene
    topology: Topology
    hydro: HydroModel | None
    states: tuple[str, ...]
    inputs: tuple[str, ...]          # u: PTO force commands (N or N m)
    disturbances: tuple[str, ...]    # w: excitation on each hydro DOF (N or N m, body axes)
    outputs: tuple[str, ...]
    parameters: tuple[str, ...]
    p0: np.ndarray
    f: ca.Function = field(repr=False)
    h: ca.Function = field(repr=False)
    notes: dict = field(default_factory=dict)   # build-time findings (plant.checks.rest_checks)
    parts: dict | None = field(default=None, repr=False)    # f's pieces (module plant.pieces)
    # nonlinear hydrostatics and Froude-Krylov bodies (module plant.nonlinear); their field
    # rows follow the excitation in w
    pressure: tuple = field(default=(), repr=False)
    # [hydro] nonlinear_update = "step": f with the pressure load held (module plant.held_pressure)
    held: HeldPressure | None = field(default=None, repr=False)
    # MoorDyn moorings' Coupled points: their forces follow the field rows in w
    moordyn: tuple = field(default=(), repr=False)
    # the rest state when it is not the scene's pose (MoorDyn lines' pull: moordyn_loads)
    rest: np.ndarray | None = field(default=None, repr=False)
    # derived data and compiled code, freed with the plant (module plant.workspace)
    workspace: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def __getstate__(self):               # a pickled plant travels without its compiled code
        return {**self.__dict__, "workspace": {}}

    @property
    def name(self) -> str:
        return self.scene.name

    def units(self, signal: str) -> str:
        """SI unit of a named state, input, disturbance or output."""
        return signal_unit(self, signal)

    @property
    def nx(self) -> int:
        return len(self.states)

    @property
    def n_q(self) -> int:
        return self.topology.tree.n_q

    def x0(self) -> np.ndarray:
        """The rest state: still water, all bodies at their scene pose, or where MoorDyn lines'
        pull holds them (plant.moordyn_loads.moored_rest)."""
        return np.zeros(self.nx) if self.rest is None else self.rest.copy()

    def params(self, **overrides) -> np.ndarray:
        """Parameter vector with named overrides, e.g. params(hinge_pto__damping=3.0)."""
        p = self.p0.copy()
        for key, value in overrides.items():
            if key not in self.parameters:
                raise UnknownName(f"{self.name}: unknown parameter {key!r}; known: "
                                  f"{', '.join(self.parameters)}")
            p[self.parameters.index(key)] = value
        return p

    def excitation(self, wave, t) -> np.ndarray:
        """Excitation w(t) (len(t), n_w) of a wave on this plant's hydro DOFs (and the wave
        field's rows, with nonlinear Froude-Krylov forces)."""
        if self.hydro is None:
            return np.zeros((np.size(t), len(self.disturbances)))
        if not self.wave_rows:
            return self.padded(self.hydro.excitation(wave, t))
        from ..waves import coefficient_series
        return coefficient_series(wave, self.wave_coefficients(wave), np.atleast_1d(t))

    def padded(self, rows: np.ndarray) -> np.ndarray:
        """rows (..., n) of the wave's part of w, with zero columns for the rows the wave does
        not drive (MoorDyn's point forces, filled as a run steps)."""
        missing = len(self.disturbances) - rows.shape[-1]
        if missing <= 0:
            return rows
        return np.concatenate([rows, np.zeros(rows.shape[:-1] + (missing,), rows.dtype)], -1)

    @property
    def wave_rows(self) -> int:
        """Rows of w that carry the incident field (nonlinear Froude-Krylov), after the
        excitation's."""
        return sum(b.n_rows for b in self.pressure)

    def wave_coefficients(self, wave) -> np.ndarray:
        """(n_components, n_w) complex rows of w per unit amplitude, exp(-i omega t): the BEM
        excitation on the hydro DOFs, less the surface model's linear Froude-Krylov force when
        that force is nonlinear (the plant computes it), then the wave field's rows."""
        if not self.wave_rows:
            return self.padded(self.hydro.excitation_at(wave.omega, wave.direction))
        return self.padded(nonlinear.wave_coefficients(self, wave))


def assemble_plant(scene: Scene | str, hydro: HydroModel | None = None, *,
                   radiation_tol: float | None = None, radiation: bool = True,
                   hydro_corrections: bool = False) -> ProcessPlant:
    """The full process plant of a scene (a Scene, a scene file or a catalogue name).

    Hydrodynamics come from `hydro` or the scene's hydro.file; the radiation model is fitted
    to `radiation_tol` (default: the scene's) on the DOFs the joints can move. With
    radiation=False the plant has no radiation states: w is then the whole wave load on the
    hydro DOFs (excitation minus radiation memory), as a direct-convolution reference needs.
    hydro_corrections: per hydro DOF d, parameters d__added_mass_scale, d__radiation_scale and
    d__excitation_scale (1: the BEM data, dimensionless) scale A(inf) and the radiation kernel
    (B(omega) and A(omega) - A(inf) together) as S^1/2 X S^1/2, so they stay symmetric and the
    radiation passive, and the excitation force on d; for identification. Users call
    `mbcontrol.plant.build_plant`, which also builds simplified models.
    """
    scene, topo, hydro_dofs = _resolved(load_scene(scene) if not isinstance(scene, Scene) else scene)
    tree = topo.tree
    q, s = ca.SX.sym("q", tree.n_q), ca.SX.sym("s", tree.n_s)
    u = ca.SX.sym("u", len(scene.ptos))

    if hydro is None and hydro_dofs:
        judged = scene.hydro.fit_judged_by == "response"
        hydro = load_hydro_model(scene, hydro_dofs, tol=radiation_tol, device=(
            lambda source, data: device_around(scene, source, data, hydro_dofs)) if judged else None)
    elif hydro is not None:
        hydro = hydro.restricted(hydro_dofs)
    n_w = len(hydro_dofs)
    n_r = hydro.radiation.A.shape[0] if hydro and radiation else 0
    pressure = nonlinear.pressure_bodies(scene, topo, hydro)
    moored = coupled_points(scene, topo)                  # MoorDyn's Coupled points
    n_f = sum(b.n_rows for b in pressure)
    w = ca.SX.sym("w", n_w + n_f + sum(g.rows for g in moored))
    chi = ca.SX.sym("chi", n_r)

    params = loads.Parameters()
    P = tree.P(q)
    select = dof_selector(topo, hydro_dofs)                  # 6N -> hydro DOFs
    scale = _hydro_scales(params, hydro_dofs) if hydro and hydro_corrections else None
    added_mass, hydro_force, chi_dot, power, radiation_apart = _hydro_loads(
        hydro, radiation, scale, select, P, s, w[:n_w], chi)
    tau = -tree.bias(q, s, added_mass)
    if hydro_force is not None:
        tau += hydro_force
    slot = ca.SX.sym("tau_p", tree.n_s)    # the hydrostatic (pressure) load's place in tau
    tau, potential, pto_signals, tensions, (wave_power, ranges), restoring = _body_loads(
        tau, scene, topo, hydro, (q, s, u, w[n_w:n_w + n_f], slot), params, pressure)
    power["excitation_power"] += wave_power
    lines_pull = 0          # MoorDyn lines' quasi-static part: after the balance of weight
    if moored:              # and buoyancy (plant.rest), which it moves (moored_rest)
        lines_pull, tau_md, power["mooring_power"] = moordyn_loads(topo, q, s, w[n_w + n_f:],
                                                                   moored)
        tau += tau_md
    # f sums each surface for its wrench alone; the outputs (restoring) also for its range
    load = nonlinear.pressure_load(scene, topo, q, w[n_w:n_w + n_f], pressure) if pressure \
        else restoring
    # a farm's radiation force is the symbol mu_r in tau (module plant.pieces: the outputs are
    # also compiled with the force as data); f, h and the checks see its value C_r chi
    actual = radiation_value(radiation_apart, chi)
    tau_full = actual(ca.substitute(tau, slot, load))
    extra, balance = preloads(scene, topo, (q, s, u, w, chi, tau_full), pto_signals, params,
                              hydro.buoyancy(scene.water) if hydro else {})
    tau, tau_full = tau + extra + lines_pull, tau_full + extra + lines_pull

    M = tree.mass_matrix(q, added_mass)
    notes = checks.rest_checks(scene, topo, q, s, u, w, chi, tau_full, M, params)
    notes["rest_balance"] = balance        # weight against buoyancy, what preloads hold (plant.rest)
    x = ca.vertcat(q, s, chi)
    x_dot_apart = ca.vertcat(ca.mtimes(tree.K(q), s), ca.solve(M, tau), chi_dot)
    x_dot_slot = actual(x_dot_apart)
    x_dot = ca.substitute(x_dot_slot, slot, load)
    kinetic, momentum = kinetic_energy(s, M, radiation_apart, ca.vertcat(q, params.vector))
    power["energy"], p = kinetic + potential, params.vector
    y_apart, output_names = _outputs(scene, topo, q, s, pto_signals, power, tensions,
                                     x_dot_apart[tree.n_q:tree.n_q + tree.n_s], ranges)
    y_apart = ca.substitute(y_apart, slot, restoring)
    y = momentum_value(actual(y_apart), momentum, M, s)
    held = held_pressure([x, u, w, p], q, slot, x_dot_slot, load) \
        if pressure and scene.hydro.nonlinear_update == "step" else None

    coords = list(tree.coordinate_names)
    states = coords + [f"{c}__vel" for c in coords] + [f"radiation_{i}" for i in range(n_r)]
    inputs = [f"u__{pto.name}" for pto in scene.ptos]
    disturbances = [f"w__{d}" for d in hydro_dofs] + nonlinear.field_names(pressure) \
        + moordyn_names(moored)
    f = ca.Function("f", [x, u, w, p], [x_dot], ["x", "u", "w", "p"], ["xdot"])
    h = ca.Function("h", [x, u, w, p], [y], ["x", "u", "w", "p"], ["y"])
    rest = moored_rest(scene, f, (tree.n_q, tree.n_s, len(states), u.shape[0], w.shape[0]),
                       np.array(params.values)) if moored else None
    if moored:
        notes["moored_rest"] = say_moored_rest(scene, states, rest)
    parts = plant_parts([x, u, w, p], M, tau_full, x_dot[:tree.n_q], chi_dot, radiation_apart,
                        (y_apart, momentum))
    return ProcessPlant(scene, topo, hydro, tuple(states), tuple(inputs), tuple(disturbances),
                        tuple(output_names), tuple(params.names), np.array(params.values),
                        f, h, notes, parts, pressure, held, moored, rest)


def _hydro_loads(hydro, radiation, scale, select, P, s, w, chi):
    """Added mass A(inf) on the coordinates, the wave-minus-radiation force (or None), chi',
    the radiated and excitation powers (W), what plant.pieces compiles apart."""
    chi_dot, power = ca.SX(0, 1), {"radiated_power": 0, "excitation_power": 0}
    if not hydro:
        return None, None, chi_dot, power, None
    # constants as sparse matrices: their explicit zeros would cost a farm's build (A_r alone
    # has n_r^2 entries) without changing an expression (CasADi drops products with zeros)
    sel = sparse_constant(select)
    if scale is None:
        added_mass = sparse_constant(select.T @ hydro.added_mass_inf @ select)
    else:
        A_inf = ca.mtimes([scale["added_mass"], ca.DM(hydro.added_mass_inf), scale["added_mass"]])
        added_mass = ca.mtimes([ca.DM(select.T), A_inf, ca.DM(select)])
    nu_h = ca.mtimes(sel, ca.mtimes(P.T, s))
    w_h = w if scale is None else ca.mtimes(scale["excitation"], w)
    if not radiation:
        return (added_mass, ca.mtimes(P, ca.mtimes(sel.T, w_h)), chi_dot,
                {"radiated_power": 0, "excitation_power": ca.dot(nu_h, w_h)}, None)
    matrices = hydro.radiation_matrices()
    A_r, B_r, C_r, D_r = (sparse_constant(m) for m in matrices)
    apart, force = None, ca.mtimes(C_r, chi)
    if scale is None:
        # a farm's C_r chi as the symbol mu_r (its value is put back by pieces.radiation_value)
        mu_r = ca.SX.sym("mu_r", C_r.shape[0]) if radiation_as_data(matrices[2]) else None
        force = force if mu_r is None else mu_r
        apart = (chi, ca.mtimes(P, sel.T), nu_h, matrices, mu_r)
    R = scale["radiation"] if scale is not None else ca.DM.eye(select.shape[0])
    nu_r = ca.mtimes(R, nu_h)           # the kernel S^1/2 K S^1/2 as a state-space model
    mu_h = ca.mtimes(R, force + ca.mtimes(D_r, nu_r))
    chi_dot = ca.mtimes(A_r, chi) + ca.mtimes(B_r, nu_r)
    return (added_mass, ca.mtimes(P, ca.mtimes(sel.T, w_h - mu_h)), chi_dot,
            {"radiated_power": ca.dot(nu_h, mu_h), "excitation_power": ca.dot(nu_h, w_h)}, apart)


def _body_loads(tau, scene, topo, hydro, symbols, params, pressure):
    """tau plus the symbol `slot` in the hydrostatic load's place, PTOs, friction, drag,
    moorings, end stops, gravity, static loads (in this order: the compiled code stays the
    same); the potential (J: hydrostatic with the static loads' own, drivetrain springs,
    moorings, end stops, gravity), PTO signals, mooring tensions, (the power of the nonlinear
    incident pressure beyond calm water's, W; the bodies' field ranges,
    plant.nonlinear.field_range), and the hydrostatic load that `slot` stands for."""
    q, s, u, rows, slot = symbols
    wave = (0, {})
    if scene.hydro.hydrostatics == "nonlinear":
        restoring, potential, *wave = nonlinear.pressure_loads(scene, topo, q, s, rows, pressure)
    elif scene.hydro.hydrostatics == "large_angle":
        restoring, potential = loads.large_angle_hydrostatics(scene, topo, q)
    else:
        restoring, potential = loads.restoring_forces(topo, q, hydro.stiffness_by_body() if hydro
                                                      else {})
    tau += slot
    tau_pto, pto_signals = loads.pto_forces(scene, topo, q, s, u, params)
    tau += tau_pto + loads.friction_forces(scene, topo, s, params)
    potential += loads.drivetrain_spring_energy(scene, pto_signals)
    tau += loads.drag_forces(scene, topo, q, s, params)
    tau_moor, mooring_energy, tensions = loads.mooring_forces(scene, topo, q, s, params)
    tau += tau_moor
    potential += mooring_energy
    for conservative in (loads.end_stop_forces(scene, topo, q, s, params),
                         loads.gravity_forces(scene, topo, q)):
        tau += conservative[0]
        potential += conservative[1]
    if scene.hydro.hydrostatics == "linear":
        tau_static, static_energy = loads.static_loads(scene, topo, q, hydro.buoyancy(scene.water)
                                                       if hydro else {})
        tau += tau_static
        potential += static_energy
    return tau, potential, pto_signals, tensions, wave, restoring


def _hydro_scales(params, dofs) -> dict:
    """Diagonal CasADi matrices of the square roots of the per-DOF hydro scale parameters."""
    out = {}
    for kind in ("added_mass", "radiation", "excitation"):
        values = [params.add(f"{d}__{kind}_scale", 1.0) for d in dofs]
        roots = values if kind == "excitation" else [ca.sqrt(v) for v in values]
        out[kind] = ca.diag(ca.vertcat(*roots))
    return out


def _resolved(scene: Scene):
    """(scene, its topology, its hydro DOFs), each mass = "displaced" body without geometry given
    rho x its BEM body's displaced volume (mbcontrol.hydro.with_displaced_masses); the joints'
    kinematics, hence the DOFs, do not depend on the masses."""
    topo = build_topology(scene)
    hydro_dofs = active_hydro_dofs(scene, topo)
    resolved = with_displaced_masses(scene, hydro_dofs)
    return (scene, topo, hydro_dofs) if resolved is scene else (resolved, build_topology(resolved), hydro_dofs)


def active_hydro_dofs(scene: Scene, topo: Topology) -> list[str]:
    """Body DOFs ("<body>__<Dof>") of hydro bodies that the joints let move.

    A DOF is active when its column of P(q) is non-zero at some configuration; probing random
    configurations finds every column that is not identically zero.
    """
    tree = topo.tree
    q = ca.SX.sym("q", tree.n_q)
    P_fun = ca.Function("P", [q], [tree.P(q)])
    rng = np.random.default_rng(12345)
    norms = sum(np.abs(np.array(P_fun(rng.uniform(-0.5, 0.5, tree.n_q)))) for _ in range(4))
    moving = norms.sum(axis=0) > 1e-12 if tree.n_q else np.zeros(6 * len(topo.bodies), bool)
    dofs = []
    for k, name in enumerate(topo.bodies):
        if scene.body(name).hydro:
            dofs += [f"{name}__{d}" for i, d in enumerate(DOF_NAMES) if moving[6 * k + i]]
    return dofs


def _outputs(scene, topo: Topology, q, s, pto_signals, power, tensions, s_dot, ranges):
    tree = topo.tree
    q_rest = ca.DM.zeros(tree.n_q)
    values, names = [q, s], list(tree.coordinate_names) + [f"{c}__vel" for c in
                                                          tree.coordinate_names]
    for k, body in enumerate(topo.bodies):
        displacement = tree.cog(q, k) - tree.cog(q_rest, k)
        values += [displacement, loads.euler_zyx(tree.rotation(q, k))]
        names += [f"{body}__{dof}" for dof in DOF_NAMES]
    drivetrains = {p.name: p.drivetrain for p in scene.ptos if p.drivetrain is not None}
    for pto, (position, velocity, force, direction) in pto_signals.items():
        values += [position, velocity, force, -force * velocity]
        names += [f"{pto}__position", f"{pto}__velocity", f"{pto}__force", f"{pto}__power"]
        if pto in drivetrains:
            values += drivetrain_signals(drivetrains[pto], position, velocity, force,
                                         ca.dot(direction, s_dot))
            names += [f"{pto}__{kind}" for kind in DRIVETRAIN_SIGNALS]
    # energy audit: radiated (W, leaving the bodies), wave input (W), and the mechanical energy
    # (J): kinetic (drivetrain inertia included) + hydrostatic, gravity (dry bodies), mooring,
    # end-stop and drivetrain shaft-spring potentials; PTO forces, the scene law's springs
    # included, are external: their power is <pto>__power
    values += [power["radiated_power"], power["excitation_power"], power["energy"]]
    names += ["radiated_power", "excitation_power", "energy"]
    if "mooring_power" in power:         # what MoorDyn's lines put into the bodies
        values.append(power["mooring_power"])
        names.append("mooring_power")
    for line, signals in tensions.items():
        values += list(signals)
        names += [f"{line}__tension", f"{line}__span", f"{line}__height"]
    values += list(ranges.values())        # "<body>__field_range" (plant.nonlinear.field_range)
    names += list(ranges)
    return ca.vertcat(*values), names


def device_around(scene, source: str, data, dofs) -> Device:
    """The device a radiation fit of ``data`` on ``dofs`` sits in: the scene's plant without
    radiation states, linear at rest, seen from its PTOs (their own damping and stiffness zero,
    Coulomb friction removed: `linear_params`), with its joints' stiffness and its drivetrains,
    and the data's excitation at every heading."""
    n = len(dofs)
    none = RadiationModel(A=np.zeros((0, 0)), B=np.zeros((0, n)), C=np.zeros((n, 0)), D=np.zeros((n, n)),
                          dofs=tuple(dofs), order=0, fit_error=0.0, entry_errors=np.zeros((n, n)))
    plant = assemble_plant(scene, HydroModel(tuple(dofs), data, none, source), radiation=False)
    mech = mechanical_matrices(plant, linear_params(plant, [pto.name for pto in scene.ptos]))
    excitation = data["excitation_force"].sel(influenced_dof=list(dofs)).transpose(
        "wave_direction", "omega", "influenced_dof").values
    return Device(tuple(plant.topology.tree.coordinate_names), tuple(dofs), mech.mass + mech.added_mass_inf,
                  mech.damping, mech.stiffness, mech.P_hydro, excitation, data["omega"].values,
                  data["wave_direction"].values, scene.hydro.response_band)


def response_error_of(plant) -> dict | None:
    """The response error (module hydro.fit.response_error) of the plant's radiation fit, whatever
    judged it: {"error", "omega", "weight", "what"} at the worst fitted frequency, on the data the
    fit saw (its band, BEM reciprocity as it applied it), the device at rest with its PTOs free.
    None for a plant without radiation states."""
    from ..hydro import response_error_on
    hydro = plant.hydro
    if hydro is None or hydro.radiation.order == 0:
        return None
    rad = hydro.radiation
    device = device_around(plant.scene, hydro.source, hydro.data, list(rad.dofs))
    return response_error_on(device, hydro.data, rad, rad.report["omega_fit"][1])
