"""Open-loop runs that keep arrays, not a Dataset: for sweeps, where a case is a few tens of
milliseconds of stepping and only its metrics are kept.

`simulate_arrays(plant, wave, ...)` steps like `simulate` (same compiled chunks, same
parameters, same divergence check and energy audit) and returns a `Run`: the time grid and
every plant output by name, readable as `run[name].values` like a Dataset's variable, with
the attributes the metrics read (`wave`, `controller`, ...). It skips what only a Dataset
needs: the wave elevation, the states and inputs as variables, provenance, the mooring
report. Measured on rm3 (one hour at dt 0.05 s, 72,000 RK4 steps, one core): 33-35 ms a run
against 62 ms for `simulate`, of which 21 ms is the stepping either way.

The excitation at the steps' nodes is `waves.coefficient_offsets` (one real inverse FFT on the
grid of half or whole steps, as `simulate` uses), with the interpolated coefficients cached
here across the seeds of a sea.
"""
from __future__ import annotations

import copy
import time

import numpy as np

from ..errors import InputError
from ..plant import derived
from . import integrators
from .run import _divergence_check, _parameters, _warn_stiff, energy_audit


class Run:
    """A run's outputs by name: `run["time"].values`, `run[name].values` ((n+1,) arrays),
    `run.data_vars`, `run.attrs` (model, wave, controller, method, dt_s, duration_s,
    wall_time_s, parameters): what the metrics and the validity checks read of a Dataset."""

    def __init__(self, t, names, Y, attrs):
        self.t, self.Y, self.attrs = t, Y, attrs
        self._column = {name: i for i, name in enumerate(names)}

    @property
    def data_vars(self) -> list[str]:
        return list(self._column)

    def __contains__(self, name) -> bool:
        return name == "time" or name in self._column

    def __getitem__(self, name):
        values = self.t if name == "time" else self.Y[:, self._column[name]]
        return _Column(values)


class _Column:
    __slots__ = ("values",)

    def __init__(self, values):
        self.values = values

    def __getitem__(self, index):
        return self.values[index]


def can_run(plant, controller, method: str) -> bool:
    """Whether `simulate_arrays` covers this run: no controller, a fixed-step method and no
    catenary mooring (whose report needs the full record) or MoorDyn mooring (stepped beside
    the plant, sim.moordyn_run)."""
    return (controller is None and integrators.method(method).fixed_step
            and not any(m.kind in ("catenary", "moordyn") for m in plant.scene.moorings))


def simulate_arrays(plant, wave=None, *, duration: float, dt: float, method: str = "rk4",
                    params=None, x0=None, compiled: bool = True, audit: bool = True) -> Run:
    """Open loop (the scene's PTO law), fixed step: the outputs of `simulate` as arrays.

    Same arguments as `simulate` without a controller; the divergence check (states) runs
    once over the whole record and the energy audit (the divergence guard) as in `simulate`.
    attrs["wall_time_s"]: excitation and stepping, as `simulate` reports it.
    """
    if duration <= 0 or dt <= 0 or dt > duration:
        raise InputError(f"expected 0 < dt <= duration, got dt={dt}, duration={duration}")
    spec = integrators.method(method)
    if not spec.fixed_step:
        raise InputError(f"simulate_arrays needs a fixed-step method, got {method!r}")
    if getattr(plant, "moordyn", ()):
        raise InputError(f"{plant.name}: simulate_arrays steps the plant alone; its MoorDyn "
                         f"moorings need sim.simulate")
    n = int(round(duration / dt))
    t = np.arange(n + 1) * dt
    p = _parameters(plant, params, None)
    x0 = plant.x0() if x0 is None else np.asarray(x0, float)
    nu = len(plant.inputs)
    if spec.kind == "explicit":
        _warn_stiff(plant, dt)
    integrators.prepare(plant, n, method, None, compiled)
    start = time.perf_counter()
    W_nodes = excitation_at_nodes(plant, wave, n, dt, spec.nodes)
    X, _ = integrators.run_fixed_step(plant, x0, np.zeros((n, nu)), W_nodes, p, dt, method,
                                      compiled=compiled)
    wall = time.perf_counter() - start
    # the states' check of `simulate`, once at the end: a diverged run steps on to the end of
    # its record (compiled code, milliseconds) and then raises the same error
    _divergence_check(plant, dt, method, None)(n, X)
    W = np.empty((n + 1, W_nodes.shape[2]))
    W[:n] = W_nodes[:, 0]
    W[n] = _last_excitation(plant, wave, t[-1], W_nodes, spec.nodes)
    Y = integrators.outputs(plant, X, np.zeros((n + 1, nu)), W, p, compiled=compiled)
    if audit:
        energy_audit(plant, t, Y, method, dt)
    attrs = {"model": plant.name, "method": method, "dt_s": dt, "duration_s": float(t[-1]),
             "wall_time_s": wall, "controller": None,
             "wave": copy.deepcopy(wave.describe()) if wave is not None else {"type": "none"},
             "parameters": dict(zip(plant.parameters, map(float, p)))}
    return Run(t, plant.outputs, Y, attrs)


def _last_excitation(plant, wave, t_end, W_nodes, nodes):
    """w(t_n): the last step's node at its end when the method has one (t_{n-1} + dt)."""
    if wave is None or W_nodes.shape[2] == 0:
        return np.zeros(W_nodes.shape[2])
    if 1.0 in nodes:
        return W_nodes[-1, list(nodes).index(1.0)]
    return plant.excitation(wave, np.array([t_end]))[0]


# --- excitation at the nodes, one inverse FFT -----------------------------------------------

COEFFICIENT_GRIDS_KEPT = 256      # frequency grids a plant keeps coefficients for


def excitation_at_nodes(plant, wave, n: int, dt: float, nodes) -> np.ndarray:
    """Excitation (n, len(nodes), n_w) at t_i + c dt, as `integrators.excitation_at_nodes`
    (`waves.coefficient_offsets`: one inverse FFT over the repeat period for all nodes), with
    the coefficients interpolated to the wave's frequencies kept per plant, direction and
    frequency grid (every seed of a sea shares them)."""
    from ..waves import coefficient_offsets
    if wave is None or not plant.disturbances or not wave.d_omega or wave.omega.size <= 16:
        return integrators.excitation_at_nodes(plant, wave, n, dt, nodes)
    return coefficient_offsets(wave, _coefficients(plant, wave), n, dt, nodes)


def _coefficients(plant, wave) -> np.ndarray:
    from ..errors import HydroError
    direction = wave.direction if not wave.directional else np.asarray(wave.direction).tobytes()
    kept = derived(plant, ("sim.light.coefficients",), dict)
    key = (direction, wave.omega.size, float(wave.omega[0]), float(wave.d_omega))
    if key not in kept:
        if len(kept) > COEFFICIENT_GRIDS_KEPT:
            kept.clear()
        try:       # the plant's rows of w: with nonlinear Froude-Krylov, the field's too
            coeffs = plant.wave_coefficients(wave)
        except HydroError:
            raise
        except ValueError as exc:
            raise HydroError(f"{plant.hydro.source}: {exc}") from None
        kept[key] = coeffs
    return kept[key]
