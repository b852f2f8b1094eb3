"""Running an exported controller from Python: its C library through ctypes as a Controller
(so `simulate` can close the loop with it), its step timed in C, and the comparison with the
Python controller it came from."""
from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np

from ..errors import InputError, UnknownName

_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def _ptr(a: np.ndarray):
    return a.ctypes.data_as(_DOUBLE_P)


class CController:
    """An exported controller's C library as a Controller (controllers.base protocol).

    library: lib<ident>.so; ident: its prefix; inputs: the plant outputs it reads, in order;
    n_force: number of PTO forces; period: s (None: every simulation step), as the Python
    controller's; params: None for the designed values."""

    def __init__(self, library, ident: str, inputs: list, n_force: int, period=None,
                 params=None, name: str = "exported"):
        self.lib = ctypes.CDLL(str(Path(library).resolve()))
        self.ident, self.inputs, self.n_force = ident, list(inputs), n_force
        self.period, self.name = period, f"{name} (C)"
        size = getattr(self.lib, f"{ident}_ctx_size")()
        self._ctx = ctypes.create_string_buffer(size + 64)   # ctypes buffers are aligned
        self._init = getattr(self.lib, f"{ident}_init")
        self._step = getattr(self.lib, f"{ident}_step")
        self._step.argtypes = [ctypes.c_void_p, _DOUBLE_P, ctypes.c_double, _DOUBLE_P]
        self._bench = getattr(self.lib, f"{ident}_bench")
        self._bench.argtypes = [ctypes.c_void_p, _DOUBLE_P, ctypes.c_int, _DOUBLE_P, _DOUBLE_P,
                                _DOUBLE_P, _DOUBLE_P]
        self.params = None if params is None else np.ascontiguousarray(params, float)
        self._force = np.zeros(n_force)
        self._index = None

    @classmethod
    def from_export(cls, exported, period=None, params=None):
        spec = exported.spec
        return cls(exported.library, exported.ident, spec.inputs, len(spec.outputs), period,
                   params, spec.name)

    def start(self) -> None:
        """init with the parameters (a fresh controller)."""
        p = None if self.params is None else _ptr(self.params)
        status = self._init(self._ctx, p)
        if status != 0:
            raise InputError(f"{self.ident}_init refused the parameters (status {status})")

    def reset(self, plant) -> None:
        missing = [n for n in self.inputs if n not in plant.outputs]
        if missing:
            raise UnknownName(f"{self.ident}: the plant has no output(s) {missing}")
        self._index = [plant.outputs.index(n) for n in self.inputs]
        self.start()

    def step(self, measurements, t: float) -> np.ndarray:
        m = np.ascontiguousarray(measurements, float)
        if self._step(self._ctx, _ptr(m), float(t), _ptr(self._force)) != 0:
            raise RuntimeError(f"{self.ident}_step failed at t = {t} s")
        return self._force.copy()

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        return self.step(np.asarray(y, float)[self._index], t)

    def casadi_law(self, plant):
        return None

    def describe(self) -> dict:
        return {"name": self.name, "period_s": self.period, "library": str(self.lib._name)}

    STAT_NAMES = ("solves", "failures", "soft_solves", "ar_fits", "ar_unstable_fits",
                  "qp_iterations_max")

    def counts(self) -> dict | None:
        """The run's counters so far (an MPC engine; None for other laws): QP solves,
        failures (the fallback, the previous plan's next move, fired), soft_solves (the
        stroke's soft form), AR fits and stabilised ones and the most iterations of one QP
        solve."""
        stats = getattr(self.lib, f"{self.ident}_stats", None)
        if stats is None:
            return None
        out = (ctypes.c_long * len(self.STAT_NAMES))()
        stats.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]
        k = stats(self._ctx, out, len(self.STAT_NAMES))
        return {name: int(out[i]) for i, name in enumerate(self.STAT_NAMES[:k])}

    def timed_run(self, measurements: np.ndarray, t: np.ndarray, cpu: bool = False) -> tuple:
        """(forces (rows, n_force), step wall times ns) of the measurement rows at times t,
        stepped and timed inside C from a fresh init; cpu: also each step's thread CPU time,
        ns (a third item)."""
        self.start()
        m = np.ascontiguousarray(measurements, float)
        t = np.ascontiguousarray(t, float)
        force = np.zeros((len(t), self.n_force))
        ns, cpu_ns = np.zeros(len(t)), np.zeros(len(t))
        if self._bench(self._ctx, _ptr(m), len(t), _ptr(t), _ptr(force), _ptr(ns),
                       _ptr(cpu_ns) if cpu else None) != 0:
            raise RuntimeError(f"{self.ident}_bench: a step failed")
        return (force, ns, cpu_ns) if cpu else (force, ns)


def step_statistics(ns: np.ndarray) -> dict:
    """median, p99 and max of step times, in microseconds."""
    us = np.asarray(ns, float) / 1e3
    return {"median": float(np.median(us)), "p99": float(np.percentile(us, 99)),
            "max": float(np.max(us)), "steps": int(us.size)}


def force_error(reference: np.ndarray, other: np.ndarray) -> float:
    """Largest force difference relative to the reference's peak force (dimensionless)."""
    reference, other = np.asarray(reference, float), np.asarray(other, float)
    scale = max(float(np.max(np.abs(reference))), 1e-300)
    return float(np.max(np.abs(other - reference)) / scale)
