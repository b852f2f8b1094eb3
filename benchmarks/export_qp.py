"""Which QP solver for the exported MPC: the code-generatable candidates against qpOASES (the
Python MPC's solver) on the QPs of a real closed loop, the sphere's causal MPC in JONSWAP Hs
2 m, Tp 9 s for 200 s (horizon 8 s in 40 steps): failures, largest error relative to the
qpOASES solution's peak, and median time per solve. CasADi's `qrqp` and `ipqp` and OSQP
(tolerances 1e-10, polished) run through CasADi (their generated C would be as exact, and
faster); mbcontrol's Goldfarb-Idnani C solver (mbcontrol/export/csrc/mbc_qp.c) through ctypes.

Run: python benchmarks/export_qp.py
"""
from __future__ import annotations

import ctypes
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def record_qps():
    import mbcontrol.controllers.mpc_qp as mq
    from mbcontrol.controllers import make
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import load_scene
    from mbcontrol.sim import simulate
    from mbcontrol.waves import irregular
    plant = build_plant(load_scene("sphere"))
    wave = irregular(2.0, 9.0, seed=1)
    seen = []
    original = mq._QpForm.solve

    def solve(self, q, free, u_prev, warm, memory=None):
        out = original(self, q, free, u_prev, warm, memory)
        if not self.soft and out[0] is not None:
            seen.append((self, *self.bounds(q, free, u_prev), out[0]))
        return out
    mq._QpForm.solve = solve
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulate(plant, wave, duration=200.0, dt=0.05,
                     controller=make("mpc", horizon_s=8.0, dt_s=0.2, wave=wave))
    finally:
        mq._QpForm.solve = original
    return seen


def ours(form):
    from mbcontrol.export.build import csrc
    from mbcontrol.export.spec import sparse_rows
    folder = Path(tempfile.mkdtemp())
    for name in ("mbc_qp.h", "mbc_qp.c"):
        (folder / name).write_text(csrc(name))
    subprocess.run(["gcc", "-O3", "-std=c99", "-fPIC", "-shared", "mbc_qp.c", "-o", "q.so",
                    "-lm"], cwd=folder, check=True)
    lib = ctypes.CDLL(str(folder / "q.so"))
    V = ctypes.c_void_p

    class Qp(ctypes.Structure):
        _fields_ = [("n", ctypes.c_int), ("m", ctypes.c_int)] + [
            (k, V) for k in ("H", "s", "c", "v", "J", "w", "iw")] + [("it", ctypes.c_int)]
    n, m = form.H.shape[0], form.A.shape[0]
    start, col, val = sparse_rows(form.A)
    keep = [np.ascontiguousarray(form.H), np.ascontiguousarray(start, np.int32),
            np.ascontiguousarray(col, np.int32), np.ascontiguousarray(val), np.zeros(n * n),
            np.zeros(3 * n * n + 6 * n + 3 * m + 1), np.zeros(3 * n + 2 * m, np.int32)]
    qp = Qp(n, m, *[a.ctypes.data_as(V) for a in keep], 0)
    lib.mbc_qp_setup(ctypes.byref(qp))

    def solve(g, lba, uba):
        args = [np.ascontiguousarray(v, float) for v in (g, form.lbx, form.ubx, lba, uba)]
        x = np.zeros(n)
        ok = lib.mbc_qp_solve(ctypes.byref(qp), *[a.ctypes.data_as(V) for a in args],
                              x.ctypes.data_as(V)) == 0
        return ok, x
    solve.keep = keep
    return solve


def casadi_solver(form, plugin, opts):
    import casadi as ca
    s = ca.conic("qp", plugin, {"h": ca.DM(form.H).sparsity(), "a": ca.DM(form.A).sparsity()},
                 opts)

    def solve(g, lba, uba):
        lba = np.where(np.isfinite(lba), lba, -1e20)
        uba = np.where(np.isfinite(uba), uba, 1e20)
        r = s(h=form.H, a=form.A, g=g, lba=lba, uba=uba, lbx=form.lbx, ubx=form.ubx)
        return bool(s.stats()["success"]), np.asarray(r["x"]).ravel()
    return solve


def main() -> None:
    seen = record_qps()
    form = seen[0][0]
    quiet = {"print_iter": False, "print_header": False, "error_on_fail": False}
    solvers = {"mbcontrol Goldfarb-Idnani (C)": ours(form),
               "casadi qrqp": casadi_solver(form, "qrqp", quiet),
               "casadi ipqp": casadi_solver(form, "ipqp", quiet),
               "osqp (eps 1e-10, polish)": casadi_solver(
                   form, "osqp", {"error_on_fail": False, "osqp": {
                       "verbose": False, "eps_abs": 1e-10, "eps_rel": 1e-10, "polish": True,
                       "max_iter": 100000}})}
    print(f"{len(seen)} QPs of {form.H.shape[0]} variables, {form.A.shape[0]} rows\n")
    print("| solver | failed | largest error vs qpOASES | median solve (ms) |")
    print("|---|---|---|---|")
    for name, solve in solvers.items():
        fails, errors, times = 0, [], []
        for _, g, lba, uba, reference in seen:
            start = time.perf_counter()
            ok, x = solve(g, lba, uba)
            times.append(time.perf_counter() - start)
            if not ok:
                fails += 1
                continue
            errors.append(np.max(np.abs(x - reference)) / max(np.max(np.abs(reference)), 1e-12))
        print(f"| {name} | {fails} of {len(seen)} | {max(errors):.1e} | "
              f"{1e3 * np.median(times):.3f} |")


if __name__ == "__main__":
    main()
