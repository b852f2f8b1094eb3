"""An exact shortcut for the MPC's dense QP, tried before qpOASES (controllers.mpc_qp).

    minimise 1/2 x'Hx + g'x   subject to   lo <= C x <= hi,   C = [I; A],   H positive definite

H and A are fixed, so H^-1 C' and C H^-1 C' are computed once and an equality-constrained
QP on a working set W costs one |W| x |W| solve. Per call:
  1. from the previous call's active set (the plan moves little from one step to the next),
     a few primal-dual active-set iterations (keep the rows whose multipliers have the right
     sign, add every violated row);
  2. if those do not settle, a few steps of Goldfarb and Idnani's dual active-set method
     from that set less its rows of the wrong sign (dual feasible all along, one row added
     or dropped per step);
  3. if that fails too (an infeasible QP, a singular working set, more steps needed), None:
     the caller solves with qpOASES (and reports its status, as without the shortcut).
     After SKIP_AFTER such calls in a row only one call in PROBE_EVERY tries (tight limits).
Whatever step 1 or 2 returns is accepted only if it passes the QP's optimality conditions
(stationarity, primal feasibility on every original row, multiplier signs, complementarity)
to qpOASES's own tolerances, so the result is the QP's unique optimum, not an approximation.
Measured on the demo's rate-limited MPC: ~70 % of calls settle in step 1 (1-2 iterations).
Parallel rows (the stroke and the first step's force, an envelope's heave and pitch rows)
are merged into one row with the tightest bounds: a working set must be independent.
`ActiveSetQp` holds only what H and A fix (built once, never changed by a solve); what one
run's calls carry from one to the next (the last active set, the counters) is its
`ActiveSetMemory`, passed to every call.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import lapack

PRIMAL_TOL = 1e-9      # scaled units (the QP is scaled to O(1)): qpOASES's own ~1e-9
DUAL_TOL = 1e-10       # a multiplier of the wrong sign beyond this is not optimal
PDAS_ITERATIONS = 4    # from the previous active set; beyond, the dual method
DUAL_STEPS = 8         # the dual method's steps; beyond, qpOASES is faster (tight limits,
                       # an infeasible QP: the steps would run on in Python)
SKIP_AFTER, PROBE_EVERY = 3, 8   # after 3 calls in a row left to qpOASES, try 1 call in 8
                                  # (tight limits: many rows change per step, few calls settle)
PARALLEL = 1 - 1e-12   # |cos| between rows treated as the same constraint


class ActiveSetMemory:
    """One run's warm start for an ActiveSetQp: the last active set (W: merged rows, up: at
    their upper bounds), counts (calls settled by each step, and those left to the caller)
    and misses (calls in a row left to the caller)."""

    def __init__(self):
        self.W, self.up = np.zeros(0, int), np.zeros(0, bool)
        self.counts = {"warm": 0, "dual": 0, "fallback": 0, "skipped": 0}
        self.misses = 0


class ActiveSetQp:
    """Verified solves of min 1/2 x'Hx + g'x, lbx <= x <= ubx, lba <= A x <= uba (H, A
    fixed); each call reads and updates the caller's ActiveSetMemory (`memory()`)."""

    def __init__(self, H, A):
        H, A = np.asarray(H, float), np.asarray(A, float)
        n = H.shape[0]
        self.n, self.H = n, H
        self.C = C = np.vstack([np.eye(n), A])
        rep, alpha = _parallel_groups(C)
        self.reps = reps = np.flatnonzero(rep == np.arange(C.shape[0]))
        group = np.searchsorted(reps, rep)
        self.order = np.argsort(group, kind="stable")
        self.starts = np.searchsorted(group[self.order], np.arange(reps.size))
        self.alpha, self.pos = alpha, alpha > 0
        self.Cg = Cg = C[reps]
        Hinv = np.linalg.inv(H)
        Hinv = 0.5 * (Hinv + Hinv.T)
        self.Hinv, self.HiCt = Hinv, Hinv @ Cg.T
        self.M = Cg @ self.HiCt
        self.m = reps.size
        self.group_of_row = group

    @staticmethod
    def memory() -> ActiveSetMemory:
        """A fresh warm start (no active set yet): one per run."""
        return ActiveSetMemory()

    def solve(self, g, lbx, ubx, lba, uba, memory: ActiveSetMemory):
        """x, or None when neither step found a verified optimum (then call remember)."""
        if memory.misses >= SKIP_AFTER and (memory.misses - SKIP_AFTER) % PROBE_EVERY:
            memory.misses += 1
            memory.counts["skipped"] += 1
            return None
        lo0 = np.concatenate([lbx, lba])
        hi0 = np.concatenate([ubx, uba])
        lo, hi = self._merged(lo0, hi0)
        xu = -(self.Hinv @ g)
        cxu = self.Cg @ xu
        for step, found in (("warm", self._pdas), ("dual", self._dual)):
            try:
                got = found(cxu, lo, hi, memory)
                x = None if got is None else self._verified(g, *got, xu, hi, lo, lo0, hi0)
            except (ArithmeticError, ValueError):
                x = None
            if x is not None:
                memory.W, memory.up = got[0], got[1]
                memory.counts[step] += 1
                memory.misses = 0
                return x
        memory.counts["fallback"] += 1
        memory.misses += 1
        return None

    def remember(self, lam_x, lam_a, memory: ActiveSetMemory):
        """The active set of a solve done elsewhere (nonzero multipliers: > 0 at the upper
        bound), the next call's start."""
        lam = np.concatenate([np.ravel(lam_x), np.ravel(lam_a)])
        rows = np.flatnonzero(lam != 0)
        groups, first = np.unique(self.group_of_row[rows], return_index=True)
        rows = rows[first]
        memory.W = groups
        memory.up = (lam[rows] > 0) == self.pos[rows]

    # -- the steps ---------------------------------------------------------------------
    def _merged(self, lo, hi):
        """Per group the tightest bounds on its representative row (row = alpha rep)."""
        a = self.alpha
        with np.errstate(invalid="ignore"):
            low = np.where(self.pos, lo / a, hi / a)[self.order]
            high = np.where(self.pos, hi / a, lo / a)[self.order]
        return np.maximum.reduceat(low, self.starts), np.minimum.reduceat(high, self.starts)

    def _eqp(self, W, up, cxu, lo, hi):
        """Multipliers nu (> 0 pushing down from an upper bound) of the rows W at their
        bounds, or None when the working set is singular."""
        if W.size == 0:
            return np.zeros(0)
        if W.size > self.n:
            return None
        b = np.where(up, hi[W], lo[W])
        _, _, nu, info = lapack.dgesv(self.M.take(W, 0).take(W, 1), cxu[W] - b)
        return None if info else nu

    def _pdas(self, cxu, lo, hi, memory):
        """(W, up, nu) from the last active set, adding and dropping rows wholesale."""
        W, up = memory.W, memory.up
        for _ in range(PDAS_ITERATIONS):
            nu = self._eqp(W, up, cxu, lo, hi)
            if nu is None:
                return None
            cx = cxu - self.M[:, W] @ nu
            wrong = np.where(up, nu < -DUAL_TOL, nu > DUAL_TOL)
            over, under = cx - hi > PRIMAL_TOL, lo - cx > PRIMAL_TOL
            if not (wrong.any() or over.any() or under.any()):
                return W, up, nu
            act, side = np.zeros(self.m, bool), np.zeros(self.m, bool)
            act[W[~wrong]], side[W[~wrong]] = True, up[~wrong]
            act |= over | under
            side[over], side[under] = True, False
            W = np.flatnonzero(act)
            up = side[W]
        return None

    def _dual_start(self, cxu, lo, hi, memory):
        """A dual-feasible start for the dual method: the last active set less the rows
        whose multipliers have the wrong sign (the empty set if it is singular)."""
        W, up = memory.W, memory.up
        for _ in range(PDAS_ITERATIONS):
            nu = self._eqp(W, up, cxu, lo, hi)
            if nu is None:
                break
            right = np.where(up, nu >= 0, nu <= 0)
            if right.all():
                return W, up, nu
            W, up = W[right], up[right]
        return np.zeros(0, int), np.zeros(0, bool), np.zeros(0)

    def _dual(self, cxu, lo, hi, memory):
        """(W, up, nu) by Goldfarb and Idnani's dual method from a dual-feasible start. In
        the outward form s c x <= s b (s = +1 at an upper bound) every multiplier mu >= 0
        throughout; each step adds the most violated row or drops one."""
        M = self.M
        Wa, upa, nu = self._dual_start(cxu, lo, hi, memory)
        cx = cxu - M[:, Wa] @ nu
        W, s = list(Wa), list(np.where(upa, 1.0, -1.0))
        mu = np.abs(nu)
        steps = 0
        for _ in range(DUAL_STEPS):
            viol = np.maximum(cx - hi, lo - cx)
            p = int(np.argmax(viol))
            if viol[p] <= PRIMAL_TOL:
                Wa = np.array(W, int)
                up = np.array(s) > 0
                nu = self._eqp(Wa, up, cxu, lo, hi)     # afresh, against drift
                return None if nu is None else (Wa, up, nu)
            sp = 1.0 if cx[p] > hi[p] else -1.0
            bp = hi[p] if sp > 0 else lo[p]
            mu_p = 0.0
            while True:
                steps += 1
                if steps > DUAL_STEPS:
                    return None
                Wa, sa = np.array(W, int), np.array(s)
                dcx = -sp * M[:, p]                     # C's change per unit step
                r = np.zeros(0)
                if Wa.size:
                    K = M.take(Wa, 0).take(Wa, 1) * np.outer(sa, sa)
                    _, _, r, info = lapack.dgesv(K, sa * sp * M[Wa, p])
                    if info:
                        return None
                    dcx = dcx + (M[:, Wa] * sa) @ r
                curv = -sp * dcx[p]                     # n_p' z >= 0
                pos = np.flatnonzero(r > 0)
                t1 = np.min(mu[pos] / r[pos]) if pos.size else np.inf
                t2 = (sp * cx[p] - sp * bp) / curv if curv > 1e-12 * M[p, p] else np.inf
                t = min(t1, t2)
                if not np.isfinite(t):
                    return None                         # infeasible: qpOASES reports it
                cx = cx + t * dcx
                mu = mu - t * r
                mu_p += t
                if t2 <= t1:                            # p joins the working set
                    W.append(p)
                    s.append(sp)
                    mu = np.append(mu, mu_p)
                    break
                j = int(pos[np.argmin(mu[pos] / r[pos])])   # a row leaves
                del W[j], s[j]
                mu = np.delete(mu, j)
            if len(W) > self.n:
                return None
        return None

    def _verified(self, g, W, up, nu, xu, hi, lo, lo0, hi0):
        """x from the working set W and its multipliers nu, if it meets the QP's
        optimality conditions."""
        Cw = self.Cg[W]
        x = xu - self.HiCt[:, W] @ nu
        scale = max(1.0, float(np.max(np.abs(g))))
        cx = self.C @ x
        optimal = (
            np.max(np.abs(self.H @ x + g + Cw.T @ nu), initial=0.0) <= PRIMAL_TOL * scale
            and np.max(np.where(up, -nu, nu), initial=0.0) <= DUAL_TOL * scale    # signs
            and np.max(np.abs(Cw @ x - np.where(up, hi[W], lo[W])), initial=0.0)
            <= PRIMAL_TOL                                                 # complementary
            and np.max(cx - hi0) <= PRIMAL_TOL and np.max(lo0 - cx) <= PRIMAL_TOL)
        return x if optimal else None


def _parallel_groups(C):
    """(rep, alpha): each row's representative (the first row parallel to it) and the
    factor with row = alpha rep."""
    m = C.shape[0]
    norm = np.linalg.norm(C, axis=1)
    unit = C / np.where(norm > 0, norm, 1.0)[:, None]
    rep, alpha = np.arange(m), np.ones(m)
    for i in range(m):
        if rep[i] != i or norm[i] == 0:
            continue
        same = np.flatnonzero(np.abs(unit[i + 1:] @ unit[i]) > PARALLEL) + i + 1
        same = same[rep[same] == same]
        rep[same] = i
        alpha[same] = (C[same] @ C[i]) / (C[i] @ C[i])
    return rep, alpha
