"""The nonlinear pressure sampled once per time step ([hydro] nonlinear_update = "step").

The pressure integral over a panel surface is the costly part of a nonlinear plant's f
(1,048 points: about 40 us a call, against under 1 us for the rest of the sphere's f), and an
explicit Runge-Kutta step calls f at every stage: four times per RK4 step. With "step", a
step evaluates the generalised pressure load tau_p(q, w) exactly once, at its start (q0, w0),
and moves it to the other stages by its first-order increments at rest:

    tau_p(q, w) ~ tau_p(q0, w0) + K (q - q0) + B (w - w0),   K = d tau_p/dq, B = d tau_p/dw at rest

(K the hydrostatic stiffness of the surface model, B its linear Froude-Krylov load per field
row). Every stage then sees the load's change across the step, so the step stays a
Runge-Kutta step of the plant; what is lost is the change of K and B away from rest within
one step, an error of order dt that `benchmarks/nonlinear_fk.py` charts against the
full-stage runs (tests/plant/test_held_pressure.py bounds it). The first stage is exact, and
so is everything else in f (radiation, PTOs, moorings, ...), at every stage.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

UPDATES = ("stage", "step")


@dataclass(frozen=True, eq=False)
class HeldPressure:
    """What a step needs to hold the pressure load: f with the load as an input, the load
    itself, and its increments at rest."""
    f: ca.Function              # (x, u, w, p, tau_p) -> x' with the pressure load given (N, N m)
    load: ca.Function           # (q, w) -> tau_p: the generalised pressure and weight load
    stiffness: np.ndarray       # (n_s, n_q): d tau_p / dq at rest (N/m, N m/rad)
    per_row: np.ndarray         # (n_s, n_w): d tau_p / dw at rest, zero for the excitation


def held_pressure(symbols, q, slot, x_dot, load) -> HeldPressure:
    """symbols = [x, u, w, p] of the plant; q its coordinates; x_dot (SX) the plant's x' with
    the symbol `slot` in the place of its generalised pressure and weight load `load` (SX), so
    that the held f never evaluates the surface."""
    x, u, w, p = symbols
    f = ca.Function("f_held", [x, u, w, p, slot], [x_dot], ["x", "u", "w", "p", "tau_p"],
                    ["xdot"])
    load_fun = ca.Function("pressure_load", [q, w], [load], ["q", "w"], ["tau_p"])
    slopes = ca.Function("slopes", [q, w], [ca.jacobian(load, q), ca.jacobian(load, w)])
    stiffness, per_row = (np.array(m) for m in slopes(np.zeros(q.shape[0]),
                                                       np.zeros(w.shape[0])))
    return HeldPressure(f, load_fun, stiffness, per_row)


def stage_load(held: HeldPressure, q0, w0, load0, q, w):
    """The load at a stage (q, w) from the step's start (q0, w0, load0): its rest increments."""
    return load0 + ca.mtimes(ca.DM(held.stiffness), q - q0) + ca.mtimes(ca.DM(held.per_row),
                                                                        w - w0)
