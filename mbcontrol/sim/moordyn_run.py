"""A run with MoorDyn moorings: the plant and MoorDyn stepped in turn (a co-simulation).

Per step of dt from t_i: the Coupled points' positions and velocities at t_i (from the state
x_i) go to MoorDyn, which advances its lines to t_i + dt, sub-cycling at its own time step
(the file's dtM), and returns the forces on the points at t_i + dt. The plant holds the lines'
quasi-static part itself (mbcontrol.plant.moordyn_loads), so MoorDyn supplies the remainder:
its force less that part, which the plant's compiled step sees vary linearly from R_i to R_i+1
across its stages (the rows of w at the method's nodes). MoorDyn extrapolates the points'
motion over its step from their position and velocity at t_i, as it does in WEC-Sim and
OpenFAST. So the coupling is explicit, first order in dt, and any fixed-step method of the
plant can run it; adaptive ones cannot (MoorDyn has no Jacobian for them), and are refused.

Recorded per sample: each line's tension at end A (MoorDyn: the anchor end) and end B (the
fairlead end), N, as "<mooring>__line<k>__anchor_tension" and "...__fairlead_tension".
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import block_diag

from ..plant import derived, moordyn_kinematics
from ..scene import TO_MOORDYN
from .compiled import compile_function
from .integrators import _chunk_function, step_extras
from .methods import METHODS
from .moordyn_events import LineEvents
from ..plant import MoorDynSystem

CHECK_EVERY = 512        # steps between divergence checks and hand-overs of outputs


def prepare_moored(plant, compiled: bool = True):
    """The compiled kinematics of the plant's Coupled points, built once per plant."""
    return derived(plant, ("sim.moordyn_points", compiled), lambda: compile_function(
        moordyn_kinematics(plant), enabled=compiled, label=f"{plant.name}: mooring points"))


class MooredRun:
    """MoorDyn systems of a plant's moorings, initialised at the state x0."""

    def __init__(self, plant, x0, compiled: bool = True):
        self.plant = plant
        self._kin = prepare_moored(plant, compiled)
        n_points = sum(len(g.ids) for g in plant.moordyn)
        self._x = np.empty(plant.nx)
        self._P, self._V = np.empty((n_points, 3)), np.empty((n_points, 3))
        self._buffer, _ = self._kin.buffer()
        self._buffer.set_arg(0, memoryview(self._x))
        self._buffer.set_res(0, memoryview(self._P))
        self._buffer.set_res(1, memoryview(self._V))
        P, V = self.points(x0)
        moorings = {m.name: m for m in plant.scene.moorings}
        self.systems, self._spans, start = [], [], 0
        try:
            for g in plant.moordyn:
                span = slice(start, start + len(g.ids))
                self.systems.append(MoorDynSystem(plant.scene, moorings[g.mooring], P[:, span],
                                                  V[:, span]))
                self._spans.append(span)
                start = span.stop
        except BaseException:
            self.close()
            raise
        self._sign = np.tile(TO_MOORDYN, n_points)           # flat MoorDyn <-> n-frame
        # the plant's own quasi-static part of the lines, F_0 + J (P - P_0) = offset + J P,
        # flat, n-frame
        self._stiffness = block_diag(*[g.stiffness for g in plant.moordyn])
        self._offset = np.concatenate([g.pull.T.ravel() for g in plant.moordyn]) \
            - self._stiffness @ np.concatenate([g.rest.T.ravel() for g in plant.moordyn])
        self._moved = np.empty(3 * n_points)
        first = len(plant.disturbances) - 3 * n_points
        self.columns = slice(first, len(plant.disturbances))       # the rows of w it fills
        self.names = [f"{s.name}__line{line.id}__{end}_tension" for s in self.systems
                      for end in ("anchor", "fairlead") for line in s.data.lines]

    def points(self, x) -> tuple[np.ndarray, np.ndarray]:
        """The Coupled points' n-frame positions and velocities (3, n) at state x."""
        self._x[:] = x
        self._buffer._eval()
        return self._P.T.copy(), self._V.T.copy()

    def forces(self, x, t: float, dt: float) -> np.ndarray:
        """MoorDyn stepped from t to t + dt from the points at state x (dt = 0: no step);
        the point forces at the end, flat in w's order (N, n-frame)."""
        self._x[:] = x
        self._buffer._eval()
        if dt <= 0:
            return np.concatenate([s.forces().T.ravel() for s in self.systems])
        P = (self._P * TO_MOORDYN).ravel()           # MoorDyn's frame, flat [x1 y1 z1 ...]
        V = (self._V * TO_MOORDYN).ravel()
        if len(self.systems) == 1:
            return self.systems[0].step_flat(P.tolist(), V.tolist(), t, dt) * self._sign
        flat = [s.step_flat(P[3 * span.start:3 * span.stop].tolist(),
                            V[3 * span.start:3 * span.stop].tolist(), t, dt)
                for s, span in zip(self.systems, self._spans)]
        return np.concatenate(flat) * self._sign

    def remainder(self, x, t: float, dt: float) -> np.ndarray:
        """`forces` less the plant's own quasi-static part of the lines at the points'
        positions at t + dt (MoorDyn's: moved on from x at their velocity): what the plant
        takes in its MoorDyn rows of w."""
        F = self.forces(x, t, dt)
        moved = self._moved
        np.multiply(self._V.ravel(), max(dt, 0.0), out=moved)
        moved += self._P.ravel()
        F -= self._offset
        F -= self._stiffness @ moved
        return F

    def tensions(self) -> np.ndarray:
        """Anchor then fairlead tension of every line, mooring by mooring (N), in `names` order."""
        return np.concatenate([s.tensions().ravel() for s in self.systems])

    def report(self) -> dict:
        """What each MoorDyn system ran with (for the result's attrs)."""
        return {s.name: {**s.environment, "file": s.data.path,
                         "format": f"MoorDyn v{s.data.version}", "dtM_s": s.dt_mooring,
                         "lines": len(s.data.lines),
                         "segments": [line.segments for line in s.data.lines],
                         **(s.settled or {"settled": "off"})}
                for s in self.systems}

    def close(self) -> None:
        for s in self.systems:
            s.close()


class _OneStep:
    """The plant's compiled step, one step per call, its arguments bound to arrays."""

    def __init__(self, plant, method: str, law, p, dt: float, compiled: bool):
        fun = _chunk_function(plant, method, law, compiled, 1)
        self.buffer, _ = fun.buffer()
        self._p = np.ascontiguousarray(p, dtype=float)
        self._h = np.array([dt])
        self._U = np.zeros(len(plant.inputs))
        self._extras = step_extras(plant, method, dt)
        self.buffer.set_arg(1, memoryview(self._U))
        self.buffer.set_arg(3, memoryview(self._p))
        self.buffer.set_arg(4, memoryview(self._h))
        for i, e in enumerate(self._extras):
            self.buffer.set_arg(5 + i, memoryview(e))

    def __call__(self, x, u, W, x_next, u_applied) -> None:
        self._U[:] = u
        self.buffer.set_arg(0, memoryview(x))
        self.buffer.set_arg(2, memoryview(W))
        self.buffer.set_res(0, memoryview(x_next))
        self.buffer.set_res(1, memoryview(u_applied))
        self.buffer._eval()


def run_moored(plant, method, x0, W_nodes, p, *, dt, n, law, compiled, check, alongside,
               command=None, period_steps: int = 1):
    """Integrate n steps with the moorings: (X (n+1, nx), U (n, nu), record). W_nodes gets
    the point forces in its MoorDyn rows. command(i, x, u_prev, w) -> u: a Python controller
    asked every `period_steps` steps (None: u = 0, or the compiled `law`). record: the
    tensions (n+1, n_lines*2) by name, the MoorDyn rows of w at t_n, the report, and the
    lines' breakage and bed contact (sim.moordyn_events)."""
    nodes = np.asarray(METHODS[method].nodes)[:, None]
    step = _OneStep(plant, method, law, p, dt, compiled)
    moored = MooredRun(plant, x0, compiled)
    events = LineEvents(plant, moored)
    X, U = np.empty((n + 1, plant.nx)), np.zeros((n, len(plant.inputs)))
    X[0] = x0
    tensions = np.empty((n + 1, len(moored.names)))
    cols, u = moored.columns, np.zeros(len(plant.inputs))
    try:
        f_now, tensions[0] = moored.remainder(x0, 0.0, 0.0), moored.tensions()
        for i in range(n):
            f_next = moored.remainder(X[i], i * dt, dt)
            W_nodes[i, :, cols] = f_now + nodes * (f_next - f_now)
            if command is not None and i % period_steps == 0:
                u = command(i, X[i], u, W_nodes[i, 0])
            step(X[i], u, W_nodes[i], X[i + 1], U[i])
            tensions[i + 1] = moored.tensions()
            if events.watching:
                events.after_step(i + 1, (i + 1) * dt, tensions[i + 1])
            f_now = f_next
            if (i + 1) % CHECK_EVERY == 0 or i + 1 == n:
                check(i + 1, X[:i + 2])
                if alongside is not None:
                    alongside.advance(i + 1, X, U, W_nodes[:, 0])
        return X, U, {"tensions": dict(zip(moored.names, tensions.T)), "w_last": f_now,
                      "columns": cols, "report": moored.report(), "events": events.record}
    finally:
        moored.close()
