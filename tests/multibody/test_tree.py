"""Tests of mbcontrol.multibody.tree against references independent of the tree recursion.

References: ERRATA sections 1 and 5 (closed forms and printed numbers), automatic
differentiation of P^T s, the skew-symmetry of M_dot - 2C, and conservation of energy and
momentum in long simulations; the independent derivations (sympy Lagrange, Kane, hand-derived
Newton-Euler) are in test_tree_derivations.py.

Tolerances: "1e-12 relative" is used where both sides are double-precision evaluations of
the same quantity by different algebra (rounding ~1e-15 times a few hundred operations);
printed reference numbers use 1e-10 since ERRATA prints 12 significant digits.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from mbcontrol.multibody import Link, Motion, Tree
from tests.helpers.tree_reference import (BRANCHING_SPEC, Y_AXIS, G, dynamics_function, free_root_tree, num,
                            random_tree, rel_err, symbols, two_body_tree)

# ---- 1. ERRATA section 5 and section 1 ----------------------------------------------------

PHI, PHI_DOT = [0.1, -0.3], [0.3, -0.7]          # ERRATA section 5, relative coordinates
T_REL_TO_ABS = np.array([[1.0, 0.0], [1.0, 1.0]])  # theta = T phi (theta1 = phi1, theta2 = phi1 + phi2)
T_INV = np.linalg.inv(T_REL_TO_ABS)


@pytest.mark.parametrize("inertia", [
    np.diag([0.3, 0.5, 0.4]),
    np.array([[0.3, 0.05, -0.02], [0.05, 0.5, 0.07], [-0.02, 0.07, 0.4]]),
], ids=["diagonal", "full"])
def test_errata_section5_two_body_numbers(inertia):
    """Only I_yy = 0.5 may matter (ERRATA section 1); the other entries are deliberately != 0.5."""
    tree = two_body_tree(inertia)
    M, Cs, P, _, _ = dynamics_function(tree)(PHI, PHI_DOT)
    M, Cs, P = num(M), num(Cs).ravel(), num(P)
    # ERRATA section 5, relative coordinates; printed to 12 significant digits -> 1e-10.
    np.testing.assert_allclose(M, [[9.83921136085, 3.11960568043], [3.11960568043, 1.4]], atol=1e-10)
    np.testing.assert_allclose(Cs, [0.0372355460393, -0.0478742734791], atol=1e-10)
    np.testing.assert_allclose(-np.linalg.solve(M, Cs), [-0.0498344787341, 0.145241568871], atol=1e-10)
    # Absolute angles: theta = T phi, so M_abs = T^-T M T^-1 and (C s)_abs = T^-T C s (same power).
    M_abs, Cs_abs = T_INV.T @ M @ T_INV, T_INV.T @ Cs
    np.testing.assert_allclose(M_abs, [[5.0, 1.71960568043], [1.71960568043, 1.4]], atol=1e-10)
    np.testing.assert_allclose(Cs_abs, [0.0851098195185, -0.0478742734791], atol=1e-10)
    np.testing.assert_allclose(-np.linalg.solve(M_abs, Cs_abs), [-0.0498344787341, 0.0954070901367],
                               atol=1e-10)
    theta, theta_dot = T_REL_TO_ABS @ PHI, T_REL_TO_ABS @ PHI_DOT
    # ERRATA section 1 closed-form P (2x12) in absolute angles; P_abs = T^-T P_rel since
    # nu = P_rel^T s_rel = P_rel^T T^-1 theta_dot. Exact trig formula -> 1e-12.
    s21, c21 = np.sin(theta[1] - theta[0]), np.cos(theta[1] - theta[0])
    L1, Lc1, Lc2 = 0.6, 0.3, 0.3
    P_errata = [[0, 0, -Lc1, 0, 1, 0, L1 * s21, 0, -L1 * c21, 0, 0, 0],
                [0, 0, 0, 0, 0, 0, 0, 0, -Lc2, 0, 1, 0]]
    np.testing.assert_allclose(T_INV.T @ P, P_errata, atol=1e-12)
    q, s = symbols(tree)
    energy = ca.Function("T", [q, s], [tree.kinetic_energy(q, s)])(PHI, PHI_DOT)
    assert abs(float(energy) - 0.130647318349) < 1e-10   # ERRATA section 5, "T = ... J"
    assert abs(float(energy) - 0.5 * theta_dot @ M_abs @ theta_dot) < 1e-14  # T = 1/2 s^T M s


def coriolis_matrix_eq10(tree: Tree, q, s, added_mass_b=None):
    """Eq. 10 / ERRATA G6: C = P (M_RB + A) Pdot^T + P C_RB(nu) P^T, Pdot by AD (q symbolic)."""
    P = tree.P(q)
    Pdot = ca.reshape(ca.jacobian(ca.vec(P), q) @ (tree.K(q) @ s), P.shape[0], P.shape[1])
    nu = P.T @ s
    C_rb = ca.diagcat(*[tree.C_RB_b_k(k, nu[6 * k:6 * k + 6]) for k in range(len(tree.links))])
    M_b = tree.M_RB_b() + (0 if added_mass_b is None else added_mass_b)
    return P @ M_b @ Pdot.T + P @ C_rb @ P.T


def test_errata_section5_coriolis_matrix():
    """The Eq. 10 matrix itself (not only C s) against ERRATA section 5's C_RB^g."""
    tree = two_body_tree()
    q, s = symbols(tree)
    C_rel = num(ca.Function("C", [q, s], [coriolis_matrix_eq10(tree, q, s)])(PHI, PHI_DOT))
    # Eq. 10 in absolute angles equals T^-T C_rel T^-1 (P_abs = T^-T P_rel, constant T).
    C_abs = T_INV.T @ C_rel @ T_INV
    np.testing.assert_allclose(C_abs, [[0, -0.212774548796], [-0.159580911597, 0]], atol=1e-10)


def test_two_body_symbolic_parameters_match_errata_closed_forms():
    """SX parameters in the links; ERRATA section 1 closed forms at random parameters/states."""
    m1, m2, L1, Lc1, Lc2, I1, I2 = ca.SX.sym("p", 7).elements()
    hinge = (Motion("revolute", Y_AXIS),)
    tree = Tree([Link("b1", -1, (0, 0, 0), (Lc1, 0, 0), m1, ca.diag(ca.vertcat(1, I1, 2)), hinge),
                 Link("b2", 0, (L1, 0, 0), (Lc2, 0, 0), m2, ca.diag(ca.vertcat(3, I2, 4)), hinge)])
    q, s = symbols(tree)
    params = ca.vertcat(m1, m2, L1, Lc1, Lc2, I1, I2)
    f = ca.Function("f", [q, s, params], [tree.mass_matrix(q), tree.bias(q, s)])
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(5):
        p = rng.uniform(0.2, 3.0, size=7)
        phi, phi_dot = rng.normal(size=2), rng.normal(size=2)
        M, Cs = f(phi, phi_dot, p)
        theta, theta_dot = T_REL_TO_ABS @ phi, T_REL_TO_ABS @ phi_dot
        k = p[1] * p[2] * p[4]
        s21, c21 = np.sin(theta[1] - theta[0]), np.cos(theta[1] - theta[0])
        M_ref = [[p[5] + p[0] * p[3] ** 2 + p[1] * p[2] ** 2, k * c21], [k * c21, p[6] + p[1] * p[4] ** 2]]
        Cs_ref = [-k * s21 * theta_dot[1] ** 2, k * s21 * theta_dot[0] ** 2]
        worst = max(worst, rel_err(T_INV.T @ num(M) @ T_INV, M_ref),
                    rel_err(T_INV.T @ num(Cs).ravel(), Cs_ref))
    assert worst < 1e-12   # same quantity by different algebra: double rounding only


# ---- 3. the beta recursion against automatic differentiation ----------------------------

@pytest.mark.parametrize("case", ["two_body", "branching", "free_root"])
def test_Pdot_T_s_equals_automatic_derivative(case):
    rng = np.random.default_rng(8)
    tree = {"two_body": lambda: two_body_tree(),
            "branching": lambda: random_tree(rng, BRANCHING_SPEC),
            "free_root": lambda: free_root_tree(rng)[0]}[case]()
    q, s = symbols(tree)
    # d/dt (P^T s) at s_dot = 0 = d(P^T s)/dq q_dot, q_dot = K s (P is pose-independent for a
    # free root, so its K block only multiplies zero columns).
    ad = ca.jacobian(tree.P(q).T @ s, q) @ (tree.K(q) @ s)
    f = ca.Function("f", [q, s], [tree.Pdot_T_s(q, s), ad, tree.body_velocity(q, s), tree.P(q).T @ s])
    for _ in range(4):
        beta, beta_ad, nu, nu_P = f(rng.normal(size=tree.n_q), rng.normal(size=tree.n_s))
        assert rel_err(beta, beta_ad) < 1e-12   # exact AD vs recursion: rounding only
        assert rel_err(nu, nu_P) < 1e-13        # body_velocity (recursion) = P^T s


def test_point_kinematics_and_forces_are_power_consistent():
    """point_velocity = d/dt point (AD), and generalised force . s = force . point velocity."""
    rng = np.random.default_rng(9)
    tree, _ = free_root_tree(rng)
    q, s = symbols(tree)
    r, force = tuple(rng.normal(size=3)), tuple(rng.normal(size=3))
    position = tree.point(q, 1, r)
    f = ca.Function("f", [q, s], [
        tree.point_velocity(q, s, 1, r), ca.jacobian(position, q) @ (tree.K(q) @ s),
        ca.dot(tree.point_force(q, 1, r, force), s), ca.dot(ca.DM(force), tree.point_velocity(q, s, 1, r)),
        tree.cog(q, 1) - tree.point(q, 1, tree.links[1].cog),
        ca.dot(tree.generalized_force(q, 1, ca.DM(np.r_[force, r])), s),
        ca.dot(ca.DM(np.r_[force, r]), tree.body_velocity(q, s)[6:12]),
        tree.K(q).T @ ca.gradient(tree.potential_energy(q, G), q) + tree.gravity(q, G),
        tree.kinetic_energy(q, s) - 0.5 * s.T @ tree.mass_matrix(q) @ s])
    for _ in range(3):
        v, v_ad, p_gen, p_point, dc, pw_gen, pw_body, grav_res, ke_res = f(
            rng.normal(size=7), rng.normal(size=7))
        assert rel_err(v, v_ad) < 1e-12            # AD of the n-frame position: rounding only
        assert abs(float(p_gen - p_point)) < 1e-12  # virtual power, O(1) numbers
        assert float(ca.norm_inf(dc)) == 0.0        # cog() is point(cog) by definition
        assert abs(float(pw_gen - pw_body)) < 1e-12  # P_k wrench . s = wrench . nu_k
        assert float(ca.norm_inf(grav_res)) < 1e-11  # K^T dV/dq = -tau_gravity (N, O(10-100))
        assert abs(float(ke_res)) < 1e-12           # T = 1/2 s^T M s


# ---- 4. skew symmetry of M_dot - 2C --------------------------------------------------------

def christoffel_matrix(M, q, qdot):
    """C_ij = sum_k 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qdot_k (joint coordinates)."""
    n = M.shape[0]
    dM = [ca.jacobian(M[:, k], q) for k in range(n)]   # dM[j][i, k] = dM_ij / dq_k
    C = ca.SX.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = 0.5 * sum((dM[j][i, k] + dM[k][i, j] - dM[k][j, i]) * qdot[k] for k in range(n))
    return C


def coupled_added_mass(rng, n_bodies):
    """A random symmetric positive-definite 6N x 6N A^b, coupled between bodies."""
    A = rng.normal(size=(6 * n_bodies, 6 * n_bodies))
    return A @ A.T / (6 * n_bodies)


@pytest.mark.parametrize("case,with_added_mass", [
    ("two_body", False), ("branching", False), ("free_root", False),
    ("branching", True), ("free_root", True)])
def test_Mdot_minus_2C_is_skew(case, with_added_mass):
    """Also with a constant coupled A^b: M = P(M_RB + A)P^T and the P A Pdot^T s bias term of
    ERRATA G6 keep M_dot - 2C skew and the power identity. The Christoffel check is skipped
    with A: Lagrange on 1/2 nu^T (M_RB + A) nu also yields the Munk terms P C_A(nu) nu, which
    the ERRATA model (rigid-body C_RB only) deliberately omits."""
    rng = np.random.default_rng(10)
    tree = {"two_body": lambda: two_body_tree(),
            "branching": lambda: random_tree(rng, BRANCHING_SPEC),
            "free_root": lambda: free_root_tree(rng)[0]}[case]()
    A = ca.DM(coupled_added_mass(rng, len(tree.links))) if with_added_mass else None
    q, s = symbols(tree)
    M = tree.mass_matrix(q, A)
    Mdot = ca.reshape(ca.jacobian(ca.vec(M), q) @ (tree.K(q) @ s), tree.n_s, tree.n_s)
    C10 = coriolis_matrix_eq10(tree, q, s, A)
    bias = tree.bias(q, s, A)
    outputs = [Mdot - 2 * C10, C10 @ s - bias, s.T @ (0.5 * Mdot @ s - bias)]
    if case != "free_root" and A is None:   # Christoffel needs s = q_dot, and no C_A (above)
        Cc = christoffel_matrix(M, q, s)
        outputs += [Mdot - 2 * Cc, Cc @ s - bias]
    f = ca.Function("f", [q, s], outputs)
    for _ in range(3):
        out = [num(x) for x in f(rng.normal(size=tree.n_q), rng.normal(size=tree.n_s))]
        scale = max(1.0, np.max(np.abs(out[0])))
        assert np.max(np.abs(out[0] + out[0].T)) < 1e-12 * scale   # skew: rounding only
        assert np.max(np.abs(out[1])) < 1e-12 * scale               # Eq. 10 C s = bias
        assert abs(out[2].item()) < 1e-12 * scale                   # power identity
        if len(out) > 3:
            assert np.max(np.abs(out[3] + out[3].T)) < 1e-12 * scale   # Christoffel skew
            assert np.max(np.abs(out[4])) < 1e-12 * scale           # Christoffel C s = bias


# ---- 5. conservation in long simulations --------------------------------------------------

def rk4_simulator(tree: Tree, g: float, dt: float, steps: int) -> ca.Function:
    """x = [q; s], x_dot = [K s; M^-1 (gravity - C s)], classic RK4, mapped over `steps`."""
    x = ca.SX.sym("x", tree.n_q + tree.n_s)
    q, s = x[:tree.n_q], x[tree.n_q:]
    rhs = ca.vertcat(tree.K(q) @ s, ca.solve(tree.mass_matrix(q), tree.gravity(q, g) - tree.bias(q, s)))
    f = ca.Function("f", [x], [rhs])
    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    step = ca.Function("step", [x], [x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])
    return step.mapaccum("run", steps)


def test_energy_conserved_three_body_chain_with_gravity():
    rng = np.random.default_rng(11)
    spec = [(-1, [("revolute", None)]), (0, [("revolute", None)]), (1, [("revolute", None)])]
    tree = random_tree(rng, spec)
    x0 = np.r_[rng.normal(size=3), rng.normal(size=3)]
    trajectory = num(rk4_simulator(tree, G, dt=1e-3, steps=20_000)(x0))   # 20 s
    X = np.c_[x0, trajectory]
    x = ca.SX.sym("x", 6)
    energy = ca.Function("E", [x], [tree.kinetic_energy(x[:3], x[3:]), tree.potential_energy(x[:3], G)])
    T, V = (num(e).ravel() for e in energy.map(X.shape[1])(X))
    drift = np.max(np.abs(T + V - (T[0] + V[0]))) / np.max(T)
    # RK4 at dt = 1 ms: local error ~ (w dt)^5 with w ~ 10 rad/s, so ~1e-10 per 20 s expected;
    # 1e-6 relative to the peak kinetic energy leaves margin without hiding a model error
    # (a wrong bias term drifts at O(1)).
    assert drift < 1e-6, drift
    assert np.ptp(T) > 0.1 * np.max(T)   # the motion really exchanges energy


def test_free_body_with_child_conserves_energy_and_momentum():
    rng = np.random.default_rng(12)
    tree, _ = free_root_tree(rng)
    x0 = np.r_[np.zeros(3), 0.1 * rng.normal(size=3), 0.3, rng.normal(size=3), 0.5 * rng.normal(size=3), 1.0]
    trajectory = num(rk4_simulator(tree, 0.0, dt=1e-3, steps=10_000)(x0))   # 10 s, no gravity
    X = np.c_[x0, trajectory]
    x = ca.SX.sym("x", 14)
    q, s = x[:7], x[7:]
    momentum, angular = 0, 0
    for k, link in enumerate(tree.links):
        v_cog = tree.point_velocity(q, s, k, link.cog)
        momentum = momentum + link.mass * v_cog
        w_n = tree.rotation(q, k) @ tree.body_velocity(q, s)[6 * k + 3:6 * k + 6]
        angular = angular + ca.cross(tree.cog(q, k), link.mass * v_cog) + \
            tree.rotation(q, k) @ ca.DM(link.inertia) @ tree.rotation(q, k).T @ w_n
    f = ca.Function("f", [x], [tree.kinetic_energy(q, s), momentum, angular, tree.euler_singularity_margin(q)])
    T, p, h, margin = (num(v) for v in f.map(X.shape[1])(X))
    T = T.ravel()
    assert margin.min() > 0.2     # stayed away from the Euler singularity (|cos theta| > 0.2)
    # RK4 at 1 ms with ~1 rad/s rotation: truncation error ~(w dt)^4 per unit time, far below
    # 1e-6 relative (measured ~1e-13); a wrong bias or K breaks these at O(1e-2) or worse.
    assert np.max(np.abs(T - T[0])) / T[0] < 1e-6                               # energy
    assert np.max(np.abs(p - p[:, :1])) / np.max(np.abs(p[:, 0])) < 1e-6        # linear momentum
    assert np.max(np.abs(h - h[:, :1])) / np.max(np.abs(h[:, 0])) < 1e-6        # angular momentum


# ---- validation -------------------------------------------------------------------------------

def test_invalid_input_raises():
    I = np.eye(3)
    with pytest.raises(ValueError):
        Motion("revolute", (0, 0, 0))
    with pytest.raises(ValueError):
        Motion("screw", (1, 0, 0))
    with pytest.raises(ValueError):
        Link("a", 0, (0, 0, 0), (0, 0, 0), 1.0, I, free=True)                  # free, not a root
    with pytest.raises(ValueError):
        Link("a", -1, (0, 0, 0), (0, 0, 0), 1.0, I, (Motion("revolute", Y_AXIS),), free=True)
    with pytest.raises(ValueError):
        Tree([Link("a", 0, (0, 0, 0), (0, 0, 0), 1.0, I)])                      # parent not earlier
    with pytest.raises(ValueError):
        Tree([Link("a", -1, (0, 0, 0), (0, 0, 0), 1.0, I), Link("a", 0, (0, 0, 0), (0, 0, 0), 1.0, I)])
    assert Motion("prismatic", (0, 3, 4)).axis == (0.0, 0.6, 0.8)   # normalised: 3-4-5 triangle
    with pytest.raises(ValueError):
        Link("a", -1, (0, 0, 0), (0, 0, 0), 1.0, I, (Motion("revolute", Y_AXIS),), coordinate_names=("x", "y"))
    named = Tree([Link("float", -1, (0, 0, 0), (0, 0, 0), 1.0, I, free=True),
                  Link("flap", 0, (1, 0, 0), (0, 0, 0), 1.0, I, (Motion("revolute", Y_AXIS),),
                       coordinate_names=("flap_pitch",)),
                  Link("ballast", 0, (0, 0, 1), (0, 0, 0), 1.0, I)])
    assert named.coordinate_names[-2:] == ["float__Yaw", "flap_pitch"] and named.n_q == named.n_s == 7
    assert named.body_names == ["float", "flap", "ballast"]


def test_tree_without_coordinates():
    """All-fixed tree: n_q = 0, empty generalised quantities, potential energy still defined."""
    tree = Tree([Link("dock", -1, (0, 0, 1), (0, 0, 0.5), 2.0, np.eye(3))])
    q = s = ca.DM.zeros(0, 1)
    assert tree.n_q == tree.n_s == 0 and tree.mass_matrix(q).shape == (0, 0)
    assert tree.bias(q, s).shape == tree.gravity(q, G).shape == (0, 1)
    assert abs(float(tree.potential_energy(q, G)) + 2.0 * G * 1.5) < 1e-14   # -m g z_c, z_c = 1.5 m


def test_reference_configuration_is_aligned():
    """At q = 0 every body frame is aligned with the n-frame and o_k = sum of joint points."""
    tree = random_tree(np.random.default_rng(14), BRANCHING_SPEC)
    q0 = ca.DM.zeros(tree.n_q)
    for k, link in enumerate(tree.links):
        assert rel_err(tree.rotation(q0, k), np.eye(3)) == 0.0   # exact: cos 0 = 1, sin 0 = 0
        expected, j = np.zeros(3), k
        while j >= 0:
            expected, j = expected + tree.links[j].joint_point, tree.links[j].parent
        assert rel_err(tree.origin(q0, k), expected) < 1e-15


def test_euler_singularity_margin():
    tree, _ = free_root_tree(np.random.default_rng(13))
    q = np.zeros(7)
    q[4] = np.pi / 2 - 1e-3
    assert abs(float(tree.euler_singularity_margin(ca.DM(q))) - np.sin(1e-3)) < 1e-15  # |cos(pi/2 - e)|
    assert two_body_tree().euler_singularity_margin(ca.DM([0.1, 0.2])).shape == (0, 1)
