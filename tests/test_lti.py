"""The shared LTI blocks (mbcontrol.lti) against python-control and scipy, which compute the
same things their own way: the frequency response by python-control's evaluation of the
transfer function, the zero-order hold by scipy's cont2discrete."""
import control
import numpy as np
import pytest
from scipy.signal import cont2discrete

from mbcontrol.lti import frequency_response, state_response, zoh


@pytest.fixture
def system():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((7, 7)) - 3 * np.eye(7)
    return A, rng.standard_normal((7, 2)), rng.standard_normal((3, 7)), rng.standard_normal((3, 2))


def test_frequency_response_is_python_controls(system):
    A, B, C, D = system
    omega = np.geomspace(0.01, 100, 257)
    G = frequency_response(A, B, C, D, omega)
    ref = control.ss(A, B, C, D)(1j * omega)            # (outputs, inputs, omega)
    assert G.shape == ref.shape == (3, 2, omega.size)   # python-control's axis order
    np.testing.assert_allclose(G, ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(frequency_response(A, B, C, None, omega) + D[..., None], G,
                               rtol=1e-12)
    X = state_response(A, B, omega)
    np.testing.assert_allclose(np.einsum("ij,jkw->ikw", C, X) + D[..., None], G, rtol=1e-12)


def test_many_states_are_solved_in_slices_with_the_same_result():
    rng = np.random.default_rng(4)
    n = 300                                             # 5 frequencies a slice
    A = rng.standard_normal((n, n)) / np.sqrt(n) - 2 * np.eye(n)
    B, C = rng.standard_normal((n, 1)), rng.standard_normal((1, n))
    omega = np.linspace(0.1, 3, 23)
    G = frequency_response(A, B, C, None, omega)[0, 0]
    one_by_one = [C[0] @ np.linalg.solve(1j * w * np.eye(n) - A, B[:, 0]) for w in omega]
    np.testing.assert_allclose(G, one_by_one, rtol=1e-10)


def test_zoh_is_scipys(system):
    A, B, C, D = system
    Phi, Gamma = zoh(A, B, 0.05)
    Ad, Bd, *_ = cont2discrete((A, B, C, D), 0.05, method="zoh")
    np.testing.assert_allclose(Phi, Ad, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(Gamma, Bd, rtol=1e-12, atol=1e-14)
