"""The plant side of a Python controller's loop: one control period at a time, buffers set once.

A controller that runs in Python (latching, declutching, MPC, ...) is asked for a command once
per period: simulate samples y = h(x, u_prev, w) at the period's start, calls the controller,
and holds its command over the period's steps. Called through CasADi's Python interface, the
output map and a short chunk of steps cost more in conversions (DM in, DM out, a padded
copy per call) than in arithmetic: the sphere's latching tuner spent 35 % of its time there.
`HeldStepper` keeps every argument of both functions in arrays bound once to CasADi's
zero-copy buffers, so a period costs two C calls and a few array copies. It runs the same
compiled chunk as `integrators.run_fixed_step` (length `chunk_length(steps)`, padded with
zero steps that are discarded), so its states are those of a run_fixed_step call per period.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from .integrators import _chunk_function, chunk_length, step_extras
from .methods import METHODS


class HeldStepper:
    """`steps` steps of `dt` s per call with the input held, and the plant's outputs.

    plant: ProcessPlant; method_name: a fixed-step method of METHODS; p: the parameter
    vector; compiled: native code (else CasADi's interpreter)."""

    def __init__(self, plant, method_name: str, steps: int, p, dt: float, compiled=True):
        nx, nu, nw = plant.nx, len(plant.inputs), len(plant.disturbances)
        self.steps, self.length = int(steps), chunk_length(int(steps))
        nodes = len(METHODS[method_name].nodes)
        self._x = np.empty(nx)
        self._U = np.zeros((self.length, nu))
        self._W = np.zeros((self.length, nodes, nw))
        self._X = np.empty((self.length, nx))
        self._U_applied = np.empty((self.length, nu))
        self._p = np.ascontiguousarray(p, dtype=float)
        self._h = np.array([dt], dtype=float)
        self._extras = step_extras(plant, method_name, dt)
        self._chunk, _ = _chunk_function(plant, method_name, None, compiled,
                                         self.length).buffer()
        for i, array in enumerate((self._x, self._U, self._W, self._p, self._h, *self._extras)):
            self._chunk.set_arg(i, memoryview(array))
        self._chunk.set_res(0, memoryview(self._X))
        self._chunk.set_res(1, memoryview(self._U_applied))
        # outputs y = h(x, u, w, p), one sample
        self._hx, self._hu, self._hw = np.empty(nx), np.empty(nu), np.empty(nw)
        self._y = np.empty(len(plant.outputs))
        self._out, _ = plant.h.buffer()
        for i, array in enumerate((self._hx, self._hu, self._hw, self._p)):
            self._out.set_arg(i, memoryview(array))
        self._out.set_res(0, memoryview(self._y))

    def outputs(self, x, u, w) -> np.ndarray:
        """y = h(x, u, w, p) (a new array)."""
        self._hx[:], self._hu[:], self._hw[:] = x, u, w
        self._out._eval()
        return self._y.copy()

    def advance(self, x, u, W_nodes) -> np.ndarray:
        """The states after each of the k = len(W_nodes) <= steps steps from x, the input u
        held: (k, nx), a view valid until the next call. W_nodes: (k, nodes, nw)."""
        k = W_nodes.shape[0]
        if k > self.steps:
            raise InputError(f"HeldStepper: {k} steps asked, built for {self.steps}")
        self._x[:] = x
        self._U[:k] = u
        self._U[k:] = 0.0
        self._W[:k] = W_nodes
        self._W[k:] = 0.0
        self._chunk._eval()
        return self._X[:k]
