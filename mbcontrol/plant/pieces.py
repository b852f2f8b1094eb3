"""The process plant's f in compiled pieces, for large plants.

f is one SX expression. Stepping code that calls it makes gcc compile it as one long function,
and gcc's time grows faster than the function's length: barge_chain's f at N = 16 (49,825
instructions: the mass matrix 12,760, the loads 17,033, the symbolic solve 12,400) took 23 s,
and array_grid's 16 floats (33,145, nearly all the radiation model's products) 7 s. Here the
same expressions are moderate functions, called in turn:
- M(q); the loads tau without radiation; q'; the map G = P S^T from the hydro DOFs' forces to
  generalised forces and their velocities nu;
- the radiation model block by block (a decoupled DOF group of a coupled fit, or a column of a
  farm's column fit): chi_b' = A_b chi_b + B_b nu_b and its force C_b chi_b, with the block's
  numbers unrolled into its code as in f. Blocks with the same numbers (identical bodies
  solved alone, sharing one fit) are one function called for each copy;
- the solve s' = M \\ (tau - G mu), the same symbolic QR as f's.
Values equal f's to round-off (the radiation's sum is only reordered).

Built where f is large: a mass matrix of PIECES_MASS_NONZEROS entries or more (a 10-body
chain), or a radiation output matrix C_r of PIECES_RADIATION_NONZEROS or more (a farm).
Measured 2026-11-28 (step compile; real-time factor or a 60 s record's wall time):
barge_chain N = 16 8.4 s against 23-25 s (RTF 280 against 306-316); array_grid 16 floats
3.3 s against 7 s (RTF 557 against 633); 25 floats 15.3-15.9 s against 174 s (the first
60 s record, compile included, 19.5 s against 169 s; then 0.53 s against 0.46 s, best of 5).
The pieces step 9-16 % slower: the price of compiling in seconds what took minutes, once per
machine (the code is cached).

Measured and not taken: holding the radiation matrices as data (sparse products over arrays,
not unrolled into code) compiled a 16-float farm in 0.8 s instead of 7 s, but stepped it 4x
slower (a dense C_r x over an array ran 5x slower than the unrolled product), and CasADi's
run-time QR for the solve cost barge_chain N = 4 a quarter of its speed.
"""
from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from ..hydro import state_blocks

PIECES_MASS_NONZEROS = 100
PIECES_RADIATION_NONZEROS = 5000


def plant_parts(inputs, M, tau, q_dot, chi_dot, radiation=None) -> dict | None:
    """f's pieces (ProcessPlant.parts), or None where f is small enough to compile whole.

    inputs: f's (x, u, w, p); radiation: (chi, G, nu, (A_r, B_r, C_r, D_r)) where the radiation
    model does not depend on parameters (else None: it stays in the loads and rates)."""
    big_radiation = radiation is not None and np.count_nonzero(radiation[3][2]) >= \
        PIECES_RADIATION_NONZEROS
    if M.nnz() < PIECES_MASS_NONZEROS and not big_radiation:
        return None
    names = ["x", "u", "w", "p"]
    M_sym, tau_sym = ca.SX.sym("M", M.sparsity()), ca.SX.sym("tau", tau.sparsity())
    parts = {"mass": ca.Function("f_mass", inputs, [M], names, ["M"]),
             "solve": ca.Function("f_solve", [M_sym, tau_sym], [ca.solve(M_sym, tau_sym)])}
    if radiation is None or chi_dot.numel() == 0:
        parts["loads"] = ca.Function("f_loads", inputs, [tau], names, ["tau"])
        parts["rates"] = ca.Function("f_rates", inputs, [q_dot, chi_dot], names,
                                     ["q_dot", "chi_dot"])
        return parts
    chi, G, nu, matrices = radiation
    # f's radiation force is C_r chi + D_r nu: chi = 0 leaves the rest, term for term (a
    # D_r nu, zero for a strictly proper fit, stays in the loads)
    parts["loads"] = ca.Function("f_loads", inputs, [ca.substitute(tau, chi, ca.SX.zeros(chi.shape))],
                                 names, ["tau"])
    parts["rates"] = ca.Function("f_rates", inputs, [q_dot, G, nu], names, ["q_dot", "G", "nu"])
    parts["radiation"] = radiation_blocks(*matrices[:3])
    return parts


def radiation_blocks(A, B, C) -> dict:
    """The radiation model (A_r, B_r, C_r) as independent blocks: {"blocks": [(states, inputs,
    outputs, Function (chi_b, nu_b) -> (C_b chi_b, chi_b'))], "n": states}. A block is a
    connected set of states with the inputs that drive them; blocks with equal numbers share
    one Function (named by its content)."""
    A, B, C = (np.asarray(m, float) for m in (A, B, C))
    functions, blocks = {}, []
    for states, inputs in state_blocks(A, B):
        outputs = np.flatnonzero(np.any(C[:, states] != 0, axis=1))
        a, b, c = A[np.ix_(states, states)], B[np.ix_(states, inputs)], C[np.ix_(outputs, states)]
        key = hashlib.sha256(b"".join(np.ascontiguousarray(m).tobytes() + str(m.shape).encode()
                                      for m in (a, b, c))).hexdigest()[:16]
        if key not in functions:
            chi_b, nu_b = ca.SX.sym("chi", states.size), ca.SX.sym("nu", inputs.size)
            a, b, c = (ca.sparsify(ca.DM(m)) for m in (a, b, c))   # no products with zeros
            functions[key] = ca.Function(f"f_radiation_{key}", [chi_b, nu_b],
                                         [ca.mtimes(c, chi_b), ca.mtimes(a, chi_b) + ca.mtimes(b, nu_b)])
        blocks.append((states, inputs, outputs, functions[key]))
    return {"blocks": blocks, "n": A.shape[0]}


def f_by_parts(plant) -> ca.Function:
    """The plant's f (same signature and values) as an MX Function calling its pieces (module
    docstring); f itself for a plant built without them. Stepping uses it where a step calls f
    as a function (large plants)."""
    if plant.parts is None:
        return plant.f
    parts = plant.parts
    args = [ca.MX.sym(k, plant.f.sparsity_in(i)) for i, k in enumerate("xuwp")]
    M, tau = parts["mass"](*args), parts["loads"](*args)
    if "radiation" not in parts:
        q_dot, chi_dot = parts["rates"](*args)
    else:
        q_dot, G, nu = parts["rates"](*args)
        radiation, start = parts["radiation"], 2 * plant.n_q
        chi, blocks = args[0][start:], radiation["blocks"]
        forces, rates = zip(*[block(chi[states.tolist()], nu[inputs.tolist()])
                              for states, inputs, _, block in blocks])
        # the blocks' rates joined (reordered only if they are not in state order) and their
        # forces summed by one sparse product, rather than a write into a long vector per block
        order = np.concatenate([states for states, *_ in blocks])
        chi_dot = ca.vertcat(*rates)
        if not np.array_equal(order, np.arange(order.size)):     # blocks not in state order
            chi_dot = chi_dot[np.argsort(order).tolist()]
        rows = np.concatenate([outputs for *_, outputs, _ in blocks])
        gather = ca.DM(ca.Sparsity.triplet(G.shape[1], rows.size, rows.tolist(),
                                           list(range(rows.size))), 1.0)
        tau = tau - ca.mtimes(G, ca.mtimes(gather, ca.vertcat(*forces)))
    x_dot = ca.vertcat(q_dot, parts["solve"](M, tau), chi_dot)
    return ca.Function("f", args, [x_dot], ["x", "u", "w", "p"], ["xdot"])


def distinct_radiation_functions(plant) -> int:
    """How many radiation block Functions the plant's pieces compile (0 without them)."""
    if plant.parts is None or "radiation" not in plant.parts:
        return 0
    return len({id(f) for *_, f in plant.parts["radiation"]["blocks"]})
