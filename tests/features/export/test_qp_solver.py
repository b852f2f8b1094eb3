"""The exported MPC's QP solver (mbcontrol/export/csrc/mbc_qp.c, Goldfarb-Idnani) against
qpOASES (the Python MPC's solver, through CasADi) on random strictly convex QPs: the same
minimiser where both solve, the same verdict where the constraints cannot be met."""
import ctypes
import subprocess

import casadi as ca
import numpy as np
import pytest

from mbcontrol.export.build import csrc
from mbcontrol.export.spec import sparse_rows

V = ctypes.c_void_p


class _Qp(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("m", ctypes.c_int), ("H", V), ("A_start", V),
                ("A_col", V), ("A_val", V), ("Jt0", V), ("work", V), ("iwork", V),
                ("iterations", ctypes.c_int), ("max_iter", ctypes.c_int)]


@pytest.fixture(scope="module")
def solver(tmp_path_factory):
    folder = tmp_path_factory.mktemp("qp")
    (folder / "mbc_qp.h").write_text(csrc("mbc_qp.h"))
    (folder / "mbc_qp.c").write_text(csrc("mbc_qp.c"))
    subprocess.run(["gcc", "-O2", "-std=c99", "-Wall", "-Werror", "-fPIC", "-shared",
                    "mbc_qp.c", "-o", "libqp.so", "-lm"], cwd=folder, check=True)
    lib = ctypes.CDLL(str(folder / "libqp.so"))

    def solve(H, A, g, lbx, ubx, lba, uba):
        n, m = H.shape[0], A.shape[0]
        start, col, val = sparse_rows(A)
        keep = [np.ascontiguousarray(H, float), np.ascontiguousarray(start, np.int32),
                np.ascontiguousarray(col, np.int32), np.ascontiguousarray(val, float),
                np.zeros(n * n), np.zeros(3 * n * n + 6 * n + 3 * m + 1),
                np.zeros(3 * n + 2 * m, np.int32)]
        qp = _Qp(n, m, *[a.ctypes.data_as(V) for a in keep], 0, 0)   # max_iter 0: the default
        assert lib.mbc_qp_setup(ctypes.byref(qp)) == 0
        args = [np.ascontiguousarray(v, float) for v in (g, lbx, ubx, lba, uba)]
        x = np.zeros(n)
        status = lib.mbc_qp_solve(ctypes.byref(qp), *[a.ctypes.data_as(V) for a in args],
                                  x.ctypes.data_as(V))
        return status, x
    return solve


def _qpoases(H, A, g, lbx, ubx, lba, uba):
    n, m = H.shape[0], A.shape[0]
    a_sp = ca.DM(A).sparsity() if m else ca.Sparsity(0, n)
    s = ca.conic("q", "qpoases", {"h": ca.DM(H).sparsity(), "a": a_sp},
                 {"printLevel": "none", "error_on_fail": False})
    r = s(h=H, a=A if m else ca.DM(0, n), g=g, lbx=lbx, ubx=ubx, lba=lba, uba=uba)
    return s.stats()["success"], np.asarray(r["x"]).ravel()


def _rows(rng, m, n, structure):
    """Constraint rows: nonzeros scattered at random, or each row one run of consecutive
    columns (the exported MPC's stroke and slew rows, which the solver takes as dense runs)."""
    if structure == "scattered":
        return rng.standard_normal((m, n)) * (rng.random((m, n)) < 0.5)
    A = np.zeros((m, n))
    for row in A:
        first = int(rng.integers(0, n))
        last = int(rng.integers(first + 1, n + 1))
        row[first:last] = rng.standard_normal(last - first)
    return A


@pytest.mark.parametrize("structure", ["scattered", "runs"])
def test_same_minimiser_and_same_infeasibility_verdict_as_qpoases(solver, structure):
    rng = np.random.default_rng(7)
    solved = infeasible = 0
    for _ in range(150):
        n, m = int(rng.integers(2, 30)), int(rng.integers(0, 40))
        M = rng.standard_normal((n, n))
        H = M @ M.T + 0.1 * np.eye(n)
        A = _rows(rng, m, n, structure)
        g = 5 * rng.standard_normal(n)
        lbx, ubx = -rng.uniform(0.1, 2, n), rng.uniform(0.1, 2, n)
        lbx[rng.random(n) < 0.2] = -np.inf
        lba = rng.uniform(-2, 1.5, m)
        uba = lba + rng.uniform(0, 2, m)
        uba[rng.random(m) < 0.3] = np.inf
        status, x = solver(H, A, g, lbx, ubx, lba, uba)
        ok, x_ref = _qpoases(H, A, g, lbx, ubx, lba, uba)
        assert (status == 0) == ok, (status, ok)
        if ok:
            solved += 1
            # both are exact active-set solutions: round-off apart (H's condition <~1e4)
            assert np.max(np.abs(x - x_ref)) <= 1e-9 * max(1.0, np.max(np.abs(x_ref)))
        else:
            infeasible += 1
            assert status == 1            # reported infeasible, not out of iterations
    assert solved > 30 and infeasible > 30   # both branches exercised


def test_unconstrained_minimum_and_a_box_by_hand(solver):
    H = np.array([[2.0, 0.0], [0.0, 4.0]])
    g = np.array([-2.0, -8.0])               # unconstrained minimum (1, 2)
    inf = np.full(2, np.inf)
    status, x = solver(H, np.zeros((0, 2)), g, -inf, inf, np.zeros(0), np.zeros(0))
    assert status == 0 and np.allclose(x, [1.0, 2.0], atol=1e-14)
    # x1 + x2 <= 1: on the line, minimising (x1 - 1)^2 + 2 (x2 - 2)^2 gives x1 = -1/3, x2 = 4/3
    status, x = solver(H, np.array([[1.0, 1.0]]), g, -inf, inf, np.array([-np.inf]),
                       np.array([1.0]))
    assert status == 0 and np.allclose(x, [-1 / 3, 4 / 3], atol=1e-14)
