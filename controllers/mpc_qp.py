"""The MPC's quadratic programme: condensed (states eliminated), scaled, built once, solved
by qpOASES (real-time path) or cvxpy/Clarabel (prototyping path); see `controllers.mpc`.
A CondensedQp is fixed once built; what a run carries from one solve to the next (the form
that solved last, the warm-starting active set, counters) is its own `QpWork`."""
from __future__ import annotations

import numpy as np

from mbcontrol.errors import ControllerError

from .mpc_backends import CvxpyBackend, QpoasesBackend
from .mpc_blocks import block_of_step, expansion, slew_spacing


class CondensedQp:
    """The MPC's QP in the forces alone (states eliminated), scaled to O(1) and built once.

    Variables (scaled): V / F_s (B nu, block-major: the forces of U = T V, held over each
    block of `blocks` (step counts summing to N; mpc_blocks); None: one block per step, V =
    U) and, with a finite stroke limit and soft_stroke, slacks s / L_s (N nu). F_s: the force limit (or L_s / lambda_max(G) if
    unlimited); L_s: the stroke limit (or 1 m). envelope: rows (ne, nz) of outputs of the
    control plant, each scaled by its limit, kept within +-1 at the ends of steps 1..N with a
    slack each (always soft: the sea alone may take a quantity beyond it); solve's offset
    adds what no state holds (the forecast surface elevation). hull: per PTO whose limit is
    on the force its drivetrain puts on the hull (force_max_on = "hull"), (index, gear^2 J,
    gear^2 b, gear^2 K, limit): that force, u - gear^2 (J a + b v + K x), at the start and
    the end of each held step kept within the limit (hard; soft in the soft form): within a
    step it moves with the motion, smooth over a step much shorter than the wave's period.
    solve(z0, D, u_prev, warm, offset, work) -> (U (N, nu) or None, status).
    """

    def __init__(self, cp, N: int, limits: dict, *, efficiency, loss_damping,
                 force_penalty: float, stroke_penalty: float, soft_stroke: bool, solver: str,
                 winding=None, envelope=None, hull=None, blocks=None):
        nu, nz = len(cp.ptos), cp.nz
        self.N, self.nu, self.solver = N, nu, solver
        # prediction of the positions at the ends of steps 1..N
        powers = [np.eye(nz)]
        for _ in range(N):
            powers.append(cp.Ad @ powers[-1])
        Phi, Psi, Om = _predictions(cp, cp.Cp, powers, N)
        # envelope rows (ne, nz): outputs each scaled by its limit, kept within +-1 (soft)
        self.n_env = 0 if envelope is None else int(np.shape(envelope)[0])
        if self.n_env:
            self.Phi_e, self.Psi_e, self.Om_e = _predictions(cp, np.asarray(envelope, float),
                                                             powers, N)
        self.hull = list(hull or [])
        if self.hull:
            self.M_h, self.Phi_h, self.Om_h = _hull_rows(cp, self.hull, powers, N)
        self.n_hull = len(self.hull)
        L = np.eye(N * nu) - np.eye(N * nu, k=-nu)       # P -> increments
        E = np.zeros((N * nu, nu))
        E[:nu] = np.eye(nu)
        G = L @ Psi
        Gs = 0.5 * (G + G.T)
        lam = float(np.max(np.linalg.eigvalsh(Gs)))
        if lam <= 0:
            raise ControllerError("mpc: the control plant absorbs no energy from the PTO (energy "
                                  "Hessian not positive); check the PTO and the model")
        self.passivity_defect = float(max(-np.min(np.linalg.eigvalsh(Gs)) / lam, 0.0))
        force, stroke, rate = limits["force"], limits["stroke"], limits["rate"]
        Ls = float(np.max(stroke)) if np.all(np.isfinite(stroke)) else 1.0
        Fs = float(np.max(force)) if np.all(np.isfinite(force)) else Ls / lam
        r = force_penalty * lam
        # electrical power with efficiency eta: P_e = a P - (1/eta - eta)/2 |P|, a = (eta +
        # 1/eta)/2, and |P| <= (F^2/c + c v^2)/2 for any c > 0 (equal at |F| = c |v|): a
        # concave minorant, with c the device's impedance |Z_i| (the passive optimum) and
        # v = increment / dt. With increments G U + q the minimised cost (J) is
        #   U'(aG)U + a q'U + b dt/c |U|^2 + b c/dt |G U + q|^2,   b = (1/eta - eta)/4
        eta = np.tile(np.asarray(efficiency, float), N)
        a, b = 0.5 * (eta + 1 / eta), 0.25 * (1 / eta - eta)
        c = np.tile(np.asarray(loss_damping, float), N)
        loss_u, loss_v = b * cp.dt / c, b * c / cp.dt
        quad = 0.5 * (a[:, None] * G + (a[:, None] * G).T) + np.diag(loss_u) \
            + G.T @ (loss_v[:, None] * G) + r * np.eye(N * nu)
        if winding is not None:            # a drivetrain's winding loss over each held step
            quad += np.diag(np.tile(np.asarray(winding, float), N) * cp.dt)
        # scaled (objective / (F_s L_s)), clipped to PSD against round-off
        w, V = np.linalg.eigh(2 * Fs / Ls * quad)
        self.H_u = (V * np.clip(w, 2 * r * Fs / Ls * 1e-3, None)) @ V.T
        W = np.diag(a) + 2 * G.T * loss_v[None, :]          # linear term W q
        self.Qz = W @ (L @ Phi - E @ cp.Cp) / Ls             # q = Qz z0 + Qd D (scaled)
        self.Qd = W @ (L @ Om) / Ls
        self.Phi, self.Om, self.Psi = Phi, Om, Psi
        # move blocking: the QP in V (U = T V); H_u, Qz, Qd stay over U (T'. over V)
        self.blocks, self.T = blocks, expansion(blocks, N, nu)
        self.n_b = self.T.shape[1]                           # force variables, B nu
        self.block_of = block_of_step(blocks, N)             # each step's block
        self.starts = np.unique(self.block_of, return_index=True)[1]     # each block's first
        self.H_v, self.Qz_v, self.Qd_v = (self.H_u, self.Qz, self.Qd) if blocks is None else (
            self.T.T @ self.H_u @ self.T, self.T.T @ self.Qz, self.T.T @ self.Qd)
        self.Fs, self.Ls, self.stroke_penalty = Fs, Ls, stroke_penalty
        self.has_stroke = bool(np.all(np.isfinite(stroke)))
        self.stroke = np.tile(stroke, N) / Ls
        self.force = np.tile(force, self.n_b // nu) / Fs        # per variable of V
        self.has_rate = bool(np.all(np.isfinite(rate)))
        spacing = slew_spacing(blocks, N)                    # steps per block boundary
        self.rate = np.kron(spacing, rate * cp.dt) / Fs      # per block boundary
        backend = QpoasesBackend if solver == "qpoases" else CvxpyBackend
        # the exact L1 penalty makes the soft QP's solution the hard one's whenever the hard
        # QP is feasible: solve the hard QP (half the variables) and the soft one only when
        # it is infeasible
        self.soft_stroke = soft_stroke
        self.forms = [_QpForm(self, soft=False, backend=backend)]
        if (soft_stroke and self.has_stroke) or self.n_env or self.n_hull:
            self.forms.append(_QpForm(self, soft=True, backend=backend))

    def workspace(self) -> "QpWork":
        """A fresh run's solver state (no warm start): one per run."""
        return QpWork(self)

    def solve(self, z0, D, u_prev, warm=None, offset=None, work: "QpWork | None" = None):
        """(U (N, nu) N or N m, status), or (None, status) when no form could be solved.
        offset (N, ne): what the envelope rows add that no state holds (minus the forecast
        surface elevation over the limit, for a relative heave), None: nothing. work: the
        run's QpWork, read and updated (None: a fresh one, a cold start)."""
        work = self.workspace() if work is None else work
        z0, D, u_prev = np.asarray(z0, float), np.asarray(D, float), np.asarray(u_prev, float)
        free = []                                     # what each row block is with U = 0
        if self.has_stroke:
            free.append((self.Phi @ z0 + self.Om @ D.reshape(-1)) / self.Ls)
        if self.n_env:
            env = self.Phi_e @ z0 + self.Om_e @ D.reshape(-1)
            free.append(env if offset is None else env + np.asarray(offset, float).reshape(-1))
        if self.n_hull:
            free.append(self.Phi_h @ z0 + self.Om_h @ D.reshape(-1))
        q = self.Qz_v @ z0 + self.Qd_v @ D.reshape(-1)        # over V
        status = "not solved"
        # start with the form that solved last time: the hard QP is infeasible for stretches
        # (a wave group), and an active-set solver takes long to prove infeasibility
        order = list(enumerate(self.forms))
        for i, form in (order if work.last == 0 else order[::-1]):
            sol, status, slack = form.solve(q, free, u_prev, warm, memory=work.forms[i])
            if sol is not None:
                # back to the hard form once the slack is no longer used
                work.last = int(form.soft and slack > 1e-6)
                work.soft_solves += int(form.soft)
                U = sol if self.blocks is None else self.T @ sol
                return (U * self.Fs).reshape(self.N, self.nu), status
        return None, status


class QpWork:
    """One run's state of a CondensedQp: last (0: the hard form solved last, 1: the soft
    one), soft_solves (count), forms (per form its backend's memory: the warm start)."""

    def __init__(self, qp: CondensedQp):
        self.last, self.soft_solves = 0, 0
        self.forms = [form.backend.memory() for form in qp.forms]


class _QpForm:
    """One layout of the condensed QP: hard limits (variables U) or soft ones (U, slacks).
    Rows: stroke (Psi U, or Psi U -/+ s; soft in the soft form when soft_stroke), envelope
    (always soft in the soft form), hull force (soft in the soft form), then force rate
    (differences of V: the force changes only between blocks, within one step), each row
    over U taken over V by T."""

    def __init__(self, qp, *, soft: bool, backend):
        nu, nb, T = qp.nu, qp.n_b, qp.T
        self.qp, self.soft, self.n_u = qp, soft, nb
        blocks = []                      # (matrix over V, soft), in row order
        if qp.has_stroke:
            blocks.append((qp.Fs / qp.Ls * qp.Psi @ T, soft and qp.soft_stroke))
        if qp.n_env:
            blocks.append((qp.Fs * qp.Psi_e @ T, soft))
        if qp.n_hull:
            blocks.append((qp.Fs * qp.M_h @ T, soft))
        self.blocks = [is_soft for _, is_soft in blocks]
        n_s = sum(M.shape[0] for M, is_soft in blocks if is_soft)
        self.n_var = nb + n_s
        rows, col = [], 0
        for M, is_soft in blocks:
            if is_soft:
                I = np.zeros((M.shape[0], n_s))
                I[:, col:col + M.shape[0]] = np.eye(M.shape[0])
                rows += [np.hstack([M, -I]), np.hstack([M, I])]
                col += M.shape[0]
            else:
                rows.append(np.hstack([M, np.zeros((M.shape[0], n_s))]))
        if qp.has_rate:
            Dr = np.eye(nb) - np.eye(nb, k=-nu)
            rows += [np.hstack([Dr, np.zeros((nb, n_s))])]
        self.A = np.vstack(rows) if rows else np.zeros((0, self.n_var))
        self.H = np.zeros((self.n_var, self.n_var))
        self.H[:nb, :nb] = qp.H_v
        self.g_slack = np.zeros(self.n_var)
        if n_s:
            self.H[nb:, nb:] = 2 * qp.stroke_penalty * np.eye(n_s)
            self.g_slack[nb:] = qp.stroke_penalty
        self.lbx = np.concatenate([-qp.force, np.zeros(n_s)])
        self.ubx = np.concatenate([qp.force, np.full(n_s, np.inf)])
        self.backend = backend(self)

    def bounds(self, q, free, u_prev):
        """(g, lba, uba) for the linear cost term q, the free outputs per block (scaled
        positions, then envelope rows) and the last force."""
        qp, n = self.qp, self.n_u
        g = self.g_slack.copy()
        g[:n] += q
        lba, uba = [], []
        limits = ([qp.stroke] if qp.has_stroke else []) + ([1.0] if qp.n_env else []) \
            + ([1.0] if qp.n_hull else [])
        for is_soft, f, lim in zip(self.blocks, free, limits):
            f = np.asarray(f, float)
            if is_soft:
                lba += [np.full(f.size, -np.inf), -lim - f]
                uba += [lim - f, np.full(f.size, np.inf)]
            else:
                lba += [-lim - f]
                uba += [lim - f]
        if qp.has_rate:
            first = np.zeros(n)
            first[:qp.nu] = u_prev / qp.Fs
            lba += [first - qp.rate]
            uba += [first + qp.rate]
        join = (lambda parts: np.concatenate(parts) if parts else np.zeros(0))
        return g, join(lba), join(uba)

    def solve(self, q, free, u_prev, warm, memory=None):
        """(scaled forces or None, status, largest slack); memory: the backend's run state
        (QpWork.forms; None: a fresh one)."""
        g, lba, uba = self.bounds(q, free, u_prev)
        x0 = np.zeros(self.n_var)
        if warm is not None:
            shifted = np.vstack([warm[1:], warm[-1:]])[self.qp.starts]   # each block's first
            x0[:self.n_u] = shifted.ravel() / self.qp.Fs
        memory = self.backend.memory() if memory is None else memory
        sol, status = self.backend.solve(g, self.lbx, self.ubx, lba, uba, x0, memory)
        if sol is None:
            return None, status, 0.0
        return sol[:self.n_u], status, float(np.max(sol[self.n_u:], initial=0.0))


def _predictions(cp, C, powers, N):
    """(Phi, Psi, Om): outputs C z at the ends of steps 1..N, from the state (Phi, (N nc,
    nz)), the held forces (Psi, (N nc, N nu)) and the held excitation (Om, (N nc, N nd))."""
    nc, nu, nd = C.shape[0], cp.Bu.shape[1], cp.nd
    Phi = np.vstack([C @ powers[k] for k in range(1, N + 1)])
    Psi = np.zeros((N * nc, N * nu))
    Om = np.zeros((N * nc, N * nd))
    for k in range(1, N + 1):
        for j in range(k):
            step = C @ powers[k - 1 - j]
            Psi[(k - 1) * nc:k * nc, j * nu:(j + 1) * nu] = step @ cp.Bu
            Om[(k - 1) * nc:k * nc, j * nd:(j + 1) * nd] = step @ cp.Bd
    return Phi, Psi, Om


def _hull_rows(cp, hull, powers, N):
    """(M, Phi, Om): each hull-limited PTO's force on the hull over its limit at the start and
    at the end of each held step (rows: starts for steps 1..N, then ends), as M U + Phi z0 +
    Om D. At a state z, with u and d held: u - gear^2 (J a + b v + K x), a = Cv (A z + Bu u +
    Bd d) from the continuous model (the acceleration has the force's feedthrough)."""
    nu, nd, nh = cp.Bu.shape[1], cp.nd, len(hull)
    idx = [h[0] for h in hull]
    J, b, K, limit = (np.array([h[i] for h in hull], float)[:, None] for i in (1, 2, 3, 4))
    Cv, Cx = cp.Cv[idx], cp.Cp[idx]
    Ch = J * (Cv @ cp.A) + b * Cv + K * Cx                   # (nh, nz): the state's part
    S = np.zeros((nh, nu))
    S[np.arange(nh), idx] = 1.0
    Du, Dd = S - J * (Cv @ cp.Bu_c), -J * (Cv @ cp.Bd_c)     # the held force's and sea's
    Phi, Psi, Om = _predictions(cp, Ch, powers, N)           # Ch z_k at the steps' ends
    start = (np.vstack([Ch, Phi[:-nh]]), np.vstack([np.zeros((nh, N * nu)), Psi[:-nh]]),
             np.vstack([np.zeros((nh, N * nd)), Om[:-nh]]))  # Ch z_k-1: the steps' starts
    # the acceleration follows the sea at the instant, not its held (midpoint) value: over a
    # step a sphere's excitation moves by ~15 % of its amplitude. d at the steps' ends is
    # interpolated between the midpoints (extrapolated at the horizon's two ends)
    at_start, at_end = _boundaries(N)
    held_u = np.kron(np.eye(N), Du)
    scale = np.tile(1.0 / limit, (2 * N, 1))
    M = np.vstack([held_u - start[1], held_u - Psi]) * scale
    Om_h = np.vstack([np.kron(at_start, Dd) - start[2], np.kron(at_end, Dd) - Om])
    return M, -np.vstack([start[0], Phi]) * scale, Om_h * scale


def _boundaries(N: int):
    """(N, N) maps from step-midpoint values to the values at each step's start and end:
    linear between midpoints, extrapolated beyond the first and the last."""
    if N == 1:
        return np.eye(1), np.eye(1)
    mid = np.eye(N)
    ends = 0.5 * (mid[:-1] + mid[1:])                      # between steps k and k+1
    first, last = 1.5 * mid[0] - 0.5 * mid[1], 1.5 * mid[-1] - 0.5 * mid[-2]
    return np.vstack([first, ends]), np.vstack([ends, last])
