"""The MPC's verified active-set shortcut (controllers.mpc_active_set) against qpOASES alone.

QPs from a closed-loop run of the demo's hinged barge (JONSWAP Hs 3 cm, Tp 1.1 s, horizon
1.2 s, dt 0.03 s, 10 s) with limits tightened so that force, stroke and rate rows bind (3 N m,
0.12 rad, 45 N m/s): each QP of the hard form solved by the shortcut, in order (its warm start
carries over), and by a plain CasADi qpOASES call with the MPC's options. Where the shortcut
returns a solution it must be qpOASES's; where it gives up (None) qpOASES takes over, as in
mpc_qp, and a QP qpOASES finds infeasible the shortcut must give up on. The soft form's QPs
from every 8th state likewise (the MPC leaves that form to qpOASES). Measured: 300 hard QPs,
229 solved by the shortcut, largest relative difference 1.3e-12; qpOASES's solutions have
force bounds binding in 235, stroke rows in 94, rate rows in 222; soft form 18 of 38 solved,
largest difference 5.1e-13.
"""
import contextlib
import io

import casadi as ca
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers import mpc_active_set
from mbcontrol.controllers.mpc import Mpc
from mbcontrol.controllers.mpc_active_set import ActiveSetQp
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

OPTIONS = {"printLevel": "none", "sparse": False, "error_on_fail": False,
           "hessian_type": "posdef"}


@pytest.fixture(scope="module")
def recorded():
    """(mpc, [(q, free, u_prev)]): the hard form's arguments at every solve of a 10 s run."""
    plant = build_plant("hinged_barge")
    sea = waves.irregular(0.03, 1.1, gamma=3.3, seed=1, duration=10.0)
    mpc = Mpc(horizon_s=1.2, dt_s=0.03, wave=sea, forecast="model", warm_up_s=1.0,
              force_max=3.0, stroke_max=0.12, rate_max=45.0)
    calls = []
    mpc.reset(plant)
    hard = mpc.qp.forms[0]
    solve = hard.solve

    def recording(q, free, u_prev, warm, memory=None):
        calls.append((q.copy(), [np.array(f) for f in free], np.array(u_prev)))
        return solve(q, free, u_prev, warm, memory)

    hard.solve = recording
    reset = mpc.reset
    mpc.reset = lambda plant: None           # keep the recording form through simulate
    simulate(plant, sea, duration=10.0, dt=0.005, controller=mpc)
    mpc.reset = reset
    return mpc, calls


def _compare(form, calls):
    """(largest relative difference, calls the shortcut solved, infeasible calls, rows
    binding per kind in qpOASES's solutions: force bounds, stroke rows, rate rows)."""
    fast = ActiveSetQp(form.H, form.A)
    memory = fast.memory()                  # this replay's warm start
    solver = ca.conic("ref", "qpoases", {"h": ca.DM(form.H).sparsity(),
                                          "a": ca.DM(form.A).sparsity()}, OPTIONS)
    worst, infeasible, solved, n = 0.0, 0, 0, form.n_u
    binding = {"force": 0, "stroke": 0, "rate": 0}
    for q, free, u_prev in calls:
        g, lba, uba = form.bounds(q, free, u_prev)
        x = fast.solve(g, form.lbx, form.ubx, lba, uba, memory)
        with contextlib.redirect_stdout(io.StringIO()):
            out = solver(h=form.H, a=form.A, g=g, lbx=form.lbx, ubx=form.ubx, lba=lba, uba=uba)
        if not solver.stats()["success"]:
            infeasible += 1
            assert x is None, "the shortcut solved a QP qpOASES found infeasible"
            continue
        ref = np.asarray(out["x"]).ravel()
        lam_x, lam_a = np.ravel(out["lam_x"]), np.ravel(out["lam_a"])
        binding["force"] += bool(np.any(lam_x[:n] != 0))
        binding["stroke"] += bool(np.any(lam_a[:n] != 0))
        binding["rate"] += bool(np.any(lam_a[-n:] != 0))
        if x is None:
            fast.remember(lam_x, lam_a, memory)
            continue
        solved += 1
        worst = max(worst, float(np.max(np.abs(x - ref)) / max(1.0, np.max(np.abs(ref)))))
    return worst, solved, infeasible, binding


def test_shortcut_is_qpoases(recorded, monkeypatch):
    monkeypatch.setattr(mpc_active_set, "SKIP_AFTER", 10 ** 9)     # try every call
    mpc, calls = recorded
    hard, soft = mpc.qp.forms
    assert len(calls) > 250
    worst, solved, infeasible, binding = _compare(hard, calls)
    assert worst < 1e-8
    assert solved > 0.6 * (len(calls) - infeasible)     # measured 229 of 300
    assert min(binding.values()) > 20, binding
    # the soft form (the MPC leaves it to qpOASES: slower there) on every 8th state
    worst_soft, solved_soft, infeasible_soft, _ = _compare(soft, calls[::8])
    assert worst_soft < 1e-8 and infeasible_soft == 0 and solved_soft > 0
