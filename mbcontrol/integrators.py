"""Time-stepping of a ProcessPlant: compiled fixed-step RK4 and CVODES (BDF, adaptive).

RK4 takes the excitation at the start, middle and end of each step (sampled on a half-step
grid), so a step is exact to O(h^4) for smooth excitation. Steps are chained by CasADi's
mapaccum into chunks compiled to native code: a chunk of thousands of steps is one C call.
"""
from __future__ import annotations

import hashlib

import casadi as ca
import numpy as np

from .compiled import compile_function

CHUNK = 512         # steps per compiled call: long enough that Python overhead vanishes


def rk4_step(plant, law=None) -> ca.Function:
    """One RK4 step (x, u, w3, p, h) -> x_next; w3 = [w(t), w(t+h/2), w(t+h)] (n_w x 3).

    With `law` (a CasADi Function y -> u), u is computed from the outputs at the start of the
    step and held over it (zero-order hold at the step), replacing the u input.
    """
    nx, nu, nw, npar = plant.nx, len(plant.inputs), len(plant.disturbances), len(plant.p0)
    x, u = ca.SX.sym("x", nx), ca.SX.sym("u", nu)
    w3, p, h = ca.SX.sym("w3", nw, 3), ca.SX.sym("p", npar), ca.SX.sym("h")
    if law is not None:
        u_held = law(plant.h(x, ca.DM.zeros(nu), w3[:, 0], p))
    else:
        u_held = u
    k1 = plant.f(x, u_held, w3[:, 0], p)
    k2 = plant.f(x + h / 2 * k1, u_held, w3[:, 1], p)
    k3 = plant.f(x + h / 2 * k2, u_held, w3[:, 1], p)
    k4 = plant.f(x + h * k3, u_held, w3[:, 2], p)
    x_next = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return ca.Function("rk4_step", [x, u, w3, p, h], [x_next, u_held],
                       ["x", "u", "w3", "p", "h"], ["x_next", "u_applied"])


_CHUNKS: dict = {}


def chunk_length(n: int) -> int:
    """Steps per compiled call: CHUNK, or the next power of two for short runs (few variants
    to compile, little padding)."""
    return CHUNK if n >= CHUNK else 1 << max(0, int(n - 1).bit_length())


def _chunk_function(plant, law, compiled: bool, length: int) -> ca.Function:
    """The compiled chunk of `length` steps of a plant (and law), built once per process."""
    # a law is keyed by its content: controllers rebuild it on reset, code need not recompile
    law_key = None if law is None else hashlib.sha256(law.serialize().encode()).hexdigest()
    key = (id(plant), law_key, compiled, length)
    if key not in _CHUNKS:
        step = rk4_step(plant, law)
        # mapaccum feeds x_next back as x; the other inputs are given per step (or broadcast)
        steps = step.mapaccum("rk4_steps", length, ["x"], ["x_next"])
        # parameters and step size are shared by all steps: repeat them inside the function
        # so that callers pass them once (the zero-copy buffer interface needs full inputs)
        x, U = ca.MX.sym("x", plant.nx), ca.MX.sym("U", len(plant.inputs), length)
        W = ca.MX.sym("W", len(plant.disturbances), 3 * length)
        p, h = ca.MX.sym("p", len(plant.p0)), ca.MX.sym("h")
        X, U_applied = steps(x, U, W, ca.repmat(p, 1, length), ca.repmat(h, 1, length))
        chunk = ca.Function("rk4_chunk", [x, U, W, p, h], [X, U_applied])
        # keep the plant alive so that its id stays unique while cached
        _CHUNKS[key] = (compile_function(chunk, enabled=compiled), plant)
    return _CHUNKS[key][0]


def prepare_rk4(plant, n: int, law=None, compiled=True) -> None:
    """Build and compile what run_rk4 will need for n steps (so timings exclude it)."""
    _chunk_function(plant, law, compiled, chunk_length(n))


def run_rk4(plant, x0, U, W_half, p, dt, law=None, compiled=True, on_chunk=None):
    """Integrate n steps; returns states (n+1, nx) and the inputs actually applied (n, nu).

    U: (n, nu) inputs held over each step (ignored with a law); W_half: (2n+1, nw) excitation
    on the half-step grid. `on_chunk(i_end, X)` is called after each chunk (progress, checks)
    and may raise to stop.
    """
    n, nu, nx = U.shape[0], len(plant.inputs), plant.nx
    length = chunk_length(n)
    chunk = _chunk_function(plant, law, compiled, length)
    # CasADi matrices are column-major, so a C-ordered (steps, ...) block is exactly the
    # (..., steps) matrix a mapaccum input or output expects: no copies on the hot path.
    W3 = np.ascontiguousarray(np.stack([W_half[0:-1:2], W_half[1::2], W_half[2::2]], axis=1))
    U = np.ascontiguousarray(U, dtype=float)
    X = np.empty((n + 1, nx))
    U_applied = np.empty((n, nu))
    X[0] = x0
    p = np.ascontiguousarray(p, dtype=float)
    h = np.array([dt], dtype=float)
    buffer, _ = chunk.buffer()
    buffer.set_arg(3, memoryview(p))
    buffer.set_arg(4, memoryview(h))
    for start in range(0, n, length):
        stop = min(start + length, n)
        if stop - start == length:
            x_in, U_c, W_c = X[start], U[start:stop], W3[start:stop]
            X_out, U_out = X[start + 1:stop + 1], U_applied[start:stop]
        else:                               # a short last chunk: pad, then copy back
            m = stop - start
            x_in = X[start].copy()
            U_c = np.zeros((length, nu))
            U_c[:m] = U[start:stop]
            W_c = np.zeros((length,) + W3.shape[1:])
            W_c[:m] = W3[start:stop]
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
    return X, U_applied


_OUTPUT_MAPS: dict = {}


def outputs(plant, X, U, W, p, compiled=True) -> np.ndarray:
    """Plant outputs y_i = h(x_i, u_i, w_i, p) for every row, in compiled chunks (bounded memory).

    X (n, nx), U (n, nu), W (n, nw); returns (n, ny).
    """
    n = X.shape[0]
    length = chunk_length(n)
    key = (id(plant), compiled, length)
    if key not in _OUTPUT_MAPS:
        x, u = ca.MX.sym("x", plant.nx, length), ca.MX.sym("u", len(plant.inputs), length)
        w, p_sym = ca.MX.sym("w", len(plant.disturbances), length), ca.MX.sym("p", len(plant.p0))
        y = plant.h.map(length)(x, u, w, ca.repmat(p_sym, 1, length))
        fun = ca.Function("outputs_chunk", [x, u, w, p_sym], [y])
        _OUTPUT_MAPS[key] = (compile_function(fun, enabled=compiled), plant)
    fun = _OUTPUT_MAPS[key][0]
    Y = np.empty((n, len(plant.outputs)))
    buffer, _ = fun.buffer()
    p = np.ascontiguousarray(p, dtype=float)
    buffer.set_arg(3, memoryview(p))
    for start in range(0, n, length):
        stop = min(start + length, n)
        blocks = [np.zeros((length, a.shape[1])) for a in (X, U, W)]
        for block, a in zip(blocks, (X, U, W)):
            block[:stop - start] = a[start:stop]
        out = np.empty((length, len(plant.outputs)))
        for i, block in enumerate(blocks):
            buffer.set_arg(i, memoryview(block))
        buffer.set_res(0, memoryview(out))
        buffer._eval()
        Y[start:stop] = out[:stop - start]
    return Y


def cvodes_integrator(plant, wave_terms, t_grid, rtol=1e-8, atol=1e-10) -> ca.Function:
    """CVODES over t_grid with the excitation an explicit function of time.

    wave_terms = (omega (m,), Fc (nw, m), Fs (nw, m), ramp_time): w(t) = ramp(t) *
    (Fc cos(omega t) + Fs sin(omega t)); parameters of the integrator: [u; p].
    """
    omega, Fc, Fs, ramp_time = wave_terms
    nu, npar = len(plant.inputs), len(plant.p0)
    x, t = ca.SX.sym("x", plant.nx), ca.SX.sym("t")
    up = ca.SX.sym("up", nu + npar)
    w = ca.mtimes(ca.DM(Fc), ca.cos(ca.DM(omega) * t)) + ca.mtimes(ca.DM(Fs),
                                                                  ca.sin(ca.DM(omega) * t))
    if ramp_time > 0:
        w *= ca.if_else(t < ramp_time, 0.5 * (1 - ca.cos(np.pi * t / ramp_time)), 1.0)
    ode = plant.f(x, up[:nu], w, up[nu:])
    dae = {"x": x, "t": t, "p": up, "ode": ode}
    opts = {"reltol": rtol, "abstol": atol, "max_num_steps": 200000}
    return ca.integrator("cvodes", "cvodes", dae, float(t_grid[0]), list(t_grid[1:]), opts)


def wave_terms(plant, wave):
    """(omega, Fc, Fs, ramp) of the excitation: Re(a F e^{-i(wt+phi)}) = Fc cos wt + Fs sin wt."""
    from .waves import interpolate_complex
    coeffs = interpolate_complex(plant.hydro.omega, plant.hydro.excitation_coefficients(
        wave.direction), wave.omega)                                      # (m, nw)
    c = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs
    return wave.omega, c.real.T, c.imag.T, wave.ramp_time
