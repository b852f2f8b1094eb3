"""Many sea states or parameter sets in one compiled call: CasADi map over cases.

`simulate_batch` steps every case together: each compiled call advances all cases by a
chunk of steps (the chunk's mapaccum, mapped over cases), so a sweep or an identification's
candidate set pays one call per chunk instead of one per case, and shares one compiled
library keyed by the plant's structure. Results come back as one Dataset with a `case`
dimension, converted to numpy once.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..errors import InputError, SimulationError
from ..plant import derived
from . import integrators
from .compiled import compile_function


def simulate_batch(plant, waves=None, params=None, *, duration: float, dt: float,
                   method: str = "rk4", x0=None, compiled: bool = True,
                   audit: bool = True) -> xr.Dataset:
    """Simulate every case (open loop, the scene's PTO law) in one compiled call per chunk.

    waves: a list of Waves (None entries: still water) or one Wave for all; params: a list of
    dicts of parameter overrides (or full vectors), or None for the scene's values. The
    number of cases is the longer list; a single entry is shared. method: a fixed-step name.
    Returns a Dataset over (case, time) with every plant output, and the states over
    (case, time, state_name); attrs: wall_time_s (excitation + stepping of all cases).
    """
    from .run import energy_audit
    waves_list, params_list = _cases(waves, params)
    t, X, P, wall = batch_states(plant, waves_list, params_list, duration=duration, dt=dt,
                                 method=method, x0=x0, compiled=compiled)
    n_cases = X.shape[0]
    Y = np.empty((n_cases, t.size, len(plant.outputs)))
    U = np.zeros((t.size, len(plant.inputs)))
    for c in range(n_cases):
        W = plant.excitation(waves_list[c], t) if waves_list[c] is not None \
            else np.zeros((t.size, len(plant.disturbances)))
        Y[c] = integrators.outputs(plant, X[c], U, W, P[c], compiled=compiled)
        if audit:
            try:
                energy_audit(plant, t, Y[c], method, dt)
            except SimulationError as exc:
                raise SimulationError(f"case {c}: {exc}") from None
    data = {name: (("case", "time"), Y[:, :, i], {"units": plant.units(name)})
            for i, name in enumerate(plant.outputs)}
    data["state"] = (("case", "time", "state_name"), X)
    ds = xr.Dataset(data, coords={"case": np.arange(n_cases), "time": ("time", t, {"units": "s"}),
                                  "state_name": list(plant.states)})
    ds.attrs.update({"model": plant.name, "method": method, "dt_s": dt, "cases": n_cases,
                     "wall_time_s": wall,
                     "waves": str([w.describe() if w is not None else None for w in waves_list]),
                     "parameter_names": list(plant.parameters)})
    ds["parameters"] = (("case", "parameter"), P)
    return ds


def batch_states(plant, waves=None, params=None, *, duration: float, dt: float,
                 method: str = "rk4", x0=None, compiled: bool = True):
    """The stepping of `simulate_batch` alone: (t (n+1,), X (cases, n+1, nx), P (cases, np),
    wall time s), for callers that evaluate outputs themselves (e.g. only over a window)."""
    import time
    spec = integrators.method(method)
    if not spec.fixed_step:
        raise InputError(f"simulate_batch needs a fixed-step method, got {method!r}")
    if getattr(plant, "moordyn", ()):
        raise InputError(f"{plant.name}: simulate_batch steps the cases in one compiled call; "
                         f"its MoorDyn moorings are stepped beside the plant: use sim.simulate")
    waves_list, params_list = _cases(waves, params)
    n_cases = len(waves_list)
    P = np.array([_vector(plant, p) for p in params_list])                 # (cases, np)
    n = int(round(duration / dt))
    x0 = plant.x0() if x0 is None else np.asarray(x0, float)
    length = integrators.chunk_length(n)
    fun = _batch_function(plant, method, length, n_cases, compiled)

    start = time.perf_counter()
    W_nodes = np.stack([integrators.excitation_at_nodes(plant, w, n, dt, spec.nodes)
                        for w in waves_list])                              # (cases, n, k, nw)
    X = _run(fun, plant, method, x0, W_nodes, P, dt, n, length)
    return np.arange(n + 1) * dt, X, P, time.perf_counter() - start


def _cases(waves, params) -> tuple[list, list]:
    """waves and params as two lists of one entry per case (a single entry is shared)."""
    waves_list = list(waves) if isinstance(waves, (list, tuple)) else [waves]
    params_list = list(params) if isinstance(params, (list, tuple)) else [params]
    n_cases = max(len(waves_list), len(params_list))
    for name, items in (("waves", waves_list), ("params", params_list)):
        if len(items) not in (1, n_cases):
            raise InputError(f"simulate_batch: {name} has {len(items)} entries; expected 1 or "
                             f"{n_cases} (one per case)")
    waves_list = waves_list * n_cases if len(waves_list) == 1 else waves_list
    params_list = params_list * n_cases if len(params_list) == 1 else params_list
    return waves_list, params_list


def _vector(plant, params) -> np.ndarray:
    if params is None:
        return plant.p0.copy()
    if isinstance(params, dict):
        return plant.params(**params)
    p = np.asarray(params, float)
    if p.shape != plant.p0.shape:
        raise InputError(f"{plant.name}: a parameter vector needs {plant.p0.size} values "
                         f"({', '.join(plant.parameters)}), got {p.size}")
    return p


def _batch_function(plant, method, length, n_cases, compiled):
    """(x (nx x cases), U, W, P (np x cases), h, *extras) -> X (nx x length*cases), compiled
    once per (plant, method, chunk length, cases)."""
    return derived(plant, ("sim.batch", method, length, n_cases, compiled),
                   lambda: _build_batch(plant, method, length, n_cases, compiled))


def _build_batch(plant, method, length, n_cases, compiled):
    import casadi as ca
    chunk = integrators.chunk_symbolic(plant, method, None, length)
    mapped = chunk.map(n_cases)
    x = ca.MX.sym("x", plant.nx, n_cases)
    U = ca.MX.sym("U", len(plant.inputs), length * n_cases)
    W = ca.MX.sym("W", chunk.size1_in(2), chunk.size2_in(2) * n_cases)
    P, h = ca.MX.sym("P", len(plant.p0), n_cases), ca.MX.sym("h")
    extras = [ca.MX.sym(f"e{i}", chunk.sparsity_in(5 + i))
              for i in range(chunk.n_in() - 5)]
    X, _ = mapped(x, U, W, P, ca.repmat(h, 1, n_cases),
                  *[ca.repmat(e, 1, n_cases) for e in extras])
    fun = ca.Function("batch", [x, U, W, P, h, *extras], [X])
    return compile_function(fun, enabled=compiled)


def _run(fun, plant, method, x0, W_nodes, P, dt, n, length):
    n_cases, nx = P.shape[0], plant.nx
    X = np.empty((n_cases, n + 1, nx))
    X[:, 0] = x0
    U = np.zeros((n_cases, length, len(plant.inputs)))
    buffer, _ = fun.buffer()
    P = np.ascontiguousarray(P)
    h = np.array([dt])
    extras = integrators.step_extras(plant, method, dt)
    buffer.set_arg(1, memoryview(U))
    buffer.set_arg(3, memoryview(P))
    buffer.set_arg(4, memoryview(h))
    for i, e in enumerate(extras):
        buffer.set_arg(5 + i, memoryview(e))
    out = np.empty((n_cases, length, nx))
    buffer.set_res(0, memoryview(out))
    for begin in range(0, n, length):
        stop = min(begin + length, n)
        x_in = np.ascontiguousarray(X[:, begin])
        W_c = np.zeros((n_cases, length) + W_nodes.shape[2:])
        W_c[:, :stop - begin] = W_nodes[:, begin:stop]
        buffer.set_arg(0, memoryview(x_in))
        buffer.set_arg(2, memoryview(W_c))
        buffer._eval()
        X[:, begin + 1:stop + 1] = out[:, :stop - begin]
        bad = ~np.isfinite(X[:, stop]).all(axis=1)
        if bad.any():
            c = int(np.flatnonzero(bad)[0])
            raise SimulationError(f"{plant.name}: batch case {c} diverged by t = {stop * dt:.4g} s "
                                  f"(steps {begin}..{stop}, dt = {dt} s, method {method!r}). "
                                  f"Remedy: a smaller dt, or method='exp-rk4'")
    return X
