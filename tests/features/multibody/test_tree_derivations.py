"""The tree's dynamics against independent derivations: Lagrange's equations built with sympy
(random trees), sympy's KanesMethod with body-frame quasi-velocities, the hand-derived
Newton-Euler equations of a free body, rotations against sympy and their definitions, and
composite joints against chains of massless links.

Tolerances: "1e-12 relative" where both sides are double-precision evaluations of the same
quantity by different algebra.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me
from sympy.algebras.quaternion import Quaternion

from mbcontrol.multibody import H, Link, Motion, R_zyx, Rot, S, T_zyx, Tree
from tests.helpers.tree_reference import (BRANCHING_SPEC, WEC_SPEC, Y_AXIS, G, dynamics_function, free_root_tree,
                            lagrange_reference, num, random_tree, rel_err, spd_inertia, symbols,
                            unit_vector)

# ---- 2. independent derivations ---------------------------------------------------------

@pytest.mark.parametrize("spec,seed", [(BRANCHING_SPEC, 1), (WEC_SPEC, 7)], ids=["branching", "wec"])
def test_random_tree_against_sympy_lagrange(spec, seed):
    rng = np.random.default_rng(seed)
    tree = random_tree(rng, spec)
    reference = lagrange_reference(tree)
    f = dynamics_function(tree)
    worst = 0.0
    for _ in range(4):
        q, s = rng.normal(size=tree.n_q), rng.normal(size=tree.n_s)
        M, Cs = f(q, s)[:2]
        M_ref, Cs_ref = reference(q, s)
        worst = max(worst, rel_err(M, M_ref), rel_err(num(Cs).ravel(), Cs_ref))
    assert worst < 1e-10   # measured ~1e-15: independent double-precision evaluations


def kane_free_root_reference(m, inertia, cogs, axis, joint_point):
    """sympy KanesMethod: free root (ZYX Euler angles, body-frame quasi-velocities) + revolute child.

    Returns (q, u) -> (M, forcing incl. gravity, q_dot) where M u_dot = forcing. The kinematic
    equations come from sympy's own orientation kinematics (solving w(Theta, Theta_dot) = u).
    """
    q, u = me.dynamicsymbols("x y z phi theta psi hinge"), me.dynamicsymbols("u0:7")
    N, B = me.ReferenceFrame("N"), me.ReferenceFrame("B")
    B.orient_body_fixed(N, (q[5], q[4], q[3]), "zyx")
    w_of_euler_rates = B.ang_vel_in(N).to_matrix(B)
    B.set_ang_vel(N, _vec(B, u[3:6]))
    origin = me.Point("O")
    origin.set_vel(N, 0)
    o_root = origin.locatenew("o_root", _vec(N, q[:3]))
    o_root.set_vel(N, _vec(B, u[:3]))
    c_root = o_root.locatenew("c_root", _vec(B, cogs[0]))
    c_root.v2pt_theory(o_root, N, B)
    C = me.ReferenceFrame("C")
    C.orient_axis(B, _vec(B, axis), q[6])
    C.set_ang_vel(B, u[6] * _vec(B, axis))
    o_child = o_root.locatenew("o_child", _vec(B, joint_point))
    o_child.v2pt_theory(o_root, N, B)
    c_child = o_child.locatenew("c_child", _vec(C, cogs[1]))
    c_child.v2pt_theory(o_child, N, C)
    bodies = [me.RigidBody(name, point, frame, mass, (_dyadic(frame, I), point))
              for name, point, frame, mass, I in
              (("root", c_root, B, m[0], inertia[0]), ("child", c_child, C, m[1], inertia[1]))]
    qd = [qi.diff() for qi in q]
    euler_rates = sp.solve(list(w_of_euler_rates - sp.Matrix(u[3:6])), qd[3:6], dict=True)[0]
    q_dot = list(_vec(B, u[:3]).to_matrix(N)) + [euler_rates[qd[i]] for i in range(3, 6)] + [u[6]]
    kane = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=[a - b for a, b in zip(qd, q_dot)])
    kane.kanes_equations(bodies, [(c_root, m[0] * G * N.z), (c_child, m[1] * G * N.z)])
    qs, us = sp.symbols("Q0:7"), sp.symbols("U0:7")
    plain = dict(zip(q, qs)) | dict(zip(u, us))
    exprs = [kane.mass_matrix.xreplace(plain), kane.forcing.xreplace(plain),
             sp.Matrix(q_dot).xreplace(plain)]
    return sp.lambdify([qs, us], exprs, cse=True)


def _vec(frame, v):
    return v[0] * frame.x + v[1] * frame.y + v[2] * frame.z


def _dyadic(frame, I):
    return me.inertia(frame, I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[2, 0])


def test_free_root_with_revolute_child_against_kane():
    rng = np.random.default_rng(2)
    tree, data = free_root_tree(rng)
    assert tree.coordinate_names[:6] == [f"hull__{d}" for d in
                                         ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")]
    reference = kane_free_root_reference(*data)
    f = dynamics_function(tree)
    worst_M = worst_F = worst_K = 0.0
    for _ in range(4):
        q, s = rng.normal(size=7), rng.normal(size=7)
        M, Cs, _, K, gravity = f(q, s)
        M_ref, forcing_ref, qdot_ref = reference(q, s)
        worst_M = max(worst_M, rel_err(M, M_ref))
        # Kane: M u_dot = forcing, here forcing = generalised gravity - C s.
        worst_F = max(worst_F, rel_err(num(gravity - Cs).ravel(), np.ravel(forcing_ref)))
        worst_K = max(worst_K, rel_err(num(K @ s).ravel(), np.ravel(qdot_ref)))
    # Independent double-precision evaluations (measured ~1e-15).
    assert max(worst_M, worst_F, worst_K) < 1e-10   # measured ~1e-15


def test_single_free_body_against_newton_euler():
    """Fossen's Newton-Euler equations about o with CoG offset r_g (hand-derived):
    m(v_dot + w x v + w_dot x r_g + w x (w x r_g)) = f,
    I_o w_dot + w x I_o w + m r_g x (v_dot + w x v) = m_o,  I_o = I_c - m S(r_g)^2."""
    rng = np.random.default_rng(3)
    tree, (m, inertia, cogs, *_) = free_root_tree(rng, with_child=False)
    m, I_c, r_g = m[0], inertia[0], cogs[0]
    Sg = np.array([[0, -r_g[2], r_g[1]], [r_g[2], 0, -r_g[0]], [-r_g[1], r_g[0], 0]])
    I_o = I_c - m * Sg @ Sg
    M_ref = np.block([[m * np.eye(3), -m * Sg], [m * Sg, I_o]])
    f = dynamics_function(tree)
    q, s = symbols(tree)
    point_force = ca.Function("pf", [q], [tree.point_force(q, 0, tuple(r_g), (0, 0, m * G))])
    for _ in range(3):
        qv, sv = rng.normal(size=6), rng.normal(size=6)
        v, w = sv[:3], sv[3:]
        M, Cs, P, _, gravity = f(qv, sv)
        Cs_ref = np.r_[m * (np.cross(w, v) + np.cross(w, np.cross(w, r_g))),
                       np.cross(w, I_o @ w) + m * np.cross(r_g, np.cross(w, v))]
        R = num(R_zyx(qv[3:]))
        weight_b = R.T @ [0, 0, m * G]
        gravity_ref = np.r_[weight_b, np.cross(r_g, weight_b)]   # moment of the weight about o
        assert rel_err(M, M_ref) < 1e-12           # double rounding only
        assert rel_err(num(Cs).ravel(), Cs_ref) < 1e-12           # idem
        assert rel_err(num(gravity).ravel(), gravity_ref) < 1e-12  # idem
        assert rel_err(num(point_force(qv)).ravel(), gravity_ref) < 1e-12  # idem
        # P for a free root does not depend on the root pose (ERRATA section 4): exact.
        assert rel_err(P, f(rng.normal(size=6), sv)[2]) == 0.0


def test_rotations_against_sympy_and_definitions():
    """Rot vs sympy quaternions, R_zyx vs sympy's body-fixed zyx DCM, T_zyx vs Euler kinematics."""
    rng = np.random.default_rng(4)
    axis, angle = unit_vector(rng), 0.7
    R_ref = np.array(Quaternion.from_axis_angle(axis, angle).to_rotation_matrix().evalf(), float)
    assert rel_err(Rot(axis, angle), R_ref) < 1e-14   # same rotation, double rounding
    Theta = rng.normal(size=3)
    N, B = me.ReferenceFrame("N"), me.ReferenceFrame("B")
    B.orient_body_fixed(N, (Theta[2], Theta[1], Theta[0]), "zyx")
    assert rel_err(R_zyx(Theta), np.array(N.dcm(B).evalf(), float)) < 1e-14   # N.dcm(B) = R_b^n
    # Theta_dot = T w  <=>  w = T^-1 Theta_dot; check T^-1 against Fossen's closed form.
    phi, th = Theta[0], Theta[1]
    T_inv_ref = [[1, 0, -np.sin(th)], [0, np.cos(phi), np.cos(th) * np.sin(phi)],
                 [0, -np.sin(phi), np.cos(th) * np.cos(phi)]]
    assert rel_err(np.linalg.inv(num(T_zyx(Theta))), T_inv_ref) < 1e-13
    r = rng.normal(size=3)
    assert rel_err(S(r) @ ca.DM([1.0, 2.0, 3.0]), np.cross(r, [1.0, 2.0, 3.0])) < 1e-15
    twist = rng.normal(size=6)
    shifted = num(H(r) @ ca.DM(twist)).ravel()    # velocity of the point r: v + w x r
    assert rel_err(shifted, np.r_[twist[:3] + np.cross(twist[3:], r), twist[3:]]) < 1e-15


def test_composite_joint_equals_chain_of_massless_links():
    """A (surge, heave, pitch) composite joint = three links, two of them massless."""
    rng = np.random.default_rng(6)
    I, cog, jp = spd_inertia(rng), tuple(0.3 * rng.normal(size=3)), tuple(rng.normal(size=3))
    motions = (Motion("prismatic", (1, 0, 0)), Motion("prismatic", (0, 0, 1)), Motion("revolute", Y_AXIS))
    composite = Tree([Link("wec", -1, jp, cog, 3.0, I, motions)])
    zero = np.zeros((3, 3))
    chain = Tree([Link("sx", -1, jp, (0, 0, 0), 0.0, zero, motions[:1]),
                  Link("sz", 0, (0, 0, 0), (0, 0, 0), 0.0, zero, motions[1:2]),
                  Link("wec", 1, (0, 0, 0), cog, 3.0, I, motions[2:])])
    q, s = rng.normal(size=3), rng.normal(size=3)
    for a, b in zip(dynamics_function(composite)(q, s), dynamics_function(chain)(q, s)):
        if a.shape == (3, 6):            # P: only the real body's 6 columns are comparable
            b = b[:, 12:18]
        assert rel_err(a, b) < 1e-14     # identical algebra up to rounding
    assert composite.coordinate_names == ["wec__0", "wec__1", "wec__2"]


def test_free_root_matches_composite_six_dof_joint():
    """A free root = composite (surge, sway, heave, yaw, pitch, roll) joint with Euler-rate
    coordinates: same pose, and with q_dot = K s the same kinetic energy, so
    M_composite = J^T M_free J with J = d s / d q_dot = K^-1 (reordered)."""
    rng = np.random.default_rng(15)
    I, cog, rest = spd_inertia(rng), tuple(0.3 * rng.normal(size=3)), (1.0, -2.0, 0.5)
    e = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
    motions = tuple(Motion("prismatic", a) for a in e) + tuple(Motion("revolute", e[i]) for i in (2, 1, 0))
    free = Tree([Link("hull", -1, rest, cog, 2.0, I, free=True)])
    composite = Tree([Link("hull", -1, rest, cog, 2.0, I, motions)])
    order = [0, 1, 2, 5, 4, 3]              # composite [x, y, z, psi, theta, phi] -> free order
    x = ca.SX.sym("x", 6)
    q_free, qdot = x, ca.SX.sym("qd", 6)
    q_comp = x[order]
    s_free = ca.solve(free.K(q_free), qdot)
    f = ca.Function("f", [x, qdot], [
        free.rotation(q_free, 0) - composite.rotation(q_comp, 0),
        free.cog(q_free, 0) - composite.cog(q_comp, 0),
        free.kinetic_energy(q_free, s_free) - composite.kinetic_energy(q_comp, qdot[order]),
        free.origin(ca.DM.zeros(6), 0) - ca.DM(rest)])
    for _ in range(3):
        residuals = f(0.5 * rng.normal(size=6), rng.normal(size=6))
        assert max(float(ca.norm_inf(r)) for r in residuals) < 1e-13   # O(1) numbers, rounding
