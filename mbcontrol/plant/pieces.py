"""The process plant's f in compiled pieces, for large plants.

f is one SX expression. Stepping code that calls it makes gcc compile it as one long function,
and gcc's time grows faster than the function's length: barge_chain's f at N = 16 (49,825
instructions: the mass matrix 12,760, the loads 17,033, the symbolic solve 12,400) took 23 s.
Here the same expressions are four functions, called in turn: M(q), the loads tau (radiation
included), the rates q' and chi', and the solve s' = M \\ tau (the same symbolic QR as f's),
so values equal f's to round-off; the compile took 9.9 s, and the steps run 5-9 % slower
(M and tau each compute the bodies' kinematics: RTF 288 against 306-316).

They are built only where the mass matrix is dense and large (at least PIECES_MASS_NONZEROS
entries, a 10-body chain): a farm's floats on vertical sliders have a diagonal M and an f
that is mostly the radiation model, and there the pieces compiled slower than f (16 floats:
11 s against 7 s) and stepped 13 % slower; barge_chain N = 8 compiles in 1.5 s, not 2.2 s.

Measured and not taken: holding the radiation matrices as data (sparse products over arrays,
not unrolled into code) compiled a 16-float farm in 0.8 s instead of 7 s, but stepped it 4x
slower (a dense C_r x over an array ran 5x slower than the unrolled product), and CasADi's
run-time QR for the solve cost barge_chain N = 4 a quarter of its speed.
"""
from __future__ import annotations

import casadi as ca


PIECES_MASS_NONZEROS = 100


def plant_parts(inputs, M, tau, q_dot, chi_dot) -> tuple | None:
    """f's pieces (ProcessPlant.parts): SX Functions of f's inputs (x, u, w, p) for M, tau and
    [q'; chi'], and (M, tau) -> M \\ tau; None (not built) where M has fewer than
    PIECES_MASS_NONZEROS structural nonzeros."""
    if M.nnz() < PIECES_MASS_NONZEROS:
        return None
    names = ["x", "u", "w", "p"]
    mass = ca.Function("f_mass", inputs, [M], names, ["M"])
    loads = ca.Function("f_loads", inputs, [tau], names, ["tau"])
    rates = ca.Function("f_rates", inputs, [q_dot, chi_dot], names, ["q_dot", "chi_dot"])
    M_sym, tau_sym = ca.SX.sym("M", M.sparsity()), ca.SX.sym("tau", tau.sparsity())
    solve = ca.Function("f_solve", [M_sym, tau_sym], [ca.solve(M_sym, tau_sym)])
    return mass, loads, rates, solve


def f_by_parts(plant) -> ca.Function:
    """The plant's f (same signature and values) as an MX Function calling its pieces (module
    docstring); f itself for a plant built without them. Stepping uses it where a step calls f
    as a function (large plants)."""
    if plant.parts is None:
        return plant.f
    mass, loads, rates, solve = plant.parts
    args = [ca.MX.sym(k, plant.f.sparsity_in(i)) for i, k in enumerate("xuwp")]
    q_dot, chi_dot = rates(*args)
    x_dot = ca.vertcat(q_dot, solve(mass(*args), loads(*args)), chi_dot)
    return ca.Function("f", args, [x_dot], ["x", "u", "w", "p"], ["xdot"])
