"""The integration methods known by name (`METHODS`) and the radiation split of exp-rk4.

Explicit Runge-Kutta tableaux (rk4, rk3, dopri5), the Lawson exponential method exp-rk4 (whose
linear radiation states are advanced by exp(A_r tau), block by block), and the adaptive CVODES
methods; `mbcontrol.sim.integrators` steps a plant with them.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta method: stage j evaluates f at x + h sum_i a[j][i] k_i and
    t + c[j] h; the step is x + h sum_j b[j] k_j."""
    a: tuple
    b: tuple
    c: tuple

    @property
    def nodes(self) -> tuple[float, ...]:
        """Distinct stage times (fractions of the step) where the excitation is needed."""
        return tuple(sorted(set(self.c) | {0.0}))


RK4 = Tableau(a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
              b=(1 / 6, 1 / 3, 1 / 3, 1 / 6), c=(0.0, 0.5, 0.5, 1.0))
RK3 = Tableau(a=((), (0.5,), (-1.0, 2.0)), b=(1 / 6, 2 / 3, 1 / 6), c=(0.0, 0.5, 1.0))
DOPRI5 = Tableau(
    a=((), (1 / 5,), (3 / 40, 9 / 40), (44 / 45, -56 / 15, 32 / 9),
       (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
       (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656)),
    b=(35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
    c=(0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0))


@dataclass(frozen=True)
class Method:
    name: str
    order: int
    kind: str                  # "explicit", "exponential" (fixed step) or "adaptive"
    description: str
    tableau: Tableau | None = None

    @property
    def fixed_step(self) -> bool:
        return self.kind != "adaptive"

    @property
    def nodes(self) -> tuple[float, ...]:
        return self.tableau.nodes if self.tableau else (0.0,)


METHODS: dict[str, Method] = {m.name: m for m in (
    Method("rk4", 4, "explicit", "classic Runge-Kutta, fixed step, compiled", RK4),
    Method("rk3", 3, "explicit", "Kutta's third-order Runge-Kutta, fixed step, compiled", RK3),
    Method("dopri5", 5, "explicit", "Dormand-Prince 5th-order weights, fixed step, compiled",
           DOPRI5),
    Method("exp-rk4", 4, "exponential", "Lawson RK4: radiation states exact (matrix "
           "exponential), rigid bodies RK4; fixed step, compiled", RK4),
    Method("cvodes", 5, "adaptive", "CVODES BDF (implicit, orders 1-5, exact Jacobian), "
           "adaptive: the step follows rtol"),
    Method("adams", 12, "adaptive", "CVODES Adams-Moulton (functional iteration, orders "
           "1-12), adaptive: the step follows rtol"),
)}


def method(name: str) -> Method:
    """The Method called `name`; ValueError listing the known ones otherwise."""
    if name not in METHODS:
        raise InputError(f"unknown integration method {name!r}; expected one of "
                         f"{', '.join(METHODS)}")
    return METHODS[name]


# --- the radiation split used by the exponential method -----------------------------------

def radiation_split(plant):
    """(first radiation state index, A_r, block sparsity of exp(A_r tau), block labels).

    The plant's radiation states are the last n_r states with chi' = A_r chi + B_r nu_h; A_r
    is in real modal form (1x1 and 2x2 blocks), so exp(A_r tau) has the same small blocks.
    """
    from ..plant import derived          # here: the method registry is read at start-up
    return derived(plant, ("sim.radiation_split",), lambda: _radiation_split(plant))


def _radiation_split(plant):
    import casadi as ca       # here, as scipy below: the registry is read at start-up
    from scipy.sparse.csgraph import connected_components
    A = plant.hydro.radiation_matrices()[0] if plant.hydro is not None else np.zeros((0, 0))
    n_r = sum(1 for s in plant.states if s.startswith("radiation_"))
    if A.shape[0] != n_r:
        A = np.zeros((0, 0))
    n, labels = connected_components(np.abs(A) + np.eye(A.shape[0]) > 0, directed=False) \
        if A.size else (0, np.zeros(0, int))
    pattern = labels[:, None] == labels[None, :]
    rows, cols = np.nonzero(pattern.T)           # CasADi is column-major
    sparsity = ca.Sparsity.triplet(A.shape[0], A.shape[0], cols.tolist(), rows.tolist())
    return plant.nx - A.shape[0], A, sparsity, labels


def radiation_exponential(A, labels, tau: float) -> np.ndarray:
    """exp(A tau), block by block (exact zeros off the blocks); closed forms for the 1x1 and
    2x2 blocks of a modal form (scipy's expm costs milliseconds per call, even on 2x2)."""
    E = np.zeros_like(A)
    for k in np.unique(labels):
        idx = np.flatnonzero(labels == k)
        block = A[np.ix_(idx, idx)] * tau
        E[np.ix_(idx, idx)] = _expm_small(block)
    return E


def _expm_small(M: np.ndarray) -> np.ndarray:
    if M.shape == (1, 1):
        return np.exp(M)
    if M.shape != (2, 2):
        import scipy.linalg
        return scipy.linalg.expm(M)
    # exp(M) = e^{m} (cosh(d) I + sinh(d)/d (M - m I)), m = tr/2, d^2 = det-free discriminant
    m = 0.5 * (M[0, 0] + M[1, 1])
    S = M - m * np.eye(2)
    d = np.sqrt(complex(S[0, 0] ** 2 + S[0, 1] * S[1, 0]))
    sinhc = np.sinh(d) / d if abs(d) > 1e-8 else 1.0 + d * d / 6
    return (np.exp(m) * (np.cosh(d) * np.eye(2) + sinhc * S)).real


# A run keeps every state at every step: 1e7 steps of 30 states are 2.4 GB. A three-hour sea at
# 0.01 s is 1.1e6 steps; a hostile "--duration 1e9" would be 1e11 and exhaust the memory.
MAX_STEPS = 10_000_000


def time_steps(duration: float, dt: float) -> int:
    """The number of steps of `dt` (s) that cover `duration` (s). A dt that does not divide the
    duration used to cut the run short without a word (dt 4 s, duration 5 s ran 4 s): the run
    now covers the whole duration, ending less than a step past it, and says so (a
    RuntimeWarning naming both flags); the result's duration_s is the time simulated."""
    if not (math.isfinite(duration) and math.isfinite(dt)) or duration <= 0 or dt <= 0:
        raise InputError(f"expected a finite duration > 0 and dt > 0 (s), got duration="
                         f"{duration}, dt={dt}")
    if dt > duration:
        raise InputError(f"the time step dt = {dt:g} s is longer than the duration "
                         f"{duration:g} s; expected dt <= duration (--dt, --duration)")
    steps = duration / dt
    if steps > MAX_STEPS:
        raise InputError(f"{duration:g} s at dt = {dt:g} s is {steps:.3g} time steps, more than "
                         f"the {MAX_STEPS:.0e} a run may hold; expected a shorter --duration or "
                         f"a longer --dt")
    n = max(1, math.ceil(steps - 1e-6 * max(1.0, steps)))
    if n * dt > duration * (1 + 1e-9) + 1e-12:
        warnings.warn(f"the duration {duration:g} s is not a whole number of time steps dt = "
                      f"{dt:g} s ({steps:.6g}): simulating {n * dt:.10g} s ({n} steps); give a "
                      f"dt that divides the duration (--dt, --duration) to run it exactly",
                      RuntimeWarning, stacklevel=3)
    return n
