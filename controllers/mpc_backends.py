"""The MPC QP's solver backends (controllers.mpc_qp): qpOASES through CasADi's conic
interface (the real-time path, with the verified active-set shortcut of mpc_active_set) and
cvxpy with Clarabel (the prototyping path). Each is built once per QP form (H and A fixed)
and keeps a run's state in the memory it hands out."""
from __future__ import annotations

import contextlib
import io
import os
import sys

import numpy as np

from mbcontrol.console import flush_c_stdio

from .mpc_active_set import ActiveSetQp


class QpoasesBackend:
    """Dense qpOASES through CasADi's conic interface; H and A fixed, built once. On the hard
    form each call first tries the verified active-set shortcut (mpc_active_set: the same
    optimum, and CasADi's qpOASES starts cold at every call); not on the soft form (met only
    when the hard QP is infeasible, 6x the variables: there the shortcut measured slower).
    A run's memory: the shortcut's active set and whether qpOASES has been called yet."""

    def __init__(self, form):
        import casadi as ca
        self.H, self.A = ca.DM(form.H), ca.DM(form.A)      # converted once, not per call
        self.fast = None if form.soft else ActiveSetQp(form.H, form.A)
        opts = {"printLevel": "none", "sparse": False, "error_on_fail": False,
                "hessian_type": "posdef"}
        self.solver = _quiet(lambda: ca.conic(
            "mpc_qp", "qpoases", {"h": ca.DM(form.H).sparsity(), "a": ca.DM(form.A).sparsity()},
            opts))

    def memory(self) -> dict:
        return {"fast": None if self.fast is None else self.fast.memory(), "called": False}

    def solve(self, g, lbx, ubx, lba, uba, x0, memory):
        if self.fast is not None:
            x = self.fast.solve(g, lbx, ubx, lba, uba, memory["fast"])
            if x is not None:
                return x, "solved"
        call = (lambda: self.solver(h=self.H, a=self.A, g=g, lbx=lbx, ubx=ubx, lba=lba,
                                    uba=uba, x0=x0))
        if not memory["called"]:            # qpOASES prints its banner on the first solve
            memory["called"] = True
            out = _quiet(call)
        else:
            # and reports an infeasible QP (counted in the MPC's stats) through CasADi's
            # stream, which writes to Python's sys.stdout: a --json reader got those lines
            with contextlib.redirect_stdout(_DISCARD):
                out = call()
        stats = self.solver.stats()
        if not stats.get("success", False):
            return None, str(stats.get("return_status", "failed"))
        if self.fast is not None:               # the next call starts from this active set
            self.fast.remember(np.asarray(out["lam_x"]), np.asarray(out["lam_a"]),
                               memory["fast"])
        return np.asarray(out["x"]).ravel(), "solved"


class CvxpyBackend:
    """cvxpy with Parameters (built once, DPP), solved by Clarabel."""

    def __init__(self, form):
        import cvxpy as cp
        n = form.n_var
        self.x = cp.Variable(n)
        self.g = cp.Parameter(n)
        w, V = np.linalg.eigh(form.H)
        factor = V * np.sqrt(np.clip(w, 0, None))[None, :]
        lo, hi = np.isfinite(form.lbx), np.isfinite(form.ubx)
        cons = [self.x[np.flatnonzero(lo)] >= form.lbx[lo]] if lo.any() else []
        if hi.any():
            cons.append(self.x[np.flatnonzero(hi)] <= form.ubx[hi])
        # which rows have finite bounds is fixed by the layout: probe it once
        qp = form.qp
        free = ([np.zeros(qp.N * qp.nu)] if qp.has_stroke else []) + \
            ([np.zeros(qp.N * qp.n_env)] if qp.n_env else []) + \
            ([np.zeros(2 * qp.N * qp.n_hull)] if qp.n_hull else [])
        _, lba, uba = form.bounds(np.zeros(form.n_u), free, np.zeros(qp.nu))
        self.lo_rows, self.hi_rows = np.flatnonzero(np.isfinite(lba)), np.flatnonzero(np.isfinite(uba))
        self.lba, self.uba = cp.Parameter(self.lo_rows.size), cp.Parameter(self.hi_rows.size)
        if self.lo_rows.size:
            cons.append(form.A[self.lo_rows] @ self.x >= self.lba)
        if self.hi_rows.size:
            cons.append(form.A[self.hi_rows] @ self.x <= self.uba)
        objective = 0.5 * cp.sum_squares(factor.T @ self.x) + self.g @ self.x
        self.problem = cp.Problem(cp.Minimize(objective), cons)

    memory = staticmethod(lambda: None)   # Clarabel starts afresh; Parameters set per call

    def solve(self, g, lbx, ubx, lba, uba, x0, memory=None):
        import cvxpy as cp
        self.g.value = g
        self.lba.value, self.uba.value = lba[self.lo_rows], uba[self.hi_rows]
        try:
            self.problem.solve(solver=cp.CLARABEL)
        except cp.error.SolverError as exc:
            return None, f"solver error: {exc}"
        if self.problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
            return None, self.problem.status
        return np.asarray(self.x.value).ravel(), "solved"


class _Discard:
    """A text stream that keeps nothing."""

    def write(self, text: str) -> int:
        return len(text)

    def flush(self) -> None:
        pass


_DISCARD = _Discard()


def _quiet(call):
    """Run with output silenced: qpOASES prints a banner, through CasADi's stream (which
    CasADi hands to Python's sys.stdout) or straight to the process's stdout."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null, contextlib.redirect_stdout(io.StringIO()), \
                contextlib.redirect_stderr(io.StringIO()):
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            return call()
    finally:
        flush_c_stdio()                 # a pipe's C buffer would print after the restore
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)
