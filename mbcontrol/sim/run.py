"""Open- and closed-loop simulation of a ProcessPlant, results as an xarray.Dataset.

Methods (mbcontrol.sim.METHODS): fixed-step "rk4" (the default), "rk3", "dopri5" and
"exp-rk4" run as compiled native code; "cvodes" (BDF) and "adams" are adaptive, with the
excitation an explicit function of time. A controller is sampled with a zero-order hold at
its period; a controller that offers a CasADi law with period dt runs inside compiled code.

Every run is audited before its result is returned: a non-finite or absurd state (checked
during the run, chunk by chunk) or a mechanical energy beyond what the waves and PTOs put in
(sim.audit) raises SimulationError naming the time, the step and a remedy.
"""
from __future__ import annotations

import copy
import time
import warnings

from typing import TYPE_CHECKING

import numpy as np

from .. import defaults
from ..console import progress_bar
from ..errors import InputError, SimulationError
from ..plant import controlled_params
from ..results import jsonable
from . import diagnose, integrators, sampled
from .alongside import OutputsAlongside
from .audit import diverged, energy_audit
from .held import HeldStepper
from .methods import time_steps
from .moordyn_run import prepare_moored, run_moored
from .moorings import mooring_report
from .protocol import estimation_report, uses_state
from .record import run_dataset

if TYPE_CHECKING:                  # the record is made by .record; here only named
    import xarray as xr


def simulate(plant, wave=None, *, duration: float, dt: float | None = None, controller=None,
             method: str | None = None, x0=None, params=None, compiled: bool = True,
             rtol: float | None = None, progress: bool = False, audit: bool = True) -> xr.Dataset:
    """Simulate `plant` in `wave` (None: still water) for `duration` s with step `dt` s.

    dt, method and rtol left out take the defaults "sim.dt" (0.01 s), "sim.method" ("rk4")
    and "sim.rtol" (1e-8) of mbcontrol.defaults. method: a name in mbcontrol.sim.METHODS.
    For fixed-step methods dt is the step; for the adaptive ones ("cvodes", "adams") dt is the output (and controller) grid and
    rtol sets the accuracy. params: a dict of parameter overrides or a full vector. With a
    controller, the PTO force is the controller's command alone: the scene's PTO damping and
    stiffness are zeroed unless params sets them. audit: check the energy balance (see
    `energy_audit`). Returns a Dataset over time with every plant output, the applied
    inputs u, the excitation w, the wave elevation `eta` and the states, plus provenance in
    attrs: wall_time_s is the excitation synthesis and the time-stepping (compilation and
    the output evaluation excluded; output_time_s is the latter: on two cores most of it runs
    alongside the steps, sim.alongside, and output_time_s is what remained after them). A
    controller with a period and a static law has its held loop checked first (sim.sampled: a
    RuntimeWarning when unstable; the verdict in attrs["sampled_loop"], which
    analysis.validity reads).
    """
    dt, method = defaults.resolve("sim.dt", dt), defaults.resolve("sim.method", method)
    rtol = defaults.resolve("sim.rtol", rtol)
    n = time_steps(duration, dt)
    spec = integrators.method(method)
    if getattr(plant, "moordyn", ()) and not spec.fixed_step:
        raise InputError(f"{plant.name}: method {method!r} is adaptive, and MoorDyn's lines are "
                         f"stepped beside the plant at a fixed step (they have no Jacobian for "
                         f"it); expected a fixed-step method: rk4, rk3, dopri5 or exp-rk4")
    t = np.arange(n + 1) * dt
    p = _parameters(plant, params, controller)
    x0 = plant.x0() if x0 is None else np.asarray(x0, float)
    if controller is not None:
        controller.reset(plant)
    loop = sampled.check(plant, controller, p, dt)   # a held law's loop, before it runs
    if loop is not None and not loop["stable"]:
        warnings.warn(f"{plant.name}: {loop['message']}", RuntimeWarning, stacklevel=2)
    if spec.kind == "explicit":
        _warn_stiff(plant, dt)
    bar = _progress_bar(progress, n)
    why = diagnose.explainer(plant, wave, controller, p, x0, dt, method, duration, simulate)
    check = _divergence_check(plant, dt, method, bar, why)

    # a controller with a CasADi law held for one step runs inside the compiled code, its
    # gains (when it offers them as parameters) at the end of p: new gains, no new code
    law, gains = integrators.embedded_law(controller, plant) if spec.fixed_step else (None, None)
    embedded = controller is None or (law is not None and _period(controller, dt) == dt)
    alongside = None
    if spec.fixed_step:                  # compile first: wall_time_s excludes it
        steps = n if embedded else _steps_per_period(_period(controller, dt), dt)
        if getattr(plant, "moordyn", ()):    # one step at a time, the points' kinematics
            steps = 1
            prepare_moored(plant, compiled)
        integrators.prepare(plant, steps, method, law if embedded else None, compiled)
        alongside = OutputsAlongside(plant, n + 1, p, compiled)
    start = time.perf_counter()
    try:
        if spec.fixed_step:
            W_nodes = integrators.excitation_at_nodes(plant, wave, n, dt, spec.nodes)
            p_run = np.concatenate([p, gains]) if embedded and gains is not None else p
            X, U, moored = _run_fixed(plant, method, controller, x0, W_nodes, p_run, dt=dt,
                                      n=n, law=law if embedded else None, embedded=embedded,
                                      compiled=compiled, check=check, alongside=alongside)
        else:
            (X, U), moored = _run_cvodes(plant, wave, controller, x0, p, dt, n, rtol, check,
                                         method), None
    except BaseException:
        if alongside is not None:
            alongside.close(errors=False)
        raise
    wall = time.perf_counter() - start
    if bar is not None:
        bar.close()

    start = time.perf_counter()
    W = _disturbance_record(plant, wave, t, W_nodes if spec.fixed_step else None, moored)
    U_full = np.vstack([U, _last_command(plant, controller, t[-1], X[-1], U, W[-1], p)])
    Y = alongside.finish(X, U_full, W) if alongside is not None \
        else integrators.outputs(plant, X, U_full, W, p, compiled=compiled)
    output_wall = time.perf_counter() - start
    if audit:
        energy_audit(plant, t, Y, method, dt, why)
    eta = wave.elevation(t) if wave is not None else np.zeros_like(t)
    ds = run_dataset(plant, t, X, U_full, W, Y, eta, wave=wave, controller=controller,
                  method=method, dt=dt, p=p, wall=wall)
    ds.attrs["output_time_s"] = output_wall
    if not spec.fixed_step:
        ds.attrs["rtol"] = rtol
    ds.attrs["moorings"] = mooring_report(plant, ds)
    if moored is not None:
        _add_tensions(ds, moored)
    report = estimation_report(controller)    # an estimator's accuracy
    if report is not None:
        ds.attrs["estimator"] = jsonable(report(t, W))
    if loop is not None:                 # analysis.validity reads it
        ds.attrs["sampled_loop"] = copy.deepcopy(loop)
    return ds


def _disturbance_record(plant, wave, t, W_nodes, moored) -> np.ndarray:
    """w at every sample (n+1, nw): a fixed-step run's start nodes hold w(t_0..t_n-1) (MoorDyn's
    forces included), then w(t_n); an adaptive run's from the wave."""
    nw = len(plant.disturbances)
    if W_nodes is None:
        return plant.excitation(wave, t) if wave is not None else np.zeros((t.size, nw))
    W = np.vstack([W_nodes[:, 0], plant.excitation(wave, t[-1:]) if wave is not None
                   else np.zeros((1, nw))])
    if moored is not None:            # MoorDyn's forces at t_n
        W[-1, moored["columns"]] = moored["w_last"]
    return W


def _add_tensions(ds, moored) -> None:
    """Each MoorDyn line's anchor and fairlead tension (N) as variables, what MoorDyn ran
    with in attrs["moordyn"], the lines' breakage and bed contact in attrs["moordyn_events"]."""
    for name, values in moored["tensions"].items():
        ds[name] = ("time", values, {"units": "N", "long_name": name.replace("__", " ")})
    ds.attrs["moordyn"] = moored["report"]
    ds.attrs["moordyn_events"] = moored["events"]


def _last_command(plant, controller, t, x, U, w, p) -> np.ndarray:
    """The command at the final sample, as the controller would issue it next."""
    if controller is None:
        return np.zeros((1, len(plant.inputs)))
    y = np.asarray(plant.h(x, U[-1], w, p)).ravel()
    return _command(controller, t, y, x, U.shape[1]).reshape(1, -1)


def _command(controller, t, y, x, nu) -> np.ndarray:
    """The controller's command; a controller with `uses_state = True` (full-state feedback,
    an oracle for studies) is also handed the plant's state."""
    u = controller(t, y, x) if uses_state(controller) else controller(t, y)
    return np.asarray(u, float).reshape(nu)


def _parameters(plant, params, controller) -> np.ndarray:
    """Parameter vector. A controller owns the PTO force (plant.ownership: the scene's PTO
    law off unless `params` sets it); a full vector is taken as it is."""
    if params is not None and not isinstance(params, dict):
        return np.asarray(params, float)
    if controller is None:
        return plant.params(**(params or {}))
    return plant.params(**controlled_params(plant, params))


def _run_fixed(plant, method, controller, x0, W_nodes, p, *, dt, n, law, embedded, compiled,
               check, alongside):
    nu = len(plant.inputs)
    if getattr(plant, "moordyn", ()):
        def command(i, x, u_prev, w):
            y = np.asarray(plant.h(x, u_prev, w, p[:len(plant.p0)])).ravel()
            return _command(controller, i * dt, y, x, nu)
        return run_moored(plant, method, x0, W_nodes, p, dt=dt, n=n, law=law,
                          compiled=compiled, check=check, alongside=alongside,
                          command=None if embedded else command,
                          period_steps=1 if embedded else _steps_per_period(
                              _period(controller, dt), dt))
    if embedded:
        return (*integrators.run_fixed_step(plant, x0, np.zeros((n, nu)), W_nodes, p, dt,
                                            method, law=law, compiled=compiled, on_chunk=check,
                                            alongside=alongside), None)
    m = _steps_per_period(_period(controller, dt), dt)
    stepper = HeldStepper(plant, method, m, p, dt, compiled)
    X, U = np.empty((n + 1, plant.nx)), np.empty((n, nu))
    X[0], u_prev = x0, np.zeros(nu)
    for i in range(0, n, m):
        k = min(m, n - i)
        y = stepper.outputs(X[i], u_prev, W_nodes[i, 0])
        u_prev = _command(controller, i * dt, y, X[i], nu)
        U[i:i + k] = u_prev
        X[i + 1:i + k + 1] = stepper.advance(X[i], u_prev, W_nodes[i:i + k])
        check(i + k, X[:i + k + 1])
        alongside.advance(i + k, X, U, W_nodes[:, 0])
    return X, U, None


def _run_cvodes(plant, wave, controller, x0, p, dt, n, rtol, check, method="cvodes"):
    nu = len(plant.inputs)
    terms = integrators.wave_terms(plant, wave) if wave is not None and plant.disturbances \
        else (np.zeros(0), np.zeros((len(plant.disturbances), 0)),
              np.zeros((len(plant.disturbances), 0)), 0.0)
    m = n if controller is None else _steps_per_period(_period(controller, dt), dt)
    X, U = np.empty((n + 1, plant.nx)), np.zeros((n, nu))
    X[0], u_prev = x0, np.zeros(nu)
    for i in range(0, n, m):
        k = min(m, n - i)
        if controller is not None:
            w_now = _wave_at(terms, i * dt)
            y = np.asarray(plant.h(X[i], u_prev, w_now, p)).ravel()
            u_prev = _command(controller, i * dt, y, X[i], nu)
        U[i:i + k] = u_prev
        grid = (i + np.arange(k + 1)) * dt
        integrator = integrators.cvodes_integrator(plant, terms, grid, rtol=rtol,
                                                   atol=rtol * 1e-3,
                                                   lmm="adams" if method == "adams" else "bdf")
        try:
            out = integrator(x0=X[i], p=np.concatenate([u_prev, p]))
        except RuntimeError as exc:
            raise SimulationError(f"{plant.name}: CVODES ({method}) failed between t = {grid[0]:.4g} s and "
                                  f"{grid[-1]:.4g} s: {str(exc)[:200]}; remedy: loosen rtol or "
                                  f"check the model for stiffness or bad parameters") from None
        X[i + 1:i + k + 1] = np.asarray(out["xf"]).T
        check(i + k, X[:i + k + 1])
    return X, U


def _wave_at(terms, t):
    omega, Fc, Fs, ramp_time = terms
    r = 1.0 if ramp_time <= 0 or t >= ramp_time else 0.5 * (1 - np.cos(np.pi * t / ramp_time))
    return r * (Fc @ np.cos(omega * t) + Fs @ np.sin(omega * t))


def _period(controller, dt: float) -> float:
    """The controller's hold period; None means every step."""
    return controller.period or dt


def _steps_per_period(period: float, dt: float) -> int:
    m = int(round(period / dt))
    if m < 1 or abs(m * dt - period) > 1e-9 * max(1.0, period):
        raise InputError(f"controller period {period} s must be a whole number of steps of "
                         f"dt = {dt} s")
    return m


EULER_MARGIN = float(np.cos(np.radians(85.0)))  # stop at |pitch| > 85 deg


def _warn_stiff(plant, dt):
    for name, stop in plant.notes.get("end_stops", {}).items():
        if dt > stop["rk4_max_dt_s"]:
            warnings.warn(f"{plant.name}: end stop '{name}' rings at {stop['omega_rad_s']:.4g} rad/s "
                          f"while engaged; RK4 is stable there only for dt <= {stop['rk4_max_dt_s']:.3g} s "
                          f"(dt = {dt} s). Use a smaller dt, method='cvodes', or a softer stop",
                          RuntimeWarning, stacklevel=3)


def _euler_pitch_states(plant) -> dict:
    """State index -> body, for the pitch angle of each 6-DOF free joint (ZYX Euler angles)."""
    return {plant.states.index(f"{j.name}__Pitch"): j.child for j in plant.scene.joints
            if j.type == "free" and len(j.dofs) == 6}


def _divergence_check(plant, dt, method, bar, why=None):
    """Stop with a clear SimulationError on the first non-finite or absurd state, or when a free
    body's Euler pitch nears ±90°, where its kinematics q' = K(q) s are singular. why: the
    closed-loop diagnosis of a divergence (sim.diagnose.explainer; None: the step is blamed)."""
    pitch, checked = _euler_pitch_states(plant), [0]

    def check(i_end, X):           # X: the states from t = 0 up to step i_end
        if bar is not None:
            bar.update(i_end - bar.n)
        start, checked[0] = checked[0], X.shape[0]
        if not pitch and np.abs(X[-1]).max() < 1e8:     # False for NaN: the one test per sample
            return                                      # a Python controller's loop pays
        last = X[-1]
        for idx, body in pitch.items():
            near = np.flatnonzero(np.abs(np.cos(X[start:, idx])) < EULER_MARGIN)
            if near.size:
                i = start + int(near[0])
                raise SimulationError(
                    f"{plant.name}: body '{body}' reached a pitch of {np.degrees(X[i, idx]):.1f} deg "
                    f"at t = {i * dt:.4g} s (step {i}): its free joint's ZYX Euler angles are singular at "
                    f"±90 deg. Remedy: a model whose motions stay away from it (check the loads and "
                    f"restoring in pitch), or a revolute/composite joint for large pitch")
        if np.all(np.isfinite(last)) and np.max(np.abs(last)) < 1e8:
            return
        bad = np.flatnonzero(~np.isfinite(X).all(axis=1) | (np.abs(X).max(axis=1) >= 1e8))
        i = int(bad[0]) if bad.size else i_end
        worst = plant.states[int(np.nanargmax(np.where(np.isfinite(X[i]), np.abs(X[i]),
                                                       np.inf)))]
        head = (f"{plant.name}: simulation diverged at t = {i * dt:.4g} s (step {i}, dt = {dt} s, "
                f"method {method!r}); state {worst!r} became non-finite or exceeded 1e8")
        cause = why(i * dt) if why is not None else None
        if cause:
            raise diverged(f"{head}: {cause}", i * dt)
        raise diverged(
            f"{head}. Remedy: a "
            f"smaller dt (try {dt / 4:g} s), method='exp-rk4' when fast radiation poles limit "
            f"the step, method='cvodes' for stiff loads (end stops, friction velocity_scale, "
            f"mooring stiffness), or `mbcontrol bench {plant.name} --stability` for each "
            f"method's largest stable step", i * dt)
    return check


def _progress_bar(progress: bool, n: int):
    if not progress:
        return None
    return progress_bar(total=n, unit="step", desc="simulate", leave=False)
