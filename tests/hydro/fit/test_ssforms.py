"""Real modal form (hydro.ssforms.modal_form): the same input-output map as the realisation it
came from, at most two non-zeros per row of A_m, balanced blocks, also when eigenvalues repeat
(identical bodies give every radiation pole twice: wavestar's fit once came back with T
singular and B_m of 7.5e15). Reference: the original (A, B, C)'s own frequency response."""
import numpy as np
import pytest

from mbcontrol.hydro.fit.ssforms import modal_form


def _response(A, B, C, omega):
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(1j * w * np.eye(n) - A, B) for w in omega])


def _check(A, B, C):
    A_m, B_m, C_m = modal_form(A, B, C)
    omega = np.geomspace(0.01, 100, 60)
    ref = _response(A, B, C, omega)
    np.testing.assert_allclose(_response(A_m, B_m, C_m, omega), ref,
                               atol=1e-9 * np.abs(ref).max())
    assert np.count_nonzero(A_m, axis=1).max() <= 2
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(A_m)),
                               np.sort_complex(np.linalg.eigvals(A)), atol=1e-8)
    return A_m, B_m, C_m


def _hidden(Lam, rng, n_io=2):
    """A = T0 Λ T0⁻¹ with a random well-conditioned T0, random B and C."""
    n = Lam.shape[0]
    T0 = np.eye(n) + 0.3 * rng.normal(size=(n, n))
    return (T0 @ Lam @ np.linalg.inv(T0), rng.normal(size=(n, n_io)), rng.normal(size=(n_io, n)))


def test_distinct_poles_real_and_complex():
    rng = np.random.default_rng(1)
    Lam = np.zeros((5, 5))
    Lam[0, 0], Lam[1, 1] = -0.5, -3.0
    Lam[2:4, 2:4] = [[-0.2, 1.5], [-1.5, -0.2]]
    Lam[4, 4] = -8.0
    _check(*_hidden(Lam, rng))


@pytest.mark.parametrize("seed", range(5))
def test_repeated_poles_of_identical_bodies(seed):
    """Two identical, uncoupled bodies: every pole (real and complex) twice. The blocks stay
    balanced: no row of B_m or column of C_m grows beyond the original system's gain."""
    rng = np.random.default_rng(seed)
    one = np.zeros((4, 4))
    one[0, 0] = -0.7
    one[1:3, 1:3] = [[-0.3, 2.0], [-2.0, -0.3]]
    one[3, 3] = -4.0
    A, B, C = _hidden(np.kron(np.eye(2), one), rng)
    A_m, B_m, C_m = _check(A, B, C)
    gain = np.abs(_response(A, B, C, np.geomspace(0.01, 100, 60))).max()
    assert np.abs(B_m).max() * np.abs(C_m).max() < 100 * gain


def test_defective_matrix_is_refused():
    A = np.array([[-1.0, 1.0], [0.0, -1.0]])              # a Jordan block: no eigenbasis
    with pytest.raises(ValueError, match="defective"):
        modal_form(A, np.ones((2, 1)), np.ones((1, 2)))
