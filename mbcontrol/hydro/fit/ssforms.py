"""State-space forms that make simulation cheap without changing the input-output map."""
from __future__ import annotations

import numpy as np


def modal_form(A, B, C, tol: float = 1e-9):
    """Real modal (block-diagonal) realisation (A_m, B_m, C_m) of (A, B, C).

    Complex pole pairs sigma +- i w become 2x2 blocks [[sigma, w], [-w, sigma]], real poles 1x1,
    so A_m has at most two non-zeros per row and a symbolic product A_m x costs O(n). A pair's
    eigenvector phase is chosen so its real and imaginary parts are orthogonal, a double real
    eigenvalue returned as a conjugate pair is kept as a pair (its two real parts are one column),
    and each block's states are scaled so its rows of B_m and columns of C_m have equal norms.
    Without these, a 53-state fit of wavestar's data (issue 20's branch wip/issue20-band) gave a
    near-singular T, B_m of 7.5e15 and a run that "diverged" within 0.03 s.
    Raises ValueError when A is defective (not diagonalisable to working precision).
    """
    A, B, C = (np.asarray(M, dtype=float) for M in (A, B, C))
    if A.size == 0:
        return A, B, C
    eigvals, vecs = np.linalg.eig(A)
    if np.linalg.cond(vecs) > 1e10:
        raise ValueError("modal_form: state matrix is (nearly) defective; keep the original form")
    columns, blocks, used = [], [], np.zeros(eigvals.size, bool)
    for i in np.argsort(eigvals.real, kind="stable"):
        if used[i]:
            continue
        lam, v = eigvals[i], vecs[:, i]
        used[i] = True
        # real: a real eigenvalue with a real eigenvector. A double real eigenvalue can come back
        # as a conjugate pair with a complex eigenvector: the real parts of the two are then the
        # same column; [Re v, Im v] below spans the pair
        if abs(lam.imag) <= tol * max(1.0, abs(lam)) and np.linalg.norm(v.imag) <= tol * np.linalg.norm(v):
            columns.append(v.real / np.linalg.norm(v.real))
            blocks.append(np.array([[lam.real]]))
            continue
        # the conjugate partner: mark it used; the pair spans [Re v, Im v]
        partner = np.argmin(np.abs(eigvals - lam.conjugate()) + used * 1e300)
        used[partner] = True
        if lam.imag < 0:
            lam, v = lam.conjugate(), v.conjugate()
        # any phase e^{iθ} v is an eigenvector: take the one with Re v ⟂ Im v, else
        # [Re v, Im v] can be nearly parallel and T near-singular
        a, b = v.real, v.imag
        v = v * np.exp(-0.5j * np.arctan2(2 * a @ b, a @ a - b @ b))
        columns += [v.real, v.imag]
        blocks.append(np.array([[lam.real, lam.imag], [-lam.imag, lam.real]]))
    T = np.column_stack(columns)
    A_m = _block_diag(blocks)
    B_m = np.linalg.solve(T, B)
    C_m = C @ T
    i = 0
    for b in blocks:
        k = slice(i, i + b.shape[0])
        nb, nc = np.linalg.norm(B_m[k]), np.linalg.norm(C_m[:, k])
        if nb > 0 and nc > 0:
            B_m[k], C_m[:, k] = B_m[k] * np.sqrt(nc / nb), C_m[:, k] * np.sqrt(nb / nc)
        i += b.shape[0]
    return A_m, B_m, C_m


def _block_diag(blocks):
    n = sum(b.shape[0] for b in blocks)
    out = np.zeros((n, n))
    i = 0
    for b in blocks:
        k = b.shape[0]
        out[i:i + k, i:i + k] = b
        i += k
    return out


def state_blocks(A, B) -> list[tuple[np.ndarray, np.ndarray]]:
    """[(states, inputs)]: the sets of states that A and B connect, each with the inputs that
    drive it (a decoupled DOF group of a fit, or a column of a column fit), in order of their
    first state."""
    from scipy.sparse.csgraph import connected_components
    A, B = np.asarray(A), np.asarray(B)
    n = A.shape[0]
    graph = np.zeros((n + B.shape[1],) * 2, bool)          # states, then inputs, as one graph
    graph[:n, :n], graph[:n, n:] = A != 0, B != 0
    _, label = connected_components(graph, directed=False)
    out = []
    for k in dict.fromkeys(label[:n]):                      # first-seen order
        members = np.flatnonzero(label == k)
        out.append((members[members < n], members[members >= n] - n))
    return out


def modal_blocks(A, B, C):
    """modal_form block by block: each set of states that A and B connect (a decoupled DOF
    group) on its own, in place. Identical groups (identical bodies sharing a fit) then get
    identical realisations, and repeated poles of different groups cannot mix them (the
    whole matrix's eigenvectors within a repeated eigenvalue are any basis of its eigenspace).
    A block that modal_form refuses (defective) is kept as it is."""
    A, B, C = (np.array(M, dtype=float) for M in (A, B, C))
    for s, _ in state_blocks(A, B):
        try:
            a, b, c = modal_form(A[np.ix_(s, s)], B[s], C[:, s])
        except ValueError:
            continue
        A[np.ix_(s, s)], B[s], C[:, s] = a, b, c
    return A, B, C
