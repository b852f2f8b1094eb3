"""Time-stepping methods for a ProcessPlant, selectable by name (`METHODS`).

Fixed-step methods run as compiled native code: steps are chained by CasADi's mapaccum into
chunks of thousands of steps, one C call each, with no Python on the hot path.

  rk4      classic Runge-Kutta, order 4 (the default)
  rk3      Kutta's third-order method (a lower-order point for work-precision charts)
  dopri5   Dormand-Prince 5th-order weights as a fixed-step method, 6 stages
  exp-rk4  Lawson (integrating-factor) RK4: the linear radiation states are advanced
           exactly, by exp(A_r tau) (a zero-order-hold-exact treatment of chi' = A_r chi),
           the rigid-body part by RK4. Fast radiation poles then no longer limit the step.
  cvodes   adaptive BDF with the exact Jacobian (implicit, for stiff cases); see simulate.py
  adams    adaptive Adams-Moulton (CVODES, functional iteration: non-stiff, high order)

The excitation is sampled at each method's stage times (`nodes`, fractions of the step), so a
step sees w exactly where its stages need it; the phase of the sea is exact at every node.
"""
from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from ..errors import InputError
from ..plant import derived, f_by_parts, stage_load
from .compiled import compile_function
from .methods import METHODS, method, radiation_exponential, radiation_split
from .protocol import parametric_law

CHUNK = 512         # steps per compiled call: long enough that Python overhead vanishes
# Above CALL_F_STATES a step calls the plant's f as one function (MX) instead of inlining its
# expression at every stage (SX), so the generated C holds f once, not four times. Measured on
# this machine (first use with the compile; a 300 s regular-wave run at dt 0.01 s once compiled):
# array4 (80 states) 6.2 s -> 1.2 s, run 0.34 s -> 0.37 s; flap_pair (92) 3.8 s -> 1.5 s, run
# 0.50 s -> 0.29 s; array_grid's 16 floats (776) compile 286 s -> 7 s. Below it the inlined step
# is the faster (hinged_barge, 49: run 0.19 s against 0.23 s) and its compile short. Same end
# states to round-off.
CALL_F_STATES = 64
# Above this many states (a farm: the radiation model's constants dominate) the output map,
# evaluated once per sample, is compiled unoptimised (sim.compiled.PLAIN_FLAGS): array_grid's
# output map 12 s -> 0.8 s. A farm whose outputs are in parts (plant.pieces.h_by_parts: C_r and
# M as data, code growing as N) is optimised: 49 floats 1.5 s and 0.17 s per 6,000 samples,
# against 5.2 s and 1.6 s for the unrolled h unoptimised (0.8 s and 2.8 s for the parts so).
PLAIN_OUTPUTS_STATES = 200


# --- one step -------------------------------------------------------------------------------

def calls_f(plant) -> bool:
    """Whether a step calls f rather than inlining it: a large plant. (A panel surface's
    wrench is already one call node inside f: mbcontrol.hydro.mesh.surface_sums.)"""
    return plant.nx > CALL_F_STATES


def _symbols(plant, n_nodes, n_theta: int = 0):
    nx, nu, nw, npar = plant.nx, len(plant.inputs), len(plant.disturbances), len(plant.p0)
    sym = ca.MX.sym if calls_f(plant) else ca.SX.sym
    return (sym("x", nx), sym("u", nu), sym("W", nw, n_nodes), sym("p", npar + n_theta),
            sym("h"))


def law_parameters(law) -> int:
    """How many gains a law takes besides the outputs: a Function (y, theta) -> u keeps its
    gains theta symbolic, so that compiled code does not depend on their values (they ride
    at the end of the parameter vector p); a Function y -> u has none."""
    return 0 if law is None or law.n_in() == 1 else int(law.sparsity_in(1).numel())


def embedded_law(controller, plant):
    """(law, gains): the controller's law with its gains as parameters (casadi_law_parametric:
    a Function (y, theta) -> u and theta's values) where it offers one, else its plain
    casadi_law (gains None); (None, None) without a controller."""
    if controller is None:
        return None, None
    parametric = parametric_law(controller)
    if parametric is not None:
        law, gains = parametric(plant)
        return law, np.asarray(gains, float)
    return controller.casadi_law(plant), None


def _held_input(plant, law, x, u, W, p):
    """With `law` (a CasADi Function y -> u, or (y, theta) -> u with theta the end of p), u
    comes from the outputs at the start of the step and is held over it (zero-order hold at
    the step); otherwise the u input is used."""
    if law is None:
        return u
    n = len(plant.p0)
    h = f_by_parts(plant, "h") if isinstance(x, ca.MX) else plant.h    # a farm's: C_r as data
    y = h(x, ca.DM.zeros(len(plant.inputs)), W[:, 0], p[:n])
    return law(y) if law.n_in() == 1 else law(y, p[n:])


def _stage_function(plant, x, u, W, p, column):
    """f(xs, c): the plant's x' at a stage state xs and node c of the step from x. With
    [hydro] nonlinear_update = "step" the pressure load is evaluated once, at the step's start,
    and moved to the other stages by its rest increments (module plant.held_pressure)."""
    held = getattr(plant, "held", None)     # a ProcessPlant's, else none
    if held is not None:
        n_q = plant.n_q
        load0 = held.load(x[:n_q], W[:, 0])
        return lambda xs, c: held.f(xs, u, W[:, column[c]], p, stage_load(
            held, x[:n_q], W[:, 0], load0, xs[:n_q], W[:, column[c]]))
    # MX symbols (a large plant): f is called, not inlined, and called in its parts, so that
    # gcc compiles four moderate functions instead of one long one (module plant.pieces)
    plant_f = f_by_parts(plant) if isinstance(x, ca.MX) else plant.f
    return lambda xs, c: plant_f(xs, u, W[:, column[c]], p)


def step_function(plant, method_name: str = "rk4", law=None) -> ca.Function:
    """One fixed step (x, u, W, p, h, *extras) -> (x_next, u_applied).

    W (n_w x len(nodes)) is the excitation at t + c h for each node c of the method; extras
    are the method's step-size-dependent matrices (`step_extras`), inputs so that compiled
    code depends on the plant's structure, not on h.
    """
    m = method(method_name)
    if not m.fixed_step:
        raise InputError(f"{method_name!r} is adaptive: it has no fixed step")
    tab = m.tableau
    x, u, W, p, h = _symbols(plant, len(tab.nodes), law_parameters(law))
    u_held = _held_input(plant, law, x, u, W, p)
    column = {c: i for i, c in enumerate(tab.nodes)}
    p_plant = p[:len(plant.p0)]
    f = _stage_function(plant, x, u_held, W, p_plant, column)

    if m.kind == "explicit":
        k, zero = [], type(x)(0)
        for a_j, c_j in zip(tab.a, tab.c):
            k.append(f(x + h * sum((a * ki for a, ki in zip(a_j, k) if a != 0), zero), c_j))
        x_next = x + h * sum((b * kj for b, kj in zip(tab.b, k) if b != 0), zero)
        extras = []
    else:                                    # Lawson RK4 on x' = L x + N(x), L = diag(0, A_r)
        start, A, sparsity, _ = radiation_split(plant)
        E_half, E_full = type(x).sym("E_half", sparsity), type(x).sym("E_full", sparsity)
        extras = [E_half, E_full]

        def E(M, v):                         # exp(L tau) v: identity on q and s
            return ca.vertcat(v[:start], ca.mtimes(M, v[start:]))

        lin = ca.DM(A)

        def N(xs, c):
            fx = f(xs, c)
            return ca.vertcat(fx[:start], fx[start:] - ca.mtimes(lin, xs[start:]))

        k1 = N(x, 0.0)
        k2 = N(E(E_half, x + h / 2 * k1), 0.5)
        k3 = N(E(E_half, x) + h / 2 * k2, 0.5)
        k4 = N(E(E_full, x) + h * E(E_half, k3), 1.0)
        x_next = E(E_full, x) + h / 6 * (E(E_full, k1) + 2 * E(E_half, k2 + k3) + k4)
    return ca.Function(f"{m.name.replace('-', '_')}_step", [x, u, W, p, h, *extras],
                       [x_next, u_held])


def rk4_step(plant, law=None) -> ca.Function:
    """One RK4 step (x, u, w3, p, h) -> (x_next, u_applied); w3 = w at t, t + h/2, t + h."""
    return step_function(plant, "rk4", law)


def step_extras(plant, method_name: str, dt: float) -> list[np.ndarray]:
    """The numeric values of a method's extra step inputs at step dt (nonzeros, column-major)."""
    if METHODS[method_name].kind != "exponential":
        return []
    _, A, sparsity, labels = radiation_split(plant)
    out = []
    for tau in (dt / 2, dt):
        E = radiation_exponential(A, labels, tau)
        rows, cols = sparsity.get_triplet()
        out.append(np.ascontiguousarray(E[rows, cols]))   # nonzeros, column-major order
    return out


# --- chunks of steps, compiled --------------------------------------------------------------

def chunk_length(n: int) -> int:
    """Steps per compiled call: CHUNK, or the next power of two for short runs (few variants
    to compile, little padding)."""
    return CHUNK if n >= CHUNK else 1 << max(0, int(n - 1).bit_length())


def chunk_symbolic(plant, method_name, law, length: int) -> ca.Function:
    """`length` steps as one Function (x, U, W, p, h, *extras) -> (X, U_applied), not compiled.

    U (nu x length), W (nw x nodes*length), X (nx x length): step k's columns are k, or
    k*nodes .. k*nodes + nodes - 1; p (the plant's parameters, then a law's gains: see
    law_parameters), h and extras are shared by all steps.
    """
    step = step_function(plant, method_name, law)
    # mapaccum feeds x_next back as x; the other inputs are given per step (or broadcast)
    steps = step.mapaccum("steps", length, [0], [0])
    n_nodes = len(METHODS[method_name].nodes)
    x, U = ca.MX.sym("x", plant.nx), ca.MX.sym("U", len(plant.inputs), length)
    W = ca.MX.sym("W", len(plant.disturbances), n_nodes * length)
    p, h = ca.MX.sym("p", step.sparsity_in(3).numel()), ca.MX.sym("h")
    # repeated inside the function so that callers pass them once (the zero-copy buffer
    # interface needs full inputs)
    extras = [ca.MX.sym(f"e{i}", step.sparsity_in(5 + i)) for i in range(step.n_in() - 5)]
    X, U_applied = steps(x, U, W, ca.repmat(p, 1, length), ca.repmat(h, 1, length),
                         *[ca.repmat(e, 1, length) for e in extras])
    return ca.Function("chunk", [x, U, W, p, h, *extras], [X, U_applied])


def law_key(law):
    """A law is keyed by its content: controllers rebuild it on reset, code need not
    recompile."""
    return None if law is None else hashlib.sha256(law.serialize().encode()).hexdigest()


def _chunk_function(plant, method_name, law, compiled: bool, length: int) -> ca.Function:
    """The compiled chunk of `length` steps of a plant (and law), built once per plant."""
    label = (f"{plant.name}: {length} {method_name} steps per call"
             + (f", {law.name()} in the loop" if law is not None else ""))
    return derived(plant, ("sim.chunk", method_name, law_key(law), compiled, length),
                   lambda: compile_function(chunk_symbolic(plant, method_name, law, length),
                                            enabled=compiled, label=label))


def prepare(plant, n: int, method_name: str = "rk4", law=None, compiled=True) -> None:
    """Build and compile what run_fixed_step will need for n steps (so timings exclude it)."""
    _chunk_function(plant, method_name, law, compiled, chunk_length(n))


def excitation_at_nodes(plant, wave, n: int, dt: float, nodes) -> np.ndarray:
    """Excitation (n, len(nodes), n_w) at t_i + c dt for every step i and node c."""
    from ..errors import HydroError, WaveError
    from ..waves import coefficient_offsets, excitation_at_offsets
    nw = len(plant.disturbances)
    if wave is None or nw == 0:
        return np.zeros((n, len(nodes), nw))
    try:
        if plant.wave_rows:             # nonlinear Froude-Krylov: the field's rows too
            return coefficient_offsets(wave, plant.wave_coefficients(wave), n, dt, nodes)
        if wave.directional:            # a spread sea: each component's own direction
            coeffs = plant.hydro.excitation_at(wave.omega, wave.direction)
            return plant.padded(coefficient_offsets(wave, coeffs, n, dt, nodes))
        # the data's coefficients: selected once per plant and direction
        coeffs = derived(plant, ("sim.excitation_coefficients", wave.direction),
                         lambda: plant.hydro.excitation_coefficients(wave.direction))
        return plant.padded(excitation_at_offsets(wave, plant.hydro.omega, coeffs, n, dt,
                                                  nodes))
    except (HydroError, WaveError):
        raise
    except ValueError as exc:
        raise HydroError(f"{plant.hydro.source}: {exc}") from None


def run_fixed_step(plant, x0, U, W_nodes, p, dt, method_name="rk4", law=None, compiled=True,
                   *, on_chunk=None, alongside=None):
    """Integrate n steps; returns states (n+1, nx) and the inputs actually applied (n, nu).

    U: (n, nu) inputs held over each step (ignored with a law); W_nodes: (n, n_nodes, nw)
    excitation at the method's nodes. `on_chunk(i_end, X)` is called after each chunk
    (progress, checks) and may raise to stop; then `alongside.advance` (sim.alongside: the
    outputs of the finished steps, on a second core).
    """
    n, nu, nx = U.shape[0], len(plant.inputs), plant.nx
    length = chunk_length(n)
    chunk = _chunk_function(plant, method_name, law, compiled, length)
    # CasADi matrices are column-major, so a C-ordered (steps, nodes, nw) block is exactly the
    # (nw, nodes * steps) matrix the chunk expects: no copies on the hot path.
    W_nodes = np.ascontiguousarray(W_nodes, dtype=float)
    U = np.ascontiguousarray(U, dtype=float)
    X = np.empty((n + 1, nx))
    U_applied = np.empty((n, nu))
    X[0] = x0
    p = np.ascontiguousarray(p, dtype=float)
    h = np.array([dt], dtype=float)
    extras = step_extras(plant, method_name, dt)
    buffer, _ = chunk.buffer()
    buffer.set_arg(3, memoryview(p))
    buffer.set_arg(4, memoryview(h))
    for i, e in enumerate(extras):
        buffer.set_arg(5 + i, memoryview(e))
    for start in range(0, n, length):
        stop = min(start + length, n)
        if stop - start == length:
            x_in, U_c, W_c = X[start], U[start:stop], W_nodes[start:stop]
            X_out, U_out = X[start + 1:stop + 1], U_applied[start:stop]
        else:                               # a short last chunk: pad, then copy back
            m = stop - start
            x_in = X[start].copy()
            U_c = np.zeros((length, nu))
            U_c[:m] = U[start:stop]
            W_c = np.zeros((length,) + W_nodes.shape[1:])
            W_c[:m] = W_nodes[start:stop]
            X_out, U_out = np.empty((length, nx)), np.empty((length, nu))
        x_in = np.ascontiguousarray(x_in)
        buffer.set_arg(0, memoryview(x_in))
        buffer.set_arg(1, memoryview(U_c))
        buffer.set_arg(2, memoryview(W_c))
        buffer.set_res(0, memoryview(X_out))
        buffer.set_res(1, memoryview(U_out))
        buffer._eval()
        if stop - start != length:
            X[start + 1:stop + 1], U_applied[start:stop] = X_out[:m], U_out[:m]
        if on_chunk is not None:
            on_chunk(stop, X[:stop + 1])
        if alongside is not None:
            alongside.advance(stop, X, U_applied, W_nodes[:, 0])
    return X, U_applied


def outputs(plant, X, U, W, p, compiled=True) -> np.ndarray:
    """Plant outputs y_i = h(x_i, u_i, w_i, p) for every row, in compiled chunks (bounded memory).

    X (n, nx), U (n, nu), W (n, nw); returns (n, ny). (sim.alongside evaluates the same blocks
    on a second core while a run steps.)
    """
    n = X.shape[0]
    length = chunk_length(n)
    buffer, _ = output_function(plant, compiled, length).buffer()
    p = np.ascontiguousarray(p, dtype=float)
    Y = np.empty((n, len(plant.outputs)))
    for start in range(0, n, length):
        stop = min(start + length, n)
        output_block(buffer, p, X[start:stop], U[start:stop], W[start:stop], Y[start:stop],
                     length)
    return Y


def output_function(plant, compiled: bool, length: int) -> ca.Function:
    """The compiled map of h over `length` samples (x, u, w columns; p shared), built once."""
    return derived(plant, ("sim.outputs", compiled, length),
                   lambda: _output_map(plant, compiled, length))


def output_block(buffer, p, X, U, W, Y, length: int) -> None:
    """Y[:] = h over the rows of X, U, W (at most `length`), through a FunctionBuffer of
    output_function(..., length): the rows padded to the map's length."""
    rows = X.shape[0]
    blocks = [np.zeros((length, a.shape[1])) for a in (X, U, W)]
    for block, a in zip(blocks, (X, U, W)):
        block[:rows] = a
    out = np.empty((length, Y.shape[1]))
    for i, block in enumerate(blocks):
        buffer.set_arg(i, memoryview(block))
    buffer.set_arg(3, memoryview(p))
    buffer.set_res(0, memoryview(out))
    buffer._eval()
    Y[:] = out[:rows]


def _output_map(plant, compiled: bool, length: int) -> ca.Function:
    x, u = ca.MX.sym("x", plant.nx, length), ca.MX.sym("u", len(plant.inputs), length)
    w, p_sym = ca.MX.sym("w", len(plant.disturbances), length), ca.MX.sym("p", len(plant.p0))
    h = f_by_parts(plant, "h") if calls_f(plant) else plant.h
    y = h.map(length)(x, u, w, ca.repmat(p_sym, 1, length))
    fun = ca.Function("outputs_chunk", [x, u, w, p_sym], [y])
    # a farm's h in parts is short code over its radiation data: optimised
    optimise = (plant.nx <= PLAIN_OUTPUTS_STATES and not calls_f(plant)) or h is not plant.h
    return compile_function(fun, enabled=compiled, optimise=optimise)


def cvodes_integrator(plant, wave_terms, t_grid, rtol=1e-8, atol=1e-10,
                      lmm: str = "bdf") -> ca.Function:
    """CVODES over t_grid with the excitation an explicit function of time.

    wave_terms = (omega (m,), Fc (nw, m), Fs (nw, m), ramp_time): w(t) = ramp(t) *
    (Fc cos(omega t) + Fs sin(omega t)); parameters of the integrator: [u; p]. lmm "bdf"
    (Newton iteration with the exact Jacobian) or "adams" (functional iteration).
    """
    omega, Fc, Fs, ramp_time = wave_terms
    nu = len(plant.inputs)
    x, t = ca.SX.sym("x", plant.nx), ca.SX.sym("t")
    up = ca.SX.sym("up", nu + len(plant.p0))
    w = ca.mtimes(ca.DM(Fc), ca.cos(ca.DM(omega) * t)) + ca.mtimes(ca.DM(Fs),
                                                                  ca.sin(ca.DM(omega) * t))
    if ramp_time > 0:
        w *= ca.if_else(t < ramp_time, 0.5 * (1 - ca.cos(np.pi * t / ramp_time)), 1.0)
    ode = plant.f(x, up[:nu], w, up[nu:])
    dae = {"x": x, "t": t, "p": up, "ode": ode}
    opts = {"reltol": rtol, "abstol": atol, "max_num_steps": 200000,
            "linear_multistep_method": lmm,
            "nonlinear_solver_iteration": "newton" if lmm == "bdf" else "functional"}
    return ca.integrator("cvodes", "cvodes", dae, float(t_grid[0]), list(t_grid[1:]), opts)


def wave_terms(plant, wave):
    """(omega, Fc, Fs, ramp) of the excitation: Re(a F e^{-i(wt+phi)}) = Fc cos wt + Fs sin wt."""
    coeffs = plant.wave_coefficients(wave)                                # (m, nw)
    c = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs
    return wave.omega, c.real.T, c.imag.T, wave.ramp_time
