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

Measured and not taken: the sparse product C_r x over an array (CasADi's casadi_mtimes: an
indexed scatter per nonzero, not vectorised) ran 6x slower than dot products over the rows, and
CasADi's run-time QR for the solve cost barge_chain N = 4 a quarter of its speed.

Farms (C_r of PIECES_RADIATION_NONZEROS or more) keep their dense couplings as DATA, so that
their code grows as N, not N^2: the radiation force C_r chi is one dot product per hydro DOF
over a row of C_r held as a constant array (casadi_dot: a plain loop that gcc vectorises, 5 us
for 25 x 1,500 against 31 us as casadi_mtimes), the blocks' code holds only chi_b' = A_b chi_b
+ B_b nu_b (a column fit's blocks share their poles: few distinct functions), and a constant
mass matrix (bodies on fixed axes: no q in M) is inverted once, numerically, s' = M^-1 tau by
one dot product per row. The outputs likewise ("outputs": h with C_r chi and the kinetic
energy's M s as inputs, `h_by_parts`). Values equal f's and h's to round-off.
Measured 2026-12-06 (benchmarks/farm_compile.py, array_grid on a synthetic hydro model of 60
states per float; step compile, its C, a 60 s record's real-time factor): 25 floats 0.9-1.0 s
and 824 kB (of which 109 kB code, the rest C_r's numbers) against 20 s and 2.2 MB (the column
blocks 1.5 MB, the symbolic solve 0.7 MB: N^2 and N^3); 49 floats 1.5-1.8 s against 254 s
(10.5 MB); 49 over 25 floats 1.6-1.9x (proportional: 1.96x). Stepping 2.7-3x faster (16
floats RTF 641 against 238, 25 floats 230 against 76: the unrolled products were megabytes of
instructions), same end states to 1e-14.
"""
from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from ..hydro import state_blocks

PIECES_MASS_NONZEROS = 100
PIECES_RADIATION_NONZEROS = 5000


def radiation_as_data(C_r) -> bool:
    """Whether a radiation output matrix C_r (n_h x n_r) is large enough (a farm's) to be
    compiled as data (module docstring)."""
    return np.count_nonzero(C_r) >= PIECES_RADIATION_NONZEROS


def radiation_value(apart, chi):
    """expression -> the expression with the radiation force symbol mu_r (a farm's, see
    plant.process._hydro_loads) replaced by its value C_r chi; the identity for other plants."""
    if apart is None or apart[4] is None:
        return lambda expression: expression
    mu_r, value = apart[4], ca.mtimes(sparse_constant(apart[3][2]), chi)
    return lambda expression: ca.substitute(expression, mu_r, value)


def kinetic_energy(s, M, apart, symbols):
    """(0.5 s^T M s (J), None); for a farm (apart with mu_r) whose M does not depend on
    `symbols` (q, p): (0.5 s . m, m) with m = M s a symbol, so that its outputs in parts take
    M s as data (its value is put back by `momentum_value`)."""
    if apart is None or apart[4] is None or ca.depends_on(M, symbols):
        return 0.5 * ca.mtimes([s.T, M, s]), None
    momentum = ca.SX.sym("Ms", M.shape[0])
    return 0.5 * ca.dot(s, momentum), momentum


def momentum_value(expression, momentum, M, s):
    """The expression with kinetic_energy's symbol m replaced by its value M s."""
    return expression if momentum is None else ca.substitute(expression, momentum, ca.mtimes(M, s))


def sparse_constant(matrix) -> ca.DM:
    """A numpy matrix as a CasADi DM of its nonzeros only (ca.sparsify(ca.DM(matrix)) without
    first making the dense DM, slow for a farm's n_r x n_r A_r)."""
    matrix = np.asarray(matrix, float)
    cols, rows = np.nonzero(matrix.T)                   # column-major: CasADi's storage order
    return ca.DM(ca.Sparsity.triplet(*matrix.shape, rows.tolist(), cols.tolist()),
                 matrix[rows, cols])


def plant_parts(inputs, M, tau, q_dot, chi_dot, radiation=None, outputs=None) -> dict | None:
    """f's pieces (ProcessPlant.parts), or None where f is small enough to compile whole.

    inputs: f's (x, u, w, p); radiation: (chi, G, nu, (A_r, B_r, C_r, D_r), mu_r) where the
    radiation model does not depend on parameters (else None: it stays in the loads and
    rates); mu_r: the symbol of the radiation force C_r chi in the outputs (a farm's) or None;
    outputs: (y, m), the outputs with mu_r and kinetic_energy's symbol m = M s (or None) in
    them, for "outputs" (x, u, w, p, mu_r[, m]) -> y."""
    big_radiation = radiation is not None and radiation_as_data(radiation[3][2])
    if M.nnz() < PIECES_MASS_NONZEROS and not big_radiation:
        return None
    names = ["x", "u", "w", "p"]
    parts = _mass_parts(inputs, M, tau, names)
    if radiation is None or chi_dot.numel() == 0:
        parts["loads"] = ca.Function("f_loads", inputs, [tau], names, ["tau"])
        parts["rates"] = ca.Function("f_rates", inputs, [q_dot, chi_dot], names,
                                     ["q_dot", "chi_dot"])
        return parts
    chi, G, nu, matrices, mu_r = radiation
    # f's radiation force is C_r chi + D_r nu: chi = 0 leaves the rest, term for term (a
    # D_r nu, zero for a strictly proper fit, stays in the loads)
    parts["loads"] = ca.Function("f_loads", inputs, [ca.substitute(tau, chi, ca.SX.zeros(chi.shape))],
                                 names, ["tau"])
    parts["rates"] = ca.Function("f_rates", inputs, [q_dot, G, nu], names, ["q_dot", "G", "nu"])
    parts["radiation"] = radiation_blocks(*matrices[:3], output_as_data=big_radiation)
    if big_radiation and mu_r is not None:
        y, momentum = outputs
        apart = [mu_r] + ([] if momentum is None else [momentum])
        parts["outputs"] = ca.Function("h_apart", [*inputs, *apart], [y])
    return parts


def _mass_parts(inputs, M, tau, names) -> dict:
    """{"mass_matrix": M, "inverse_mass": M^-1} (arrays) where M is constant, else the
    Functions "mass" (x, u, w, p) -> M and "solve" (M, tau) -> M \\ tau (symbolic QR)."""
    if not ca.depends_on(M, ca.vertcat(*[ca.vec(v) for v in inputs])):
        mass = np.array(ca.evalf(M), float)
        return {"mass_matrix": mass, "inverse_mass": np.linalg.inv(mass)}
    M_sym, tau_sym = ca.SX.sym("M", M.sparsity()), ca.SX.sym("tau", tau.sparsity())
    return {"mass": ca.Function("f_mass", inputs, [M], names, ["M"]),
            "solve": ca.Function("f_solve", [M_sym, tau_sym], [ca.solve(M_sym, tau_sym)])}


def radiation_blocks(A, B, C, output_as_data: bool = False) -> dict:
    """The radiation model (A_r, B_r, C_r) as independent blocks: {"blocks": [(states, inputs,
    outputs, Function (chi_b, nu_b) -> (C_b chi_b, chi_b'))], "n": states}. A block is a
    connected set of states with the inputs that drive them; blocks with equal numbers share
    one Function (named by its content). output_as_data: the Functions give chi_b' only and
    "output" holds C_r (array), applied as data (module docstring)."""
    A, B, C = (np.asarray(m, float) for m in (A, B, C))
    functions, blocks = {}, []
    for states, inputs in state_blocks(A, B):
        outputs = np.flatnonzero(np.any(C[:, states] != 0, axis=1))
        a, b, c = A[np.ix_(states, states)], B[np.ix_(states, inputs)], C[np.ix_(outputs, states)]
        numbers = (a, b) if output_as_data else (a, b, c)
        key = hashlib.sha256(b"".join(np.ascontiguousarray(m).tobytes() + str(m.shape).encode()
                                      for m in numbers)).hexdigest()[:16]
        if key not in functions:
            chi_b, nu_b = ca.SX.sym("chi", states.size), ca.SX.sym("nu", inputs.size)
            a, b, c = (ca.sparsify(ca.DM(m)) for m in (a, b, c))   # no products with zeros
            rate = ca.mtimes(a, chi_b) + ca.mtimes(b, nu_b)
            functions[key] = ca.Function(f"f_radiation_{key}", [chi_b, nu_b], [rate] if
                                         output_as_data else [ca.mtimes(c, chi_b), rate])
        blocks.append((states, inputs, outputs, functions[key]))
    out = {"blocks": blocks, "n": A.shape[0]}
    if output_as_data:
        out["output"] = C
    return out


def dense_product(matrix: np.ndarray, v):
    """matrix @ v for an MX vector v, with the matrix as data: one dot product per row over its
    nonzero columns (the whole of v where they are most of it), a row of zeros giving 0."""
    rows = []
    for row in np.asarray(matrix, float):
        columns = np.flatnonzero(row)
        if columns.size == 0:
            rows.append(ca.MX(1, 1))
        elif columns.size > row.size // 2:
            rows.append(ca.dot(ca.DM(row), v))
        else:
            rows.append(ca.dot(ca.DM(row[columns]), v[columns.tolist()]))
    return ca.vertcat(*rows)


def _radiation_by_parts(radiation, chi, nu):
    """(chi', the radiation force on the hydro DOFs) of the pieces' blocks (MX)."""
    blocks = radiation["blocks"]
    if "output" in radiation:
        rates = [block(chi[states.tolist()], nu[inputs.tolist()])
                 for states, inputs, _, block in blocks]
        forces = dense_product(radiation["output"], chi)
    else:
        pieces = [block(chi[states.tolist()], nu[inputs.tolist()])
                  for states, inputs, _, block in blocks]
        rates = [rate for _, rate in pieces]
        # the blocks' forces summed by one sparse product, rather than a write into a long
        # vector per block
        rows = np.concatenate([outputs for *_, outputs, _ in blocks])
        gather = ca.DM(ca.Sparsity.triplet(nu.shape[0], rows.size, rows.tolist(),
                                           list(range(rows.size))), 1.0)
        forces = ca.mtimes(gather, ca.vertcat(*[force for force, _ in pieces]))
    # the blocks' rates joined (reordered only if they are not in state order)
    order = np.concatenate([states for states, *_ in blocks])
    chi_dot = ca.vertcat(*rates)
    if not np.array_equal(order, np.arange(order.size)):     # blocks not in state order
        chi_dot = chi_dot[np.argsort(order).tolist()]
    return chi_dot, forces


def f_by_parts(plant, which: str = "f") -> ca.Function:
    """The plant's f (same signature and values) as an MX Function calling its pieces (module
    docstring); f itself for a plant built without them. Stepping uses it where a step calls f
    as a function (large plants). which="h": the outputs' h so (`h_by_parts`)."""
    if which == "h":
        return h_by_parts(plant)
    if plant.parts is None:
        return plant.f
    parts = plant.parts
    args = [ca.MX.sym(k, plant.f.sparsity_in(i)) for i, k in enumerate("xuwp")]
    tau = parts["loads"](*args)
    if "radiation" not in parts:
        q_dot, chi_dot = parts["rates"](*args)
    else:
        q_dot, G, nu = parts["rates"](*args)
        chi_dot, forces = _radiation_by_parts(parts["radiation"], args[0][2 * plant.n_q:], nu)
        tau = tau - ca.mtimes(G, forces)
    if "inverse_mass" in parts:
        s_dot = dense_product(parts["inverse_mass"], tau)
    else:
        s_dot = parts["solve"](parts["mass"](*args), tau)
    x_dot = ca.vertcat(q_dot, s_dot, chi_dot)
    return ca.Function("f", args, [x_dot], ["x", "u", "w", "p"], ["xdot"])


def h_by_parts(plant) -> ca.Function:
    """The plant's h (same signature and values) as an MX Function with a farm's radiation
    force C_r chi as data (module docstring); h itself for other plants."""
    parts = getattr(plant, "parts", None)
    if parts is None or "outputs" not in parts:
        return plant.h
    args = [ca.MX.sym(k, plant.h.sparsity_in(i)) for i, k in enumerate("xuwp")]
    x, n = args[0], plant.n_q
    apart = [dense_product(parts["radiation"]["output"], x[2 * n:])]
    if parts["outputs"].n_in() > 5:                   # the kinetic energy's M s
        apart.append(dense_product(parts["mass_matrix"], x[n:2 * n]))
    return ca.Function("h", args, [parts["outputs"](*args, *apart)], ["x", "u", "w", "p"], ["y"])


def distinct_radiation_functions(plant) -> int:
    """How many radiation block Functions the plant's pieces compile (0 without them)."""
    if plant.parts is None or "radiation" not in plant.parts:
        return 0
    return len({id(f) for *_, f in plant.parts["radiation"]["blocks"]})
