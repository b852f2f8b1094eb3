"""Linear time-invariant building blocks every stage shares: the frequency response of a
state-space model and its exact zero-order-hold discretisation. A common module (numpy and
scipy only), so the plant, the simulator, the analysis and the controllers use one each.

Phasors exp(+i omega t), python-control's convention and the toolbox's public one (see
notebooks/guide.md, "Conventions"): with u = Re(U e^{i omega t}) the steady state is
x = Re(X e^{i omega t}), X = (i omega I - A)^-1 B U, and the response is
G(i omega) = C (i omega I - A)^-1 B + D. Frequencies omega in rad/s. Responses are stacked as
python-control's (outputs, inputs, omega). The hydro data keep Capytaine's exp(-i omega t) on
disk; `phasor` converts them, once, at the hydro boundary.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg


def frequency_chunks(n_omega: int, n: int, budget: int = 1 << 19):
    """Slices of the frequencies whose n x n complex matrices fill about 8 MB: a stacked
    solve per slice, rather than a Python loop of small solves or one huge stack (a loop of
    rm3's 40 x 40 solves cost a sweep's uncertainty budget 5 s over 92 seas; one stack of
    raft3's 275 x 275 is 240 MB)."""
    step = max(1, budget // (n * n))
    return [slice(k, k + step) for k in range(0, max(n_omega, 1), step)]   # one if empty


def phasor(stored) -> np.ndarray:
    """The exp(+i omega t) phasor of complex amplitudes stored in exp(-i omega t) (the BEM
    data's, Capytaine's, and a wave component's a e^{-i phi}): y(t) = Re[Y- e^{-i omega t}]
    = Re[conj(Y-) e^{+i omega t}], so the complex conjugate (exact in floating point)."""
    return np.conj(stored)


def state_response(A, B, omega) -> np.ndarray:
    """X = (i omega I - A)^-1 B at each omega: (n_states, n_inputs, n_omega), complex (the
    axis order of python-control's frequency responses)."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B).reshape(A.shape[0], -1)
    omega = np.atleast_1d(np.asarray(omega, float))
    eye = np.eye(A.shape[0])
    X = np.empty((omega.size, A.shape[0], B.shape[1]), complex)
    for k in frequency_chunks(omega.size, A.shape[0]):
        X[k] = np.linalg.solve(1j * omega[k, None, None] * eye - A, B)
    return np.moveaxis(X, 0, -1)


def frequency_response(A, B, C, D=None, omega=()) -> np.ndarray:
    """G(i omega) = C (i omega I - A)^-1 B + D at each omega: (n_outputs, n_inputs, n_omega),
    complex, in units of output per input: python-control's axis order (its
    `FrequencyResponseData.fresp`, `ss(...)(1j * omega)`). D None: no feedthrough. Solved a
    slice of frequencies at a time, so only G is kept whatever the number of states."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B).reshape(A.shape[0], -1)
    C = np.asarray(C).reshape(-1, A.shape[0])
    omega = np.atleast_1d(np.asarray(omega, float))
    eye = np.eye(A.shape[0])
    G = np.empty((omega.size, C.shape[0], B.shape[1]), complex)
    for k in frequency_chunks(omega.size, A.shape[0]):
        G[k] = C @ np.linalg.solve(1j * omega[k, None, None] * eye - A, B)
    if D is not None:
        G += np.asarray(D).reshape(C.shape[0], B.shape[1])
    return np.moveaxis(G, 0, -1)


def zoh(A, B, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(Phi, Gamma): the exact zero-order-hold discretisation of x' = A x + B u over a hold
    of dt s (python-control's name for a sampling period), Phi = e^{A dt} and
    Gamma = int_0^dt e^{A s} ds B, from the exponential of the augmented
    matrix [[A, B], [0, 0]] (Van Loan)."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(len(A), -1)
    n, m = A.shape[0], B.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = scipy.linalg.expm(M * dt)
    return E[:n, :n], E[:n, n:]
