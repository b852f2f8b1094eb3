"""Active loads as CasADi expressions of (q, s) and symbolic parameters.

Each function returns a generalised force (n_s vector, conjugate to s) and registers its
parameters in a `Parameters` collection, so that tuning, sweeps and identification change
numbers without rebuilding the plant. Sign conventions (DESIGN.md): the load a PTO applies to
its follower (the joint's child) is -(c v + k x) + u; absorbed power is P = -F v.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..multibody import Topology
from ..scene import DOF_NAMES, Scene


@dataclass
class Parameters:
    """Named symbolic parameters with their nominal values."""
    names: list[str] = field(default_factory=list)
    values: list[float] = field(default_factory=list)
    symbols: list = field(default_factory=list)

    def add(self, name: str, value: float) -> ca.SX:
        sym = ca.SX.sym(name)
        self.names.append(name)
        self.values.append(float(value))
        self.symbols.append(sym)
        return sym

    @property
    def vector(self) -> ca.SX:
        return ca.vertcat(*self.symbols) if self.symbols else ca.SX(0, 1)


def pto_forces(scene: Scene, topo: Topology, q, s, u, params: Parameters):
    """Generalised PTO force and, per PTO, its (position, velocity, force, force map).

    Joint PTOs act on their coordinate; point-to-point PTOs along the line between their two
    points (x: change of distance, m; equal and opposite forces on the two bodies). The force
    map takes a scalar PTO force to the generalised force (used for preloads). A drivetrain
    adds its friction and shaft stiffness here, gear^2 (b v + K x), and its inertia to the
    tree's coordinate inertia (so every mass matrix taken from the tree afterwards holds it);
    the force stays the machine's.
    """
    tau = ca.SX.zeros(topo.tree.n_s)
    signals = {}
    topo.tree.coordinate_inertia[:] = 0.0           # set afresh by each call
    for i, pto in enumerate(scene.ptos):
        c = params.add(f"{pto.name}__damping", pto.damping)
        k = params.add(f"{pto.name}__stiffness", pto.stiffness)
        if pto.between_points:
            x, v, direction = _line(topo, q, s, pto)
        else:
            j = topo.coordinate_of_joint[pto.joint]
            x, v, direction = q[j], s[j], ca.SX.zeros(topo.tree.n_s)
            direction[j] = 1.0
        force = -(c * v + k * x) + u[i]
        tau += direction * force
        if pto.drivetrain is not None:   # the machine's friction and shaft spring, geared
            d = pto.drivetrain
            tau -= direction * d.gear_ratio ** 2 * (d.friction * v + d.stiffness * x)
            if pto.drivetrain.inertia:
                topo.tree.coordinate_inertia[topo.coordinate_of_joint[pto.joint]] += \
                    pto.drivetrain.gear_ratio ** 2 * pto.drivetrain.inertia
        signals[pto.name] = (x, v, force, direction)
    return tau, signals


def drivetrain_spring_energy(scene: Scene, signals) -> ca.SX:
    """The potential energy of the drivetrains' shaft springs, sum gear^2 K x^2 / 2 (J), from
    pto_forces' signals: the drivetrain is part of the plant (its inertia is in the kinetic
    energy, its friction in <pto>__friction_loss)."""
    energy = ca.SX(0)
    for pto in scene.ptos:
        if pto.drivetrain is not None and pto.drivetrain.stiffness:
            x = signals[pto.name][0]
            energy += 0.5 * pto.drivetrain.gear_ratio ** 2 * pto.drivetrain.stiffness * x * x
    return energy


def _line(topo: Topology, q, s, pto):
    """Stroke (m), stroke rate (m/s) and generalised direction of a point-to-point PTO.

    The direction d satisfies: generalised force = d * F for a tension-positive force F
    pushing the follower away from the parent point, and stroke rate = d^T s.
    """
    tree = topo.tree
    ends = []
    for body, point in ((pto.body, pto.point), (pto.parent, pto.parent_point)):
        if body == "ground":
            ends.append((None, ca.DM(point), None))
        else:
            k = topo.body_index(body)
            local = np.asarray(point) - topo.origin(body)
            ends.append((k, tree.point(q, k, local), local))
    (k1, p1, local1), (k2, p2, local2) = ends
    delta = p1 - p2
    length = ca.norm_2(delta)
    rest = float(np.linalg.norm(np.subtract(pto.point, pto.parent_point)))
    e = delta / length
    direction = tree.point_force(q, k1, local1, e)
    if k2 is not None:
        direction -= tree.point_force(q, k2, local2, e)
    return length - rest, ca.dot(direction, s), direction


def friction_forces(scene: Scene, topo: Topology, s, params: Parameters):
    """Joint friction: viscous plus Coulomb smoothed by tanh(v / velocity_scale)."""
    tau = ca.SX.zeros(topo.tree.n_s)
    for fr in scene.frictions:
        j = topo.coordinate_of_joint[fr.joint]
        viscous = params.add(f"{fr.name}__viscous", fr.viscous)
        coulomb = params.add(f"{fr.name}__coulomb", fr.coulomb)
        tau[j] -= viscous * s[j] + coulomb * ca.tanh(s[j] / fr.velocity_scale)
    return tau


def end_stop_forces(scene: Scene, topo: Topology, q, s, params: Parameters):
    """One-sided spring-dampers at joint travel limits: beyond a stop by d > 0 the joint feels
    max(k d + c v_in, 0) pushing it back (v_in: speed into the stop), never a pull.
    Returns (generalised force, spring energy 1/2 k d² stored in engaged stops, J)."""
    tau, energy = ca.SX.zeros(topo.tree.n_s), 0
    for stop in scene.end_stops:
        j = topo.coordinate_of_joint[stop.joint]
        k = params.add(f"{stop.name}__stiffness", stop.stiffness)
        c = params.add(f"{stop.name}__damping", stop.damping)
        if np.isfinite(stop.upper):
            d = q[j] - stop.upper
            tau[j] -= ca.if_else(d > 0, ca.fmax(k * d + c * s[j], 0), 0)
            energy += ca.if_else(d > 0, 0.5 * k * d**2, 0)
        if np.isfinite(stop.lower):
            d = stop.lower - q[j]
            tau[j] += ca.if_else(d > 0, ca.fmax(k * d - c * s[j], 0), 0)
            energy += ca.if_else(d > 0, 0.5 * k * d**2, 0)
    return tau, energy


def mooring_forces(scene: Scene, topo: Topology, q, s, params: Parameters):
    """Mooring loads mapped through P(q) at each fairlead.

    Linear moorings: spring-dampers from the fairlead's rest position along the n-frame axes.
    Catenary lines: the quasi-static line tension at the fairlead's current position
    (mbcontrol.plant.catenary: a table of the exact solution refined by Newton steps, compiled
    with the plant). Returns (generalised force, spring energy 1/2 Σ k_a d_a² of the linear
    moorings (J; a catenary's elastic and gravity energy is not included), {line: (tension (N),
    fairlead's horizontal distance from the anchor (m), its height above it (m))}).
    """
    from .catenary_line import catenary_line

    tree, tau, energy, tensions = topo.tree, ca.SX.zeros(topo.tree.n_s), 0, {}
    q_rest = ca.DM.zeros(tree.n_q)
    for m in scene.moorings:
        k = topo.body_index(m.body)
        local = np.asarray(m.point) - topo.origin(m.body)      # body axes = n axes at rest
        if m.kind == "catenary":
            fairlead = tree.point(q, k, local)
            force, tension = catenary_line(m).force_function()(fairlead)
            tau += tree.point_force(q, k, local, force)
            span = ca.norm_2(fairlead[:2] - ca.DM(m.anchor[:2]))
            tensions[m.name] = (tension, span, m.anchor[2] - fairlead[2])
            continue
        stiffness = ca.vertcat(*[params.add(f"{m.name}__stiffness_{a}", v)
                                 for a, v in zip("xyz", m.stiffness)])
        damping = ca.vertcat(*[params.add(f"{m.name}__damping_{a}", v)
                               for a, v in zip("xyz", m.damping)])
        displacement = tree.point(q, k, local) - tree.point(q_rest, k, local)
        velocity = tree.point_velocity(q, s, k, local)
        force = -(stiffness * displacement + damping * velocity)
        tau += tree.point_force(q, k, local, force)
        energy += 0.5 * ca.dot(stiffness, displacement**2)
    return tau, energy, tensions


def drag_forces(scene: Scene, topo: Topology, q, s, params: Parameters):
    """Quadratic drag -c|nu|nu on each listed DOF of the body's CoG twist (body axes)."""
    tree, tau = topo.tree, ca.SX.zeros(topo.tree.n_s)
    nu = tree.body_velocity(q, s)
    for d in scene.drags:
        k = topo.body_index(d.body)
        wrench = ca.SX.zeros(6)
        for dof, value in d.coefficients.items():
            i = DOF_NAMES.index(dof)
            c = params.add(f"{d.name}__{dof}", value)
            v = nu[6 * k + i]
            wrench[i] -= c * ca.fabs(v) * v
        for dof, value in d.linear.items():
            i = DOF_NAMES.index(dof)
            b = params.add(f"{d.name}__{dof}_linear", value)
            wrench[i] -= b * nu[6 * k + i]
        tau += tree.generalized_force(q, k, wrench)
    return tau


def restoring_forces(topo: Topology, q, stiffness_by_body: dict):
    """Generalised restoring force -K^T dV/dq of V = sum_k 1/2 dxi_k^T G_k dxi_k.

    dxi_k = [CoG displacement (n axes); ZYX Euler angles of body k] from the rest pose and G_k
    is the body's 6x6 hydrostatic stiffness at its CoG. The Hessian of V at rest is
    P0 G^b P0^T (ERRATA section 3); away from rest the kinematics stay exact, so the restoring
    load is conservative and energy checks balance.
    """
    tree = topo.tree
    q_rest = ca.DM.zeros(tree.n_q)
    potential = 0
    for name, G in stiffness_by_body.items():
        k = topo.body_index(name)
        dxi = ca.vertcat(tree.cog(q, k) - tree.cog(q_rest, k), euler_zyx(tree.rotation(q, k)))
        potential += 0.5 * ca.mtimes([dxi.T, ca.DM(G), dxi])
    if not stiffness_by_body:
        return ca.SX.zeros(tree.n_s), 0
    return -ca.mtimes(tree.K(q).T, ca.gradient(potential, q)), potential


def large_angle_hydrostatics(scene: Scene, topo: Topology, q):
    """Weight and buoyancy of each hydro body from its immersed part at the current pose.

    Buoyancy comes from the body's primitive (box, cylinder, sphere; mbcontrol.hydro.mesh.large_angle)
    cut by the calm free surface, so restoring stays right at large heel, heave and pitch
    where the linear stiffness G^b does not. It replaces the linear restoring and the static
    loads. Returns (generalised force, potential energy relative to rest, J).
    """
    from ..hydro import geometry_dict
    from ..hydro import buoyancy

    tree, tau, energy = topo.tree, ca.SX.zeros(topo.tree.n_s), 0
    rho, g = scene.water.rho, scene.water.g
    for body in scene.bodies:
        if not body.hydro:
            continue
        k = topo.body_index(body.name)
        R, r_cog = tree.rotation(q, k), tree.cog(q, k)
        b = buoyancy(geometry_dict(body.geometry), body.cog, R, r_cog, rho, g)
        force_n = b["force"] + ca.DM([0.0, 0.0, body.mass * g])     # weight acts at the CoG
        tau += tree.generalized_force(q, k, ca.vertcat(R.T @ force_n, R.T @ b["moment"]))
        rest = buoyancy(geometry_dict(body.geometry), body.cog, np.eye(3), np.asarray(body.cog), rho, g)
        energy += b["potential"] - float(rest["potential"]) - body.mass * g * (r_cog[2] - body.cog[2])
    return tau, energy


def static_loads(scene: Scene, topo: Topology, q, buoyancy: dict):
    """Constant loads at rest that linear hydrostatics leave out (ERRATA section 3, F0), and
    their potential (J, zero at rest).

    A hydro body whose weight m g differs from its buoyancy rho g V, or whose CoG is not above
    its centre of buoyancy, carries a net static load: F0 = (m g - rho g V) down through its
    CoG and, at rest, the couple C of buoyancy about the CoG (n axes). Their potential is
    V = -F0 . (r_c(q) - r_c(0)) - C . phi(q), with phi the n-frame rotation vector of the body
    from rest, and the load is -K^T dV/dq, conservative by construction (the energy audit
    balances). F0 is a constant n-frame force at a body point, so its geometric stiffness
    F0 d2z_c/dq2 is exact (ERRATA section 3). C does the work C . a theta about a fixed axis a,
    as a constant couple does, so hinges to the ground and sliders see the same load as a
    constant couple at every angle and the linear model is unchanged; only rotations about
    changing axes differ from a constant couple, which is not conservative there (rotations do
    not commute), by the antisymmetric part of its stiffness (|C| per rad), which no potential
    holds.
    buoyancy: body -> (rho g V (N), centre of buoyancy at rest, n-frame, m).
    """
    tree, potential = topo.tree, ca.SX(0)
    q_rest = ca.DM.zeros(tree.n_q)
    for body in scene.bodies:
        if not body.hydro or body.name not in buoyancy:
            continue
        k = topo.body_index(body.name)
        lift, centre = buoyancy[body.name]
        net = body.mass * scene.water.g - lift
        arm = np.asarray(centre) - np.asarray(body.cog)
        couple = np.cross(arm, [0.0, 0.0, -lift])            # n axes, about the CoG
        if abs(net) < 1e-9 * max(lift, 1.0) and np.linalg.norm(couple) < 1e-9 * max(lift, 1.0):
            continue
        potential -= net * (tree.cog(q, k)[2] - tree.cog(q_rest, k)[2])
        turned = ca.mtimes(tree.rotation(q, k), ca.DM(tree.rotation(q_rest, k)).T)
        potential -= ca.dot(ca.DM(couple), rotation_vector(turned))
    if potential.is_zero():
        return ca.SX.zeros(tree.n_s), 0
    return -ca.mtimes(tree.K(q).T, ca.gradient(potential, q)), potential


# Below sin^2(theta) = 1e-4 (theta < 0.01 rad) theta / sin(theta) is its series in sin^2: the
# first term left out, 35/1152 sin^8, is 3e-18; atan2 takes over above, where 1 / sin is well
# conditioned (and the series' derivatives stay finite at rest, where atan2(s, c) / s has 0/0).
_SERIES_BELOW = 1e-4


def rotation_vector(R):
    """The rotation vector theta a (rad, |theta| < pi) of a rotation matrix R = exp(theta S(a)):
    theta / sin(theta) times the axial vector of (R - R^T) / 2, which is sin(theta) a."""
    v = 0.5 * ca.vertcat(R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1])
    cosine, sin2 = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0), ca.dot(v, v)
    series = 1.0 + sin2 / 6.0 + 3.0 * sin2**2 / 40.0 + 5.0 * sin2**3 / 112.0   # asin(s) / s
    sine = ca.sqrt(ca.fmax(sin2, _SERIES_BELOW))
    ratio = ca.if_else(ca.logic_and(sin2 < _SERIES_BELOW, cosine > 0), series,
                       ca.atan2(sine, cosine) / sine)
    return ratio * v


def gravity_forces(scene: Scene, topo: Topology, q):
    """Weight of the bodies whose buoyancy is not modelled (hydro = false).
    Returns (generalised force, potential -Σ m g (z_c - z_c,rest), J; z down)."""
    tree, tau, energy = topo.tree, ca.SX.zeros(topo.tree.n_s), 0
    q_rest = ca.DM.zeros(tree.n_q)
    for body in scene.bodies:
        if not body.hydro:
            k = topo.body_index(body.name)
            tau += tree.point_force(q, k, tree.links[k].cog,
                                    ca.DM([0, 0, body.mass * scene.water.g]))
            energy -= body.mass * scene.water.g * (tree.cog(q, k)[2] - tree.cog(q_rest, k)[2])
    return tau, energy


def euler_zyx(R):
    """Roll, pitch, yaw (rad) of a rotation matrix R_b^n, ZYX convention."""
    roll = ca.atan2(R[2, 1], R[2, 2])
    pitch = -ca.asin(ca.fmin(ca.fmax(R[2, 0], -1), 1))
    yaw = ca.atan2(R[1, 0], R[0, 0])
    return ca.vertcat(roll, pitch, yaw)
