"""Linear time-invariant building blocks every stage shares: the frequency response of a
state-space model and its exact zero-order-hold discretisation. A common module (numpy and
scipy only), so the plant, the simulator, the analysis and the controllers use one each.

Phasors exp(+i omega t), python-control's convention: with u = Re(U e^{i omega t}) the
steady state is x = Re(X e^{i omega t}), X = (i omega I - A)^-1 B U, and the response is
G(i omega) = C (i omega I - A)^-1 B + D. Frequencies omega in rad/s.
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


def state_response(A, B, omega) -> np.ndarray:
    """X = (i omega I - A)^-1 B at each omega: (n_omega, n_states, n_inputs), complex."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B).reshape(A.shape[0], -1)
    omega = np.atleast_1d(np.asarray(omega, float))
    eye = np.eye(A.shape[0])
    X = np.empty((omega.size, A.shape[0], B.shape[1]), complex)
    for k in frequency_chunks(omega.size, A.shape[0]):
        X[k] = np.linalg.solve(1j * omega[k, None, None] * eye - A, B)
    return X


def frequency_response(A, B, C, D=None, omega=()) -> np.ndarray:
    """G(i omega) = C (i omega I - A)^-1 B + D at each omega: (n_omega, n_outputs, n_inputs),
    complex, in units of output per input. D None: no feedthrough. Solved a slice of
    frequencies at a time, so only G is kept whatever the number of states."""
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
    return G


def zoh(A, B, period: float) -> tuple[np.ndarray, np.ndarray]:
    """(Phi, Gamma): the exact zero-order-hold discretisation of x' = A x + B u over `period`
    s, Phi = e^{A T} and Gamma = int_0^T e^{A s} ds B, from the exponential of the augmented
    matrix [[A, B], [0, 0]] (Van Loan)."""
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(len(A), -1)
    n, m = A.shape[0], B.shape[1]
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A, B
    E = scipy.linalg.expm(M * period)
    return E[:n, :n], E[:n, n:]
