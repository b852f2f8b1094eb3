"""Move blocking (controllers.mpc_blocks) in the MPC's condensed QP: the blocked QP's optimum
against qpOASES on the same blocked problem built here by hand (T'HT, T'g, the stroke rows
over the blocks, the slew rows between blocks), and blocks that are every one step long
against no blocking (the same QP, the same plan). The C engine with blocking against the
Python MPC: tests/features/export/test_export.py (the "mpc-blocked" case)."""
import casadi as ca
import numpy as np
import pytest

from mbcontrol.controllers.control_plant import build_control_plant
from mbcontrol.controllers.mpc_blocks import block_lengths, geometric_layout
from mbcontrol.controllers.mpc_qp import CondensedQp
from mbcontrol.errors import ControllerError
from mbcontrol.plant import build_plant

N, FORCE_MAX, STROKE_MAX, RATE_MAX, DT = 40, 2e6, 2.0, 5e6, 0.24
KW = dict(efficiency=[1.0], loss_damping=[1.0], force_penalty=1e-3, stroke_penalty=100.0,
          soft_stroke=False, solver="qpoases")


@pytest.fixture(scope="module")
def cp():
    return build_control_plant(build_plant("sphere"), DT)


def _limits():
    return {"force": np.array([FORCE_MAX]), "stroke": np.array([STROKE_MAX]),
            "rate": np.array([RATE_MAX])}


def _data(cp, rng):
    z0 = rng.normal(size=cp.nz) * np.abs(rng.normal()) * 0.5
    D = np.sin(0.65 * DT * np.arange(N) + rng.uniform(0, 6))[:, None] * rng.uniform(0.5, 3)
    return z0, D, rng.uniform(-1, 1, 1) * FORCE_MAX


def _by_hand(qp, lengths, z0, D, u_prev):
    """The blocked QP from the unblocked one's matrices (U = T V, T by hand), solved by
    qpOASES in the QP's scaled units (V / F_s); the plan U (N), N, or None if infeasible."""
    B = len(lengths)
    T = np.zeros((N, B))
    T[np.arange(N), np.repeat(np.arange(B), lengths)] = 1.0
    H = T.T @ qp.H_u @ T
    g = T.T @ (qp.Qz @ z0 + qp.Qd @ D.ravel())
    free = (qp.Phi @ z0 + qp.Om @ D.ravel()) / qp.Ls
    stroke = qp.Fs / qp.Ls * qp.Psi @ T
    diff = np.eye(B) - np.eye(B, k=-1)
    L = np.asarray(lengths, float)
    span = np.concatenate([[1.0], (L[:-1] + L[1:]) / 2])       # steps between block middles
    rate = RATE_MAX * DT * span / qp.Fs
    first = np.zeros(B)
    first[0] = u_prev[0] / qp.Fs
    A = np.vstack([stroke, diff])
    lim = STROKE_MAX / qp.Ls
    solver = ca.conic("ref", "qpoases", {"h": ca.DM(H).sparsity(), "a": ca.DM(A).sparsity()},
                      {"printLevel": "none"})
    out = solver(h=H, a=A, g=g, lbx=-FORCE_MAX / qp.Fs, ubx=FORCE_MAX / qp.Fs,
                 lba=np.concatenate([-lim - free, first - rate]),
                 uba=np.concatenate([lim - free, first + rate]))
    if not solver.stats()["success"]:
        return None
    return T @ np.asarray(out["x"]).ravel() * qp.Fs


@pytest.mark.parametrize("blocks", [10, 16, (1, 2, 3, 4, 5, 6, 19)])
def test_the_blocked_qp_is_the_blocked_problem(cp, blocks):
    """Random states, forecasts and last commands with the force, stroke and slew limits
    active: the blocked QP's plan equals qpOASES' on the hand-built blocked problem to 1e-8
    of the force limit (measured ~1e-12), and holds each block's force."""
    lengths = block_lengths(blocks, N)
    qp = CondensedQp(cp, N, _limits(), blocks=lengths, **KW)
    rng = np.random.default_rng(1)
    solved = 0
    for _ in range(12):
        z0, D, u_prev = _data(cp, rng)
        U, _ = qp.solve(z0, D, u_prev)
        ref = _by_hand(qp, lengths, z0, D, u_prev)
        assert (U is None) == (ref is None)
        if U is None:
            continue
        solved += 1
        assert np.max(np.abs(U[:, 0] - ref)) <= 1e-8 * FORCE_MAX
        inside = np.ones(N - 1, bool)
        inside[np.cumsum(lengths)[:-1] - 1] = False          # steps within a block
        assert np.all(np.diff(U[:, 0])[inside] == 0)
    assert solved >= 6


def test_one_step_blocks_are_no_blocking(cp):
    """Blocks of one step each (T the identity, built and applied) give the unblocked QP's
    plan to 1e-12 of the force limit, hard and soft stroke forms."""
    limits = _limits()
    limits["stroke"] = np.array([0.5])                         # the soft form runs too
    kw = dict(KW, soft_stroke=True)
    plain = CondensedQp(cp, N, limits, **kw)
    ones = CondensedQp(cp, N, limits, blocks=(1,) * N, **kw)
    rng = np.random.default_rng(2)
    work_a, work_b = plain.workspace(), ones.workspace()
    for _ in range(10):
        z0, D, u_prev = _data(cp, rng)
        Ua, _ = plain.solve(z0, D, u_prev, work=work_a)
        Ub, _ = ones.solve(z0, D, u_prev, work=work_b)
        assert np.max(np.abs(Ua - Ub)) <= 1e-12 * FORCE_MAX
    assert work_a.soft_solves == work_b.soft_solves > 0


def test_the_default_layouts():
    """Counts give short blocks first, doubling every second block, summing to N; lengths
    are checked; one block per step is no blocking."""
    assert geometric_layout(8, 30) == (1, 1, 2, 2, 4, 4, 8, 8)
    assert geometric_layout(10, 40) == (1, 1, 2, 2, 4, 4, 6, 6, 7, 7)
    for B in range(1, N + 1):
        lengths = geometric_layout(B, N)
        assert len(lengths) == B and sum(lengths) == N and min(lengths) >= 1
        assert list(lengths) == sorted(lengths) and (B == 1 or lengths[0] == 1)
    assert block_lengths(None, N) is None and block_lengths(N, N) is None
    assert block_lengths([5] * 8, N) == (5,) * 8
    assert block_lengths(10.0, N) == geometric_layout(10, N)      # --set blocks=10
    with pytest.raises(ControllerError):
        block_lengths((5, 5), N)
    with pytest.raises(ControllerError):
        block_lengths(41, N)
