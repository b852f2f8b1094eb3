"""Shared by the multibody tests: small numeric helpers, tree builders (two-body, random, branching,
WEC-like) and the independent reference, Lagrange's equations built with sympy from absolute
CoG positions and sympy quaternion rotations."""
from __future__ import annotations

import casadi as ca
import numpy as np
import sympy as sp
from sympy.algebras.quaternion import Quaternion

from mbcontrol.multibody import Link, Motion, Tree

G = 9.81  # m/s^2
Y_AXIS = (0.0, 1.0, 0.0)


def num(x) -> np.ndarray:
    """CasADi DM (or anything array-like) -> numpy float array, without numpy-on-casadi calls."""
    return np.array(x.full() if isinstance(x, ca.DM) else x, dtype=float)


def rel_err(a, b) -> float:
    """max |a - b| / max |b|, the relative error used throughout (vectors compared flat)."""
    a, b = num(a), num(b)
    assert a.size == b.size, (a.shape, b.shape)
    a = a.reshape(b.shape)
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


def symbols(tree: Tree):
    return ca.SX.sym("q", tree.n_q), ca.SX.sym("s", tree.n_s)


def dynamics_function(tree: Tree) -> ca.Function:
    q, s = symbols(tree)
    return ca.Function("dyn", [q, s], [tree.mass_matrix(q), tree.bias(q, s), tree.P(q),
                                       tree.K(q), tree.gravity(q, G)])


# ---- model builders ------------------------------------------------------------------------

def two_body_tree(inertia=np.diag([0.3, 0.5, 0.4]), m=10.0, L1=0.6, Lc=0.3) -> Tree:
    """ERRATA section 5: two bodies hinged about y, body 1 pinned at the n-frame origin."""
    hinge = (Motion("revolute", Y_AXIS),)
    return Tree([Link("b1", -1, (0, 0, 0), (Lc, 0, 0), m, inertia, hinge),
                 Link("b2", 0, (L1, 0, 0), (Lc, 0, 0), m, inertia, hinge)])


def unit_vector(rng):
    a = rng.normal(size=3)
    return tuple(a / np.linalg.norm(a))


def spd_inertia(rng):
    A = rng.normal(size=(3, 3))
    return A @ A.T + 0.5 * np.eye(3)   # full symmetric positive-definite tensor, kg m^2


def random_tree(rng, spec) -> Tree:
    """spec: list of (parent, [(kind, axis or None=random skew), ...]); random geometry/inertia."""
    links = []
    for k, (parent, motions) in enumerate(spec):
        motions = tuple(Motion(kind, axis or unit_vector(rng)) for kind, axis in motions)
        links.append(Link(f"b{k}", parent, tuple(0.5 * rng.normal(size=3)),
                          tuple(0.5 * rng.normal(size=3)), float(rng.uniform(1, 5)),
                          spd_inertia(rng), motions))
    return Tree(links)


# Branching 3-D tree: skew revolute root, prismatic child, composite (prismatic + revolute)
# sibling, a fixed (welded) body and a revolute grandchild: 5 bodies, 5 coordinates.
BRANCHING_SPEC = [(-1, [("revolute", None)]), (0, [("prismatic", None)]),
                  (0, [("prismatic", None), ("revolute", None)]), (2, []), (3, [("revolute", None)])]
# WEC-like: a surge-heave-pitch composite root joint carrying a skew-hinged flap and a
# (skew revolute, then prismatic along the rotated axis) composite slider with a welded mass.
WEC_SPEC = [(-1, [("prismatic", (1, 0, 0)), ("prismatic", (0, 0, 1)), ("revolute", Y_AXIS)]),
            (0, [("revolute", None)]), (0, [("revolute", None), ("prismatic", None)]), (2, [])]


# ---- independent reference: Lagrange's equations in sympy -------------------------------

def sympy_rotation(axis, angle):
    """Rotation matrix from sympy's quaternion (not Rodrigues), simplified to cos/sin(angle)."""
    R = Quaternion.from_axis_angle(tuple(axis), angle).to_rotation_matrix()
    return R.applyfunc(lambda e: sp.expand(sp.expand_trig(sp.trigsimp(e))))


def lagrange_reference(tree: Tree):
    """(q, q_dot) -> (M, C s) from T = 1/2 sum(m v_c.v_c + w.I w), for joint coordinates.

    Absolute CoG positions p_c(q) and rotations R(q) are composed directly (no recursion);
    v_c = (dp_c/dq) q_dot and S(w^b) = R^T R_dot. T = 1/2 q_dot^T M(q) q_dot, and Lagrange's
    equations give C s = M_dot q_dot - dT/dq, i.e. sum_k (dM/dq_k q_dot_k) q_dot -
    1/2 [q_dot^T dM/dq_i q_dot]_i, with dM/dq from sympy derivatives of the Jacobians.
    """
    n = tree.n_q
    q = sp.symbols(f"q0:{n}")
    rotations, origins, terms, index = [], [], [], 0
    for link in tree.links:
        R_p, o_p = (sp.eye(3), sp.zeros(3, 1)) if link.parent < 0 else \
            (rotations[link.parent], origins[link.parent])
        R_joint, offset = sp.eye(3), sp.Matrix(link.joint_point)
        for motion in link.motions:
            if motion.kind == "prismatic":
                offset = offset + R_joint * sp.Matrix(motion.axis) * q[index]
            else:
                R_joint = R_joint * sympy_rotation(motion.axis, q[index])
            index += 1
        R, o = R_p * R_joint, o_p + R_p * offset
        rotations.append(R)
        origins.append(o)
        Jv = (o + R * sp.Matrix(link.cog)).jacobian(q)
        Jw = sp.Matrix.hstack(*[_vee(R.T * R.diff(qi)) for qi in q])
        terms.append((link.mass, np.array(link.inertia, dtype=float), Jv, Jw,
                      [Jv.diff(qi) for qi in q], [Jw.diff(qi) for qi in q]))
    jacobians = sp.lambdify([q], [t[2:] for t in terms], cse=True)

    def evaluate(q_value, qdot):
        M, dM = np.zeros((n, n)), np.zeros((n, n, n))
        for (m, I, *_), (Jv, Jw, dJv, dJw) in zip(terms, jacobians(q_value)):
            M += m * Jv.T @ Jv + Jw.T @ I @ Jw
            for i in range(n):
                dM[i] += m * (dJv[i].T @ Jv + Jv.T @ dJv[i]) + dJw[i].T @ I @ Jw + Jw.T @ I @ dJw[i]
        Cs = np.einsum("kij,k,j->i", dM, qdot, qdot) - 0.5 * np.einsum("j,ijk,k->i", qdot, dM, qdot)
        return M, Cs

    return evaluate


def _vee(Sw):
    return sp.Matrix([Sw[2, 1], Sw[0, 2], Sw[1, 0]])


def free_root_tree(rng, with_child=True):
    m, inertia = [2.5, 1.2], [spd_inertia(rng), spd_inertia(rng)]
    cogs = [0.3 * rng.normal(size=3), 0.3 * rng.normal(size=3)]
    axis, joint_point = unit_vector(rng), 0.5 * rng.normal(size=3)
    links = [Link("hull", -1, (0, 0, 0), tuple(cogs[0]), m[0], inertia[0], free=True)]
    if with_child:
        links.append(Link("flap", 0, tuple(joint_point), tuple(cogs[1]), m[1], inertia[1],
                          (Motion("revolute", axis),)))
    return Tree(links), (m, inertia, cogs, axis, joint_point)
