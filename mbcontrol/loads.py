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

from .scene import DOF_NAMES, Scene
from .topology import Topology


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
    """Generalised PTO force and, per PTO, its (position, velocity, force) expressions."""
    tau = ca.SX.zeros(topo.tree.n_s)
    signals = {}
    for i, pto in enumerate(scene.ptos):
        j = topo.coordinate_of_joint[pto.joint]
        c = params.add(f"{pto.name}__damping", pto.damping)
        k = params.add(f"{pto.name}__stiffness", pto.stiffness)
        force = -(c * s[j] + k * q[j]) + u[i]
        tau[j] += force
        signals[pto.name] = (q[j], s[j], force)
    return tau, signals


def friction_forces(scene: Scene, topo: Topology, s, params: Parameters):
    """Joint friction: viscous plus Coulomb smoothed by tanh(v / velocity_scale)."""
    tau = ca.SX.zeros(topo.tree.n_s)
    for fr in scene.frictions:
        j = topo.coordinate_of_joint[fr.joint]
        viscous = params.add(f"{fr.name}__viscous", fr.viscous)
        coulomb = params.add(f"{fr.name}__coulomb", fr.coulomb)
        tau[j] -= viscous * s[j] + coulomb * ca.tanh(s[j] / fr.velocity_scale)
    return tau


def mooring_forces(scene: Scene, topo: Topology, q, s, params: Parameters):
    """Linear spring-dampers from each fairlead's rest position, along the n-frame axes."""
    tree, tau = topo.tree, ca.SX.zeros(topo.tree.n_s)
    q_rest = ca.DM.zeros(tree.n_q)
    for m in scene.moorings:
        k = topo.body_index(m.body)
        local = np.asarray(m.point) - topo.origin(m.body)      # body axes = n axes at rest
        stiffness = ca.vertcat(*[params.add(f"{m.name}__stiffness_{a}", v)
                                 for a, v in zip("xyz", m.stiffness)])
        damping = ca.vertcat(*[params.add(f"{m.name}__damping_{a}", v)
                               for a, v in zip("xyz", m.damping)])
        displacement = tree.point(q, k, local) - tree.point(q_rest, k, local)
        velocity = tree.point_velocity(q, s, k, local)
        force = -(stiffness * displacement + damping * velocity)
        tau += tree.point_force(q, k, local, force)
    return tau


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
            wrench[i] = -c * ca.fabs(v) * v
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


def gravity_forces(scene: Scene, topo: Topology, q):
    """Weight of the bodies whose buoyancy is not modelled (hydro = false)."""
    tree, tau = topo.tree, ca.SX.zeros(topo.tree.n_s)
    for body in scene.bodies:
        if not body.hydro:
            k = topo.body_index(body.name)
            tau += tree.point_force(q, k, tree.links[k].cog,
                                    ca.DM([0, 0, body.mass * scene.water.g]))
    return tau


def euler_zyx(R):
    """Roll, pitch, yaw (rad) of a rotation matrix R_b^n, ZYX convention."""
    roll = ca.atan2(R[2, 1], R[2, 2])
    pitch = -ca.asin(ca.fmin(ca.fmax(R[2, 0], -1), 1))
    yaw = ca.atan2(R[1, 0], R[0, 0])
    return ca.vertcat(roll, pitch, yaw)
