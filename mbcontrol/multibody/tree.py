"""Joint tree (forest) -> P(q), Pdot^T s, M^g, C^g s and generalised forces (ERRATA section 4).

Frames: the n-frame is NED (x forward, y starboard, z down, m). Every body frame b_k has
its origin o_k at the joint point and is aligned with the n-frame at q = 0. Body twists are
CoG twists ``nu_k = [v_ck^bk; w_nbk^bk]`` (m/s, rad/s), as in the paper's Eq. 1.

Coordinates: a revolute/prismatic motion has one coordinate (rad or m) with ``s = q_dot``;
a free root has ``q = [x, y, z, phi, theta, psi]`` (m, rad; n-frame position of o_k relative
to its rest position ``joint_point``, and ZYX Euler angles) and ``s = [v_o^b; w^b]``, so
``q_dot = K(q) s`` (ERRATA G4). As for every joint, q = 0 is the reference configuration.

Everything is built from one parents-first O(N) recursion (``_walk``); the bias Pdot^T s
comes from the ERRATA beta recursion, never from symbolic differentiation.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from .rotations import R_zyx, Rot, S, T_zyx, as_casadi

FREE_DOF_NAMES = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
_MOTION_KINDS = ("revolute", "prismatic")


@dataclass(frozen=True)
class Motion:
    """One elementary joint motion: ``kind`` "revolute" | "prismatic" along unit ``axis``.

    The axis is given in the frame reached so far (parent-body axes at q = 0, since all
    frames are aligned there) and is normalised on construction.
    """

    kind: str
    axis: tuple[float, float, float]

    def __post_init__(self):
        if self.kind not in _MOTION_KINDS:
            raise ValueError(f"Motion.kind must be one of {_MOTION_KINDS}, got {self.kind!r}")
        a = np.asarray(self.axis, dtype=float).reshape(-1)
        norm = np.linalg.norm(a)
        if a.shape != (3,) or not np.isfinite(norm) or norm < 1e-12:
            raise ValueError(f"Motion.axis must be a non-zero finite 3-vector, got {self.axis!r}")
        object.__setattr__(self, "axis", tuple(float(x) for x in a / norm))


@dataclass(frozen=True)
class Link:
    """A rigid body and the joint to its parent.

    parent: index of the parent link (-1 = ground / n-frame); parents come first.
    joint_point: (3,) o_k relative to the parent's origin, parent axes, at q = 0 (m).
    cog: (3,) CoG relative to o_k in b_k axes (m). mass: kg. inertia: (3,3) about the CoG
    in b_k axes (kg m^2). Parameters may be floats or CasADi SX.
    motions: elementary motions applied in order; () is a fixed joint.
    free: 6-DOF free joint (roots only, no motions); q = [x, y, z] + ZYX Euler angles, with
    o_k = joint_point + [x, y, z] in n axes.
    coordinate_names: optional, one per coordinate.
    """

    name: str
    parent: int
    joint_point: object
    cog: object
    mass: object
    inertia: object
    motions: tuple[Motion, ...] = ()
    free: bool = False
    coordinate_names: tuple[str, ...] = ()

    def __post_init__(self):
        object.__setattr__(self, "motions", tuple(self.motions))
        if not all(isinstance(m, Motion) for m in self.motions):
            raise ValueError(f"link {self.name!r}: motions must be Motion instances")
        if self.free and self.parent != -1:
            raise ValueError(f"link {self.name!r}: a free joint needs parent == -1, got {self.parent}")
        if self.free and self.motions:
            raise ValueError(f"link {self.name!r}: a free joint takes no motions")
        n = 6 if self.free else len(self.motions)
        if self.coordinate_names and len(self.coordinate_names) != n:
            raise ValueError(f"link {self.name!r}: {n} coordinate names expected, "
                             f"got {len(self.coordinate_names)}")

    def default_coordinate_names(self) -> tuple[str, ...]:
        if self.coordinate_names:
            return tuple(self.coordinate_names)
        if self.free:
            return tuple(f"{self.name}__{dof}" for dof in FREE_DOF_NAMES)
        return tuple(f"{self.name}__{i}" for i in range(len(self.motions)))


@dataclass(frozen=True)
class _Step:
    """One elementary transform from a frame to the next (massless intermediates between)."""

    kind: str                 # "revolute" | "prismatic" | "fixed"
    axis: tuple | None        # unit axis, None for fixed
    offset: object            # origin of the next frame from the previous one at q = 0
    index: int                # coordinate index, -1 for fixed


@dataclass
class _State:
    """Kinematics of one frame: pose, Jacobians of the origin twist and, given s, its bias."""

    R: object                 # R_b^n
    o: object                 # origin, n axes (m)
    V: object                 # 3 x n_s: v_o^b = V s
    W: object                 # 3 x n_s: w^b = W s
    v: object = None          # v_o^b (m/s)
    w: object = None          # w^b (rad/s)
    bv: object = None         # (dV/dt) s, body-component derivative at s_dot = 0
    bw: object = None         # (dW/dt) s


class Tree:
    """A forest of rigid bodies joined by revolute, prismatic, composite, fixed or free joints.

    Methods take CasADi column vectors q (n_q) and s (n_s) and return CasADi expressions.
    """

    def __init__(self, links: list[Link]):
        self.links = list(links)
        self._check_topology()
        self.body_names = [link.name for link in self.links]
        self.coordinate_names: list[str] = []
        self._first_coordinate: list[int] = []
        for link in self.links:
            self._first_coordinate.append(len(self.coordinate_names))
            self.coordinate_names.extend(link.default_coordinate_names())
        self._check_names()
        self.n_q = self.n_s = len(self.coordinate_names)
        # inertia on single generalised speeds (kg or kg m^2), e.g. a PTO drivetrain's
        # gear_ratio^2 J on its joint: constant, so it adds no Coriolis terms
        self.coordinate_inertia = np.zeros(self.n_s)
        self._joint_point = [as_casadi(link.joint_point, (3, 1)) for link in self.links]
        self._steps = [self._compile_steps(k) for k in range(len(self.links))]
        self._cog = [as_casadi(link.cog, (3, 1)) for link in self.links]
        self._mass = [as_casadi(link.mass, (1, 1)) for link in self.links]
        self._inertia = [as_casadi(link.inertia, (3, 3)) for link in self.links]

    # ---- construction -------------------------------------------------------------------
    def _check_topology(self):
        if not self.links:
            raise ValueError("a Tree needs at least one link")
        for k, link in enumerate(self.links):
            if not (-1 <= link.parent < k):
                raise ValueError(f"link {k} ({link.name!r}): parent {link.parent} must be -1 "
                                 f"or the index of an earlier link (parents first)")

    def _check_names(self):
        for kind, names in (("body", self.body_names), ("coordinate", self.coordinate_names)):
            if len(set(names)) != len(names):
                raise ValueError(f"duplicate {kind} names in {names}")
            dotted = [n for n in names if "." in n]
            if dotted:
                raise ValueError(f"{kind} names must not contain dots: {dotted}")

    def _compile_steps(self, k: int) -> list[_Step]:
        link, offset = self.links[k], self._joint_point[k]
        if link.free:
            return []
        if not link.motions:
            return [_Step("fixed", None, offset, -1)]
        steps, first = [], self._first_coordinate[k]
        for i, motion in enumerate(link.motions):
            # Only the first step carries the joint point; later ones start where it ends.
            steps.append(_Step(motion.kind, motion.axis, offset if i == 0
                               else ca.DM.zeros(3, 1), first + i))
        return steps

    # ---- the recursion ------------------------------------------------------------------
    def _root_state(self, k: int, q, s) -> _State:
        n = self.n_s
        if not self.links[k].free:   # parent is the n-frame: at rest, V = W = 0
            zero = ca.DM.zeros(3, 1)
            return _State(ca.DM.eye(3), zero, ca.DM(3, n), ca.DM(3, n),
                          zero, zero, zero, zero)
        i = self._first_coordinate[k]
        V, W = ca.DM(3, n), ca.DM(3, n)
        V[:, i:i + 3] = ca.DM.eye(3)
        W[:, i + 3:i + 6] = ca.DM.eye(3)
        state = _State(R_zyx(q[i + 3:i + 6]), self._joint_point[k] + q[i:i + 3], V, W)
        if s is not None:   # s is the body twist itself, so its bias is zero (ERRATA section 4)
            zero = ca.DM.zeros(3, 1)
            state.v, state.w, state.bv, state.bw = s[i:i + 3], s[i + 3:i + 6], zero, zero
        return state

    def _advance(self, p: _State, step: _Step, q, s) -> _State:
        """ERRATA section 4 recursion through one elementary joint (Q = R_child^parent^T)."""
        i, a = step.index, (ca.DM(step.axis) if step.axis else None)
        if step.kind == "revolute":
            R_rel, rho = Rot(step.axis, q[i]), step.offset
        elif step.kind == "prismatic":
            R_rel, rho = ca.DM.eye(3), step.offset + a * q[i]
        else:
            R_rel, rho = ca.DM.eye(3), step.offset
        Q = R_rel.T
        c = _State(p.R @ R_rel, p.o + p.R @ rho, Q @ (p.V - S(rho) @ p.W), Q @ p.W)
        if i >= 0:   # this motion's own column: a e_i^T
            unit = ca.DM(1, self.n_s)
            unit[i] = 1
            if step.kind == "revolute":
                c.W = c.W + a @ unit
            else:
                c.V = c.V + a @ unit
        if s is None:
            return c
        Qw = Q @ p.w
        v_at_joint = Q @ (p.v + ca.cross(p.w, rho))
        c.w, c.v = Qw, v_at_joint
        c.bw, c.bv = Q @ p.bw, Q @ (p.bv + ca.cross(p.bw, rho))
        if step.kind == "revolute":     # sigma_k = s_i
            c.w = c.w + a * s[i]
            c.bw = c.bw + ca.cross(Qw, a) * s[i]
            c.bv = c.bv + ca.cross(v_at_joint, a) * s[i]
        elif step.kind == "prismatic":  # delta_k = s_i
            c.v = c.v + a * s[i]
            c.bv = c.bv + ca.cross(Qw, a) * s[i]
        return c

    def _walk(self, q, s=None, upto: int | None = None) -> list:
        """States of the real bodies, parents first: all of them (O(N) elementary steps), or
        with upto = k body k and its ancestors only (the others None): O(depth), so that a
        farm's N per-body queries cost O(N), not O(N^2)."""
        chain = range(len(self.links)) if upto is None else self._ancestry(upto)
        states: list = [None] * (len(self.links) if upto is None else upto + 1)
        for k in chain:
            parent = self.links[k].parent
            state = self._root_state(k, q, s) if parent < 0 else states[parent]
            for step in self._steps[k]:
                state = self._advance(state, step, q, s)
            states[k] = state
        return states

    def _ancestry(self, k: int) -> list[int]:
        """Body k's ancestors among the real bodies, root first, then k."""
        chain = []
        while k >= 0:
            chain.append(k)
            k = self.links[k].parent
        return chain[::-1]

    # ---- kinematics ---------------------------------------------------------------------
    def K(self, q):
        """``q_dot = K(q) s``, n_q x n_s: identity except diag(R(Theta), T(Theta)) for free roots."""
        blocks = []
        for k, link in enumerate(self.links):
            if link.free:
                Theta = q[self._first_coordinate[k] + 3:self._first_coordinate[k] + 6]
                blocks += [R_zyx(Theta), T_zyx(Theta)]
            elif link.motions:
                blocks.append(ca.DM.eye(len(link.motions)))
        return ca.diagcat(*blocks)

    def euler_singularity_margin(self, q):
        """|cos(theta)| per free root (pitch theta); K(q) is singular where it reaches 0."""
        margins = [ca.fabs(ca.cos(q[self._first_coordinate[k] + 4]))
                   for k, link in enumerate(self.links) if link.free]
        return ca.vertcat(*margins) if margins else ca.DM.zeros(0, 1)

    def rotation(self, q, k: int):
        """R_b^n of body k, 3x3 (body components -> n components)."""
        return self._walk(q, upto=k)[k].R

    def origin(self, q, k: int):
        """n-frame position of o_k (m), 3x1."""
        return self._walk(q, upto=k)[k].o

    def point(self, q, k: int, r_local):
        """n-frame position (m) of a point fixed in body k, ``r_local`` in b_k axes from o_k."""
        state = self._walk(q, upto=k)[k]
        return state.o + state.R @ as_casadi(r_local, (3, 1))

    def cog(self, q, k: int):
        """n-frame position of the CoG of body k (m)."""
        return self.point(q, k, self._cog[k])

    def point_velocity(self, q, s, k: int, r_local):
        """n-axes velocity (m/s) of a point fixed in body k (``r_local``: b_k axes, from o_k)."""
        state = self._walk(q, s, upto=k)[k]
        return state.R @ (state.v + ca.cross(state.w, as_casadi(r_local, (3, 1))))

    def _P_block(self, state: _State, k: int):
        """P_k (n_s x 6): P_k^T = H(r_ck)[V_k; W_k] = [V_k - S(r_ck) W_k; W_k]."""
        return ca.vertcat(state.V - S(self._cog[k]) @ state.W, state.W).T

    def _P_from(self, states: list[_State]):
        return ca.horzcat(*[self._P_block(st, k) for k, st in enumerate(states)])

    def P(self, q):
        """Velocity transformation matrix, n_s x 6N: nu = P^T s (paper Eq. 2, ERRATA section 4)."""
        return self._P_from(self._walk(q))

    def _nu_k(self, state: _State, k: int):
        """CoG twist of body k from its origin twist: v_c = v_o + w x r_c."""
        return ca.vertcat(state.v + ca.cross(state.w, self._cog[k]), state.w)

    def _beta_from(self, states: list[_State]):
        """(Pdot^T s)_k = [beta_v + beta_w x r_ck; beta_w] (ERRATA section 4), stacked."""
        return ca.vertcat(*[ca.vertcat(st.bv + ca.cross(st.bw, self._cog[k]), st.bw)
                            for k, st in enumerate(states)])

    def body_velocity(self, q, s):
        """CoG twists nu = P^T s (6N; m/s, rad/s), from the recursion's velocities."""
        return ca.vertcat(*[self._nu_k(st, k) for k, st in enumerate(self._walk(q, s))])

    def Pdot_T_s(self, q, s):
        """Bias (dP^T/dt) s (6N; m/s^2, rad/s^2): nu_dot = P^T s_dot + this (beta recursion)."""
        return self._beta_from(self._walk(q, s))

    # ---- dynamics -----------------------------------------------------------------------
    def M_RB_b(self):
        """Block-diagonal rigid-body inertia, 6N x 6N, blocks diag(m_k I3, I_ck) (Eq. 4)."""
        return ca.diagcat(*[ca.diagcat(m * ca.DM.eye(3), inertia)
                            for m, inertia in zip(self._mass, self._inertia)])

    def _body_mass(self, added_mass_b):
        M = self.M_RB_b()
        if added_mass_b is None:
            return M
        return M + as_casadi(added_mass_b, (6 * len(self.links), 6 * len(self.links)))

    def C_RB_b_k(self, k: int, nu_k):
        """Skew-symmetric Coriolis-centripetal matrix of body k, 6x6 (paper Eq. 5)."""
        m, v, w = self._mass[k], nu_k[0:3], nu_k[3:6]
        return ca.vertcat(ca.horzcat(ca.DM.zeros(3, 3), -m * S(v)),
                          ca.horzcat(-m * S(v), -S(self._inertia[k] @ w)))

    def mass_matrix(self, q, added_mass_b=None):
        """M^g = P (M_RB^b + A^b) P^T, n_s x n_s (kg, kg m, kg m^2 entries)."""
        P = self.P(q)
        M = P @ self._body_mass(added_mass_b) @ P.T
        return M + ca.diag(ca.DM(self.coordinate_inertia)) if self.coordinate_inertia.any() else M

    def bias(self, q, s, added_mass_b=None):
        """C^g s = P M^b (Pdot^T s) + P C_RB^b(nu) nu, n_s (ERRATA G6, section 4).

        M^b = M_RB^b + A^b (``added_mass_b``, 6N x 6N, may couple bodies); C_RB is rigid-body
        only (Eq. 5 per body): as in the ERRATA, no added-mass Coriolis (Munk) term C_A(nu) nu.
        Equations of motion: M^g s_dot + C^g s = generalised forces.
        """
        states = self._walk(q, s)
        nus = [self._nu_k(st, k) for k, st in enumerate(states)]
        coriolis = ca.vertcat(*[self.C_RB_b_k(k, nu_k) @ nu_k for k, nu_k in enumerate(nus)])
        beta = self._beta_from(states)
        return self._P_from(states) @ (self._body_mass(added_mass_b) @ beta + coriolis)

    def generalized_force(self, q, k: int, wrench_b):
        """P_k wrench (n_s): ``wrench_b = [force (N); moment (N m)]`` about CoG k, b_k axes."""
        state = self._walk(q, upto=k)[k]
        return self._P_block(state, k) @ as_casadi(wrench_b, (6, 1))

    def point_force(self, q, k: int, r_local, force_n):
        """Generalised force (n_s) of ``force_n`` (N, n axes) applied at a point of body k.

        ``r_local`` is in b_k axes from o_k (m). The force is moved to a CoG wrench in body
        axes with H^T(r - r_ck) (ERRATA G12) and mapped with P_k.
        """
        state = self._walk(q, upto=k)[k]
        f_b = state.R.T @ as_casadi(force_n, (3, 1))
        arm = as_casadi(r_local, (3, 1)) - self._cog[k]
        return self._P_block(state, k) @ ca.vertcat(f_b, ca.cross(arm, f_b))

    def gravity(self, q, g):
        """Generalised gravity force (n_s, N or N m): weights m_k g along +z_n at each CoG."""
        total = ca.DM.zeros(self.n_s, 1)
        for k, state in enumerate(self._walk(q)):
            weight_b = state.R.T @ ca.vertcat(0, 0, self._mass[k] * g)
            total = total + self._P_block(state, k) @ ca.vertcat(weight_b, ca.DM.zeros(3, 1))
        return total

    def kinetic_energy(self, q, s):
        """Rigid-body kinetic energy (J): sum 1/2 (m_k v_ck.v_ck + w_k . I_ck w_k)."""
        energy = 0
        for k, state in enumerate(self._walk(q, s)):
            nu = self._nu_k(state, k)
            v, w = nu[0:3], nu[3:6]
            energy = energy + 0.5 * (self._mass[k] * ca.dot(v, v) + ca.dot(w, self._inertia[k] @ w))
        return energy

    def potential_energy(self, q, g):
        """Gravitational potential energy (J) = -sum m_k g z_ck (z down; zero at z = 0)."""
        energy = 0
        for k, state in enumerate(self._walk(q)):
            z_cog = (state.o + state.R @ self._cog[k])[2]
            energy = energy - self._mass[k] * g * z_cog
        return energy
