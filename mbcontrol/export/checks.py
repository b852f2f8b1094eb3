"""Is the exported controller the controller? Closed-loop runs on the same plant and wave:
the Python controller, its C library (through ctypes, stepped by `simulate`), and, when fmpy is
installed, the two FMUs co-simulated by fmpy; then the C step timed over the run's own
measurements, beside the Python step on the same ones. Each Python run is a private copy of
the caller's controller (simulate and the timing reset it; the caller's stays as it was):
the Python run's describe() is in its record, ds.attrs["controller"]."""
from __future__ import annotations

import copy
import time

import numpy as np

from ..sim import period_of
from .runtime import CController, force_error, step_statistics


def closed_loop_check(plant, wave, controller, exported, *, duration: float, dt: float,
                      plant_fmu=None) -> dict:
    """Force and mean-power differences of the exported controller against `controller`,
    closed loop on `plant` in `wave` for `duration` s at step dt (s): relative to the
    Python run's peak force and |mean power|; beside them the round-off floor (the Python
    run against itself from a start moved by 1e-12). Returns the check and the Python record
    (the timing replays its measurements)."""
    from mbcontrol.controllers import mean_power
    from mbcontrol.sim import simulate
    period = period_of(controller)
    reference = simulate(plant, wave, duration=duration, dt=dt,
                         controller=copy.copy(controller), method="rk4")
    c_ctrl = CController.from_export(exported, period=period)
    c_run = simulate(plant, wave, duration=duration, dt=dt, controller=c_ctrl, method="rk4")
    commands = exported.spec.outputs
    pto = commands[0][len("u__"):]
    u_ref = np.column_stack([reference[k].values for k in commands])
    u_c = np.column_stack([c_run[k].values for k in commands])
    p_ref, p_c = mean_power(reference, pto), mean_power(c_run, pto)
    # the floor: the Python controller against itself with the first state moved by 1e-12
    # (m or rad), what round-off alone does to this closed loop (an MPC whose QP switches
    # active sets amplifies it; a static law does not)
    x0 = plant.x0().copy()
    x0[0] += 1e-12
    nudged = simulate(plant, wave, duration=duration, dt=dt, controller=copy.copy(controller),
                      method="rk4", x0=x0)
    u_nudged = np.column_stack([nudged[k].values for k in commands])
    p_nudged = mean_power(nudged, pto)
    from mbcontrol.analysis import summary
    verdict = summary(reference, plant)      # the run's physics checks (bound, energy, range)
    out = {"max_rel_force_error": force_error(u_ref, u_c),
           "mean_power_rel_error": abs(p_c - p_ref) / max(abs(p_ref), 1e-300),
           "python_mean_power_W": p_ref, "c_mean_power_W": p_c,
           "python_run_valid": verdict["valid"],
           "python_run_invalid_reasons": verdict["invalid_reasons"],
           "round_off_floor": {"max_rel_force_error": force_error(u_ref, u_nudged),
                               "mean_power_rel_error": abs(p_nudged - p_ref) / max(abs(p_ref),
                                                                                    1e-300),
                               "what": "Python controller against itself, first state "
                                       "+1e-12"},
           "duration_s": duration, "dt_s": dt, "pto": pto}
    if plant_fmu is not None:
        out["fmu"] = _fmu_check(plant_fmu, exported.fmu, u_ref, reference, duration, dt,
                                pto)
    return {"check": out, "record": reference}


def _fmu_check(plant_fmu, controller_fmu, u_ref, reference, duration, dt, pto) -> dict:
    from importlib.util import find_spec
    if find_spec("fmpy") is None:
        return {"skipped": "fmpy is not installed (pip install fmpy)"}
    from .cosim import closed_loop
    run = closed_loop(plant_fmu, controller_fmu, duration=duration, step=dt)
    n = run["u"].shape[0]
    position = f"{pto}__position"
    y_ref = reference[position].values[:n + 1]
    y_fmu = run["y"][:, run["outputs"].index(position)]
    return {"max_rel_force_error": force_error(u_ref[:n], run["u"]),
            "max_rel_position_error": force_error(y_ref, y_fmu), "position": position,
            "steps": int(n), "master": "fmpy FMU2Slave, plant outputs -> controller -> plant"}


def step_timing(controller, exported, record, plant, *, python_steps: int | None = None) -> dict:
    """Step times (us) of the C library over the measurements of `record` (a Dataset of a
    closed-loop run) at the controller's calls, and of the Python controller over the same
    (the first python_steps of them). Both from a fresh start; the C one timed inside C, wall
    ("c") and thread CPU time ("c_cpu")."""
    period = period_of(controller)
    t = record["time"].values
    if period:                             # the samples the controller acts on
        every = max(1, int(round(period / (t[1] - t[0]))))
        t = t[::every]
    inputs = exported.spec.inputs
    y = np.column_stack([record[n].values for n in inputs])
    if period:
        y = y[::every]
    c_ctrl = CController.from_export(exported, period=period)
    c_ctrl.reset(plant)
    _, ns, cpu_ns = c_ctrl.timed_run(y, t, cpu=True)
    # wall time (what a shared machine's scheduler adds included) and thread CPU time
    out = {"c": step_statistics(ns), "c_cpu": step_statistics(cpu_ns)}
    counts = c_ctrl.counts()                # the MPC engine's: fallbacks, soft solves, fits
    if counts is not None:
        out["c_counts"] = counts
    n_py = len(t) if python_steps is None else min(python_steps, len(t))
    controller = copy.copy(controller)          # a private run: the caller's is left alone
    controller.reset(plant)
    index = [plant.outputs.index(name) for name in inputs]
    full = np.zeros(len(plant.outputs))
    times = np.empty(n_py)
    for k in range(n_py):
        full[index] = y[k]
        start = time.perf_counter_ns()
        controller(t[k], full)
        times[k] = time.perf_counter_ns() - start
    out["python"] = step_statistics(times)
    out["speed_up_median"] = out["python"]["median"] / max(out["c"]["median"], 1e-9)
    return out


def footprint(exported) -> dict:
    """Memory of one controller: its context (bytes, all its state) and its library's code
    and constant data (bytes on disk)."""
    ctrl = CController.from_export(exported)
    return {"context_bytes": int(getattr(ctrl.lib, f"{exported.ident}_ctx_size")()),
            "library_bytes": int(exported.library.stat().st_size)}
