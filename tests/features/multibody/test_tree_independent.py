"""Independent checks of the multibody core against references outside mbcontrol's algebra.

1. MuJoCo (its own composite-rigid-body mass matrix, recursive Newton-Euler bias and RK4):
   a 4-link chain (revolute about y, revolute about x, a prismatic joint on a spring along an
   oblique axis, revolute about an oblique axis) with full inertia tensors and CoGs off the
   joint axes, under gravity. M(q), the bias, the CoG positions, 3 s trajectories and the
   total energy are compared. MuJoCo's world is z-up: the n-frame (NED) is mapped to it by
   the proper rotation C = diag(1, -1, -1) (x forward, y to port, z up), applied to every
   point, axis and inertia tensor, with gravity (0, 0, -g). Joint coordinates are unchanged
   by the mapping (Rot(C a, q) = C Rot(a, q) C^T), so qpos/qvel compare one to one.
2. Conservation of linear and angular momentum of a free body carrying a hinged flap with an
   internal spring-damper torque, with momenta, kinetic energy and Euler-angle kinematics
   computed here from scratch (numpy rotations, complex-step derivatives, Fossen's ZYX
   kinematics), not with the library's recursion; the energy falls by exactly the damper's
   work, integrated alongside the state.
3. The energy balance of a scene (hydro = false, so gravity acts through loads.gravity_forces)
   built by build_plant: a 3-body chain with a joint PTO damper and Coulomb/viscous friction
   over 200 s; kinetic + potential change equals minus the dissipated work, integrated with a
   dissipated power written here from the scene's numbers.

Tolerances are stated at each assertion with the value measured when the test was written.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from mbcontrol.multibody import Link, Motion, Tree

G = 9.81  # m/s^2


# ---- helpers written independently of mbcontrol.multibody ----------------------------------

def rot(axis, angle):
    """Rodrigues rotation about a unit `axis` (numpy; angle may be an array, real or complex)."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    angle = np.asarray(angle)[..., None, None]
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * (K @ K)


def inertia_tensor(moments, axis, angle):
    """Full tensor with principal `moments` (triangle inequality holds) rotated off the axes."""
    Q = rot(axis, angle)
    return Q @ np.diag(moments) @ Q.T


def rk4_run(rhs: ca.Function, nx: int, dt: float, steps: int) -> ca.Function:
    """Classic RK4 on x' = rhs(x), `steps` steps of dt chained by mapaccum: x0 -> (nx, steps)."""
    x = ca.SX.sym("x", nx)
    k1 = rhs(x)
    k2 = rhs(x + dt / 2 * k1)
    k3 = rhs(x + dt / 2 * k2)
    k4 = rhs(x + dt * k3)
    return ca.Function("step", [x], [x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)]).mapaccum("run", steps)


def trajectory(run: ca.Function, x0) -> np.ndarray:
    """(steps + 1, nx) samples including x0."""
    return np.c_[np.asarray(x0, float), np.array(run(x0))].T


# ---- 1. MuJoCo ------------------------------------------------------------------------------

# name, parent, joint point (from the parent's origin, m), kind, axis, CoG (from o_k, m),
# mass (kg), inertia about the CoG (kg m^2); n-frame axes at rest (z down).
CHAIN = [
    ("arm", -1, (0.0, 0.0, 0.0), "revolute", (0, 1, 0), (0.4, 0.05, 0.1), 3.0,
     inertia_tensor((0.05, 0.40, 0.42), (1, 2, 3), 0.7)),
    ("fore", 0, (0.8, 0.0, 0.1), "revolute", (1, 0, 0), (0.1, 0.3, -0.05), 2.0,
     inertia_tensor((0.20, 0.03, 0.21), (-2, 1, 0.5), 1.1)),
    ("slider", 1, (0.2, 0.5, 0.0), "prismatic", (0.3, 0.2, 0.9), (0.05, -0.1, 0.15), 1.5,
     inertia_tensor((0.02, 0.025, 0.03), (0, 1, 1), 0.4)),
    ("flap", 2, (0.0, 0.0, 0.3), "revolute", (0.3, -0.5, 0.8), (0.15, 0.1, 0.2), 1.0,
     inertia_tensor((0.03, 0.05, 0.07), (1, -1, 2), 2.0)),
]
SLIDER_STIFFNESS = 80.0        # N/m, a joint spring keeps the slider from running away
SLIDER = 2                     # its coordinate
NED_TO_MUJOCO = np.diag([1.0, -1.0, -1.0])   # proper rotation (det +1): z down -> z up


def chain_tree() -> Tree:
    return Tree([Link(name, parent, jp, cog, m, inertia, (Motion(kind, axis),))
                 for name, parent, jp, kind, axis, cog, m, inertia in CHAIN])


def chain_mjcf(dt: float) -> str:
    C = NED_TO_MUJOCO

    def vec(x):
        return " ".join(f"{float(v):.17g}" for v in x)

    def body(i):
        name, _, jp, kind, axis, cog, m, inertia = CHAIN[i]
        I = C @ inertia @ C.T
        children = "".join(body(j) for j, link in enumerate(CHAIN) if link[1] == i)
        spring = f' stiffness="{SLIDER_STIFFNESS}" springref="0"' if i == SLIDER else ""
        joint_type = "hinge" if kind == "revolute" else "slide"
        # fullinertia order: Ixx Iyy Izz Ixy Ixz Iyz, about the inertial pos, body axes
        return (f'<body name="{name}" pos="{vec(C @ np.array(jp))}">'
                f'<joint name="{name}" type="{joint_type}" pos="0 0 0" axis="{vec(C @ np.array(axis))}" '
                f'limited="false" damping="0" armature="0" frictionloss="0"{spring}/>'
                f'<inertial pos="{vec(C @ np.array(cog))}" mass="{m}" '
                f'fullinertia="{vec([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]])}"/>'
                f'{children}</body>')

    # no geoms (so no contacts) and contacts/constraints disabled anyway; no fluid forces
    # (density and viscosity default to 0); energy enabled for data.energy.
    return (f'<mujoco><compiler inertiafromgeom="false"/>'
            f'<option timestep="{dt}" integrator="RK4" gravity="0 0 {-G}">'
            f'<flag contact="disable" constraint="disable" energy="enable"/></option>'
            f'<worldbody>{body(0)}</worldbody></mujoco>')


def full_mass_matrix(mujoco, model, data) -> np.ndarray:
    M = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, M)          # MuJoCo 4: (m, d, dst)
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)       # MuJoCo 3: (m, dst, qM)
    return M


def chain_functions(tree: Tree):
    """mbcontrol side: M, bias - gravity - spring (MuJoCo's qfrc_bias - qfrc_passive), CoGs,
    total energy, and the ODE right-hand side."""
    q, s = ca.SX.sym("q", tree.n_q), ca.SX.sym("s", tree.n_s)
    spring = ca.SX.zeros(tree.n_s)
    spring[SLIDER] = -SLIDER_STIFFNESS * q[SLIDER]
    forces = tree.gravity(q, G) + spring
    energy = tree.kinetic_energy(q, s) + tree.potential_energy(q, G) + \
        0.5 * SLIDER_STIFFNESS * q[SLIDER] ** 2
    cogs = ca.horzcat(*[tree.cog(q, k) for k in range(len(tree.links))])
    f = ca.Function("f", [q, s], [tree.mass_matrix(q), tree.bias(q, s) - forces, cogs, energy])
    x = ca.SX.sym("x", 2 * tree.n_q)
    qx, sx = x[:tree.n_q], x[tree.n_q:]
    spring_x = ca.SX.zeros(tree.n_s)
    spring_x[SLIDER] = -SLIDER_STIFFNESS * qx[SLIDER]
    rhs = ca.Function("rhs", [x], [ca.vertcat(sx, ca.solve(
        tree.mass_matrix(qx), tree.gravity(qx, G) + spring_x - tree.bias(qx, sx)))])
    return f, rhs


def test_mass_matrix_bias_and_cogs_match_mujoco():
    """Sharpest check: M(q) against MuJoCo's mj_fullM (composite rigid body algorithm), and
    C s - gravity - spring against qfrc_bias - qfrc_passive (recursive Newton-Euler), at
    random states over wide angle ranges; CoG positions against MuJoCo's xipos."""
    mujoco = pytest.importorskip("mujoco")
    tree = chain_tree()
    model = mujoco.MjModel.from_xml_string(chain_mjcf(1e-3))
    data = mujoco.MjData(model)
    assert model.nq == model.nv == tree.n_q == 4
    np.testing.assert_array_equal(model.body_mass[1:], [link[6] for link in CHAIN])
    f, _ = chain_functions(tree)
    rng = np.random.default_rng(21)
    worst_M = worst_bias = worst_cog = 0.0
    for _ in range(6):
        q, s = rng.uniform(-np.pi, np.pi, 4), rng.normal(size=4)
        q[SLIDER] = rng.uniform(-0.5, 0.5)
        data.qpos[:], data.qvel[:] = q, s
        mujoco.mj_forward(model, data)
        M, bias, cogs, _ = (np.array(v) for v in f(q, s))
        M_mj = full_mass_matrix(mujoco, model, data)
        bias_mj = data.qfrc_bias - data.qfrc_passive
        worst_M = max(worst_M, np.abs(M - M_mj).max() / np.abs(M_mj).max())
        worst_bias = max(worst_bias, np.abs(bias.ravel() - bias_mj).max() / np.abs(bias_mj).max())
        cogs_mj = NED_TO_MUJOCO.T @ data.xipos[1:].T          # MuJoCo world -> n-frame
        worst_cog = max(worst_cog, np.abs(cogs - cogs_mj).max())
    # Same quantities by different algorithms in double precision: rounding only.
    assert worst_M < 1e-12, worst_M            # measured 1.1e-15
    assert worst_bias < 1e-12, worst_bias      # measured 7.1e-16
    assert worst_cog < 1e-12, worst_cog        # m; measured 2.2e-16


def test_chain_trajectory_and_energy_match_mujoco():
    """3 s from a state that spins the chain (the forearm turns > 1.5 revolutions), both
    with classic RK4 at dt = 1 ms: mbcontrol's ODE [s; M^-1 (gravity + spring - C s)] and
    MuJoCo's mj_step with integrator RK4. Identical schemes on identical ODEs, so the
    difference is rounding amplified by the motion; total energy (kinetic + gravity +
    spring) against MuJoCo's data.energy, evaluated after mj_forward at each sample."""
    mujoco = pytest.importorskip("mujoco")
    dt, duration = 1e-3, 3.0
    n = round(duration / dt)
    tree = chain_tree()
    f, rhs = chain_functions(tree)
    x0 = np.array([0.4, -0.6, 0.05, 1.0, 1.5, -0.8, 0.3, -2.0])
    X = trajectory(rk4_run(rhs, 8, dt, n), x0)

    model = mujoco.MjModel.from_xml_string(chain_mjcf(dt))
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = x0[:4], x0[4:]
    mujoco.mj_forward(model, data)
    X_mj, E_mj = np.empty_like(X), np.empty(n + 1)
    X_mj[0], E_mj[0] = x0, data.energy.sum()
    for i in range(n):
        mujoco.mj_step(model, data)
        mujoco.mj_forward(model, data)     # energy of the new state (mj_step reports the old)
        X_mj[i + 1, :4], X_mj[i + 1, 4:], E_mj[i + 1] = data.qpos, data.qvel, data.energy.sum()

    E = np.array(f.map(n + 1)(X[:, :4].T, X[:, 4:].T)[3]).ravel()
    assert np.ptp(X[:, 1]) > 3 * np.pi                   # a non-trivial, spinning motion
    dq = np.abs(X[:, :4] - X_mj[:, :4]).max()
    ds = np.abs(X[:, 4:] - X_mj[:, 4:]).max()
    # Expected ~1e-8 if the two RK4s differed in detail; they do not: measured 8.4e-14 rad
    # (or m) and 4.0e-13 rad/s (or m/s). A wrong M or bias term diverges at O(0.1) within 3 s.
    assert dq < 1e-9, dq
    assert ds < 1e-8, ds
    # Energy: E ~ 26.6 J; measured |E - E_mujoco| 6.6e-13 J, and both drift 1.5e-8 J (RK4).
    assert np.abs(E - E_mj).max() < 1e-9 * abs(E[0]), np.abs(E - E_mj).max()
    assert np.ptp(E) < 1e-6 * abs(E[0]), np.ptp(E)


# ---- 2. momentum of a free system with internal loads ---------------------------------------

HULL_MASS, FLAP_MASS = 4.0, 1.5                          # kg
HULL_INERTIA = inertia_tensor((0.6, 0.9, 1.2), (1, 2, -1), 0.5)
FLAP_INERTIA = inertia_tensor((0.05, 0.20, 0.22), (2, -1, 1), 1.3)
HULL_REST = np.array([1.0, -2.0, 0.5])                   # o_hull at rest, n-frame (m)
HULL_COG = np.array([0.1, -0.05, 0.08])                  # from o_hull, hull axes (m)
HINGE_POINT = np.array([0.7, 0.1, -0.2])                 # from o_hull, hull axes (m)
FLAP_COG = np.array([0.35, 0.05, 0.1])                   # from the hinge, flap axes (m)
HINGE_AXIS = np.array([0.2, 1.0, 0.3]) / np.linalg.norm([0.2, 1.0, 0.3])
HINGE_STIFFNESS, HINGE_DAMPING = 6.0, 0.05               # N m/rad, N m s/rad


def free_pair_poses(q):
    """[(R_b^n, CoG in n)] of hull and flap for q = [x, y, z, phi, theta, psi, hinge] rows:
    R_hull = Rz(psi) Ry(theta) Rx(phi), written out here (complex-safe for complex steps)."""
    R0 = rot((0, 0, 1), q[:, 5]) @ rot((0, 1, 0), q[:, 4]) @ rot((1, 0, 0), q[:, 3])
    o0 = HULL_REST + q[:, :3]
    R1 = R0 @ rot(HINGE_AXIS, q[:, 6])
    o1 = o0 + R0 @ HINGE_POINT
    return [(R0, o0 + R0 @ HULL_COG), (R1, o1 + R1 @ FLAP_COG)]


def free_pair_qdot(q, s):
    """q_dot from s = [v_o (hull axes), w (hull axes), hinge rate]: position rate R v and
    Fossen's ZYX Euler-angle rates (Fossen 2011, Eq. 2.41), written out independently of K."""
    phi, theta = q[:, 3], q[:, 4]
    p, r_q, r = s[:, 3], s[:, 4], s[:, 5]
    R0 = free_pair_poses(q)[0][0]
    return np.c_[np.einsum("nij,nj->ni", R0, s[:, :3]),
                 p + (r_q * np.sin(phi) + r * np.cos(phi)) * np.tan(theta),
                 r_q * np.cos(phi) - r * np.sin(phi),
                 (r_q * np.sin(phi) + r * np.cos(phi)) / np.cos(theta),
                 s[:, 6]]


def free_pair_momenta(X):
    """Linear momentum sum m v_c, angular momentum about the n origin
    sum (c x m v_c + R I_c R^T w_n), kinetic energy, all in the n-frame. Velocities are exact
    complex-step derivatives of the poses along q_dot: v_c = d c / dt, S(w_n) = R_dot R^T."""
    q, s = X[:, :7], X[:, 7:14]
    h = 1e-30
    poses, perturbed = free_pair_poses(q), free_pair_poses(q + 1j * h * free_pair_qdot(q, s))
    linear, angular, kinetic, asymmetry = 0.0, 0.0, 0.0, 0.0
    for (R, c), (R_c, c_c), m, I in zip(poses, perturbed, (HULL_MASS, FLAP_MASS),
                                        (HULL_INERTIA, FLAP_INERTIA)):
        R, c = R.real, c.real
        v = c_c.imag / h
        Wn = (R_c.imag / h) @ np.swapaxes(R, 1, 2)
        asymmetry = max(asymmetry, np.abs(Wn + np.swapaxes(Wn, 1, 2)).max())
        w = np.c_[Wn[:, 2, 1], Wn[:, 0, 2], Wn[:, 1, 0]]
        I_n = R @ I @ np.swapaxes(R, 1, 2)
        Iw = np.einsum("nij,nj->ni", I_n, w)
        linear = linear + m * v
        angular = angular + np.cross(c, m * v) + Iw
        kinetic = kinetic + 0.5 * m * np.sum(v * v, axis=1) + 0.5 * np.sum(w * Iw, axis=1)
    return linear, angular, kinetic, asymmetry


def test_free_body_with_damped_flap_conserves_momentum():
    """No gravity, no hydrodynamics: the only load is the hinge's spring-damper torque
    -(k q + c q_dot) on its own coordinate, i.e. equal and opposite torques on hull and flap.
    Linear and angular momentum (about the n origin) must stay constant, and kinetic +
    spring energy must fall by exactly the damper's work int c q_dot^2 dt (a 15th state)."""
    tree = Tree([Link("hull", -1, tuple(HULL_REST), tuple(HULL_COG), HULL_MASS, HULL_INERTIA,
                      free=True),
                 Link("flap", 0, tuple(HINGE_POINT), tuple(FLAP_COG), FLAP_MASS, FLAP_INERTIA,
                      (Motion("revolute", tuple(HINGE_AXIS)),))])
    x = ca.SX.sym("x", 15)
    q, s = x[:7], x[7:14]
    tau = ca.vertcat(ca.DM.zeros(6, 1), -(HINGE_DAMPING * s[6] + HINGE_STIFFNESS * q[6]))
    rhs = ca.Function("rhs", [x], [ca.vertcat(
        tree.K(q) @ s, ca.solve(tree.mass_matrix(q), tau - tree.bias(q, s)),
        HINGE_DAMPING * s[6] ** 2)])
    dt, duration = 1e-3, 20.0
    x0 = np.r_[0.1, -0.2, 0.05, 0.2, -0.3, 0.4, 0.3,      # pose: position, Euler angles, hinge
               0.5, -0.2, 0.4, 0.2, -0.1, 0.7, 2.0,       # s: v_o, w (hull axes), hinge rate
               0.0]                                       # damper work
    X = trajectory(rk4_run(rhs, 15, dt, round(duration / dt)), x0)[::10]

    linear, angular, kinetic, asymmetry = free_pair_momenta(X)
    energy = kinetic + 0.5 * HINGE_STIFFNESS * X[:, 6] ** 2
    work = X[:, 14]
    # the run is what it should be: pitch far from +-90 deg (max measured 38 deg), ~19 hinge
    # oscillations, a tumbling hull, and the damper takes a fair share of the energy
    assert np.abs(X[:, 4]).max() < np.radians(60)
    assert np.sum(np.diff(np.sign(X[:, 13])) != 0) > 30
    assert np.ptp(X[:, 5]) > 1.0
    assert work[-1] > 0.15 * energy[0]                    # measured 0.55 J of 2.46 J
    assert asymmetry < 1e-10                              # R_dot R^T skew: R really orthogonal
    # own kinetic energy against the library's (same quantity, different code): rounding,
    # measured 1.8e-15 J
    q_, s_ = ca.SX.sym("q", 7), ca.SX.sym("s", 7)
    T_lib = np.array(ca.Function("T", [q_, s_], [tree.kinetic_energy(q_, s_)]).map(X.shape[0])(
        X[:, :7].T, X[:, 7:14].T)).ravel()
    assert np.abs(T_lib - kinetic).max() < 1e-12 * kinetic.max()
    # RK4 at 1 ms with rates ~ 2.5 rad/s: truncation ~1e-12 over 20 s. Measured drifts:
    # linear momentum 5.5e-12, angular 3.2e-12 (relative to their largest component),
    # energy balance 4.3e-12 of E0. A missing or wrong bias, K, or internal torque
    # mapping gives O(1e-3) or worse.
    assert np.abs(linear - linear[0]).max() < 1e-9 * np.abs(linear[0]).max()
    assert np.abs(angular - angular[0]).max() < 1e-9 * np.abs(angular[0]).max()
    assert np.abs(energy + work - energy[0]).max() < 1e-9 * energy[0]


# ---- 3. energy balance of a scene with dissipative loads ------------------------------------

PTO_DAMPING = 0.05                                       # N m s/rad, elbow
FRICTION = {"wrist": (0.01, 0.02, 0.01),                 # viscous, Coulomb, velocity scale
            "shoulder": (0.005, 0.03, 0.02)}             # (N m s/rad, N m, rad/s)
SCENE = {
    "name": "independent_chain",
    "water": {"g": G},
    "body": [
        {"name": "upper", "mass": 3.0, "cog": [0.05, 0.02, 0.45], "hydro": False,
         "inertia": [[0.30, 0.02, -0.01], [0.02, 0.25, 0.03], [-0.01, 0.03, 0.10]]},
        {"name": "middle", "mass": 2.0, "cog": [0.1, -0.05, 1.2], "hydro": False,
         "inertia": [[0.12, -0.01, 0.02], [-0.01, 0.15, 0.01], [0.02, 0.01, 0.05]]},
        {"name": "lower", "mass": 1.2, "cog": [0.05, 0.1, 1.9], "hydro": False,
         "inertia": [[0.05, 0.005, 0.0], [0.005, 0.06, -0.01], [0.0, -0.01, 0.03]]},
    ],
    "joint": [
        {"name": "shoulder", "type": "revolute", "parent": "ground", "child": "upper",
         "point": [0, 0, 0], "axis": [0, 1, 0]},
        {"name": "elbow", "type": "revolute", "parent": "upper", "child": "middle",
         "point": [0.0, 0.0, 0.9], "axis": [1, 0, 0]},
        {"name": "wrist", "type": "revolute", "parent": "middle", "child": "lower",
         "point": [0.05, 0.0, 1.5], "axis": [0.3, 0.8, 0.2]},
    ],
    "pto": [{"name": "elbow_pto", "joint": "elbow", "damping": PTO_DAMPING}],
    "friction": [{"name": f"{joint}_friction", "joint": joint, "viscous": viscous,
                  "coulomb": coulomb, "velocity_scale": scale}
                 for joint, (viscous, coulomb, scale) in FRICTION.items()],
}


@pytest.mark.filterwarnings("ignore:.*rest is not an equilibrium:RuntimeWarning")
def test_scene_chain_energy_balance_with_pto_and_friction():
    """Scene -> build_plant (gravity through loads.gravity_forces, PTO through
    loads.pto_forces, friction through loads.friction_forces), 200 s with RK4 at dt = 2 ms on
    [x; W]: W' = c_pto v_e^2 + sum (b v^2 + F_c tanh(v / v_s) v), the dissipated power written
    from the scene's numbers. Then (T + V)(t) - (T + V)(0) = -W(t) at every sample, with
    T and V the Tree's kinetic and gravitational potential energies (both checked against
    sympy in test_multibody.py and against MuJoCo above). The library's own compiled RK4
    (simulate) must reproduce the trajectory."""
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import parse_scene
    from mbcontrol.sim import simulate

    plant = build_plant(parse_scene(SCENE, Path("independent_chain.toml")))
    tree = plant.topology.tree
    assert plant.states[:3] == ("shoulder", "elbow", "wrist") and plant.nx == 6
    index = {name: i for i, name in enumerate(plant.states[:3])}

    x = ca.SX.sym("x", plant.nx + 1)
    v = x[3:6]
    dissipated = PTO_DAMPING * v[index["elbow"]] ** 2
    for joint, (viscous, coulomb, scale) in FRICTION.items():
        vj = v[index[joint]]
        dissipated += viscous * vj ** 2 + coulomb * ca.tanh(vj / scale) * vj
    u, w = ca.DM.zeros(len(plant.inputs)), ca.DM.zeros(len(plant.disturbances))
    rhs = ca.Function("rhs", [x], [ca.vertcat(plant.f(x[:plant.nx], u, w, plant.p0), dissipated)])
    dt, duration = 2e-3, 200.0
    n = round(duration / dt)
    x0 = np.r_[1.0, -0.8, 0.5, 0.0, 1.5, -2.0, 0.0]
    X = trajectory(rk4_run(rhs, plant.nx + 1, dt, n), x0)

    q, s = ca.SX.sym("q", 3), ca.SX.sym("s", 3)
    energy = ca.Function("E", [q, s], [tree.kinetic_energy(q, s) + tree.potential_energy(q, G)])
    Xs = X[::10]
    E = np.array(energy.map(Xs.shape[0])(Xs[:, :3].T, Xs[:, 3:6].T)).ravel()
    W = Xs[:, 6]
    ratio = (E[0] - E[-1]) / W[-1]
    # a real long run: most of the energy is dissipated, the chain still moves at 200 s
    assert W[-1] > 20.0                                   # J; measured 25.5 J
    assert np.abs(X[-1, 3:6]).max() > 1e-3
    # RK4 at 2 ms (the tanh friction has time scales of ~10 ms): measured ratio
    # 1 - 1.5e-9 and largest imbalance 3.9e-8 J over the run. A sign error in a load, a wrong
    # gravity application point or a missing bias term gives O(1e-2) or worse.
    assert abs(ratio - 1) < 1e-6, ratio
    assert np.abs(E - E[0] + W).max() < 1e-6 * W[-1], np.abs(E - E[0] + W).max()

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        ds = simulate(plant, duration=duration, dt=dt, x0=x0[:plant.nx])
    # same RK4 on the same f: rounding only (measured 9.7e-13 over 200 s)
    assert np.abs(ds.state.values - X[:, :plant.nx]).max() < 1e-9
