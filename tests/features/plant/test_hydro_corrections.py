"""Hydro correction parameters (build_plant(..., hydro_corrections=True)): scale factors of
added mass, radiation and excitation per hydro DOF, for identification.

References: at scale 1 the plant's equations are the uncorrected plant's, value for value;
with scales, the linearised plant's heave response of the sphere equals the response written
here by hand from the BEM arrays with the same scales applied,
    X = s_e F / (K - omega^2 (m + s_a A_inf + s_r (A(omega) - A_inf)) + i omega (s_r B + c)),
to the radiation fit's accuracy (its scene tolerance is 1 %: 2 % allowed on the response).
"""
import numpy as np
import pytest

from mbcontrol import build_plant, linearize
from mbcontrol.analysis import statespace_response


@pytest.fixture(scope="module")
def plants():
    return build_plant("sphere"), build_plant("sphere", hydro_corrections=True)


def test_unit_scales_change_nothing(plants):
    plain, corrected = plants
    rng = np.random.default_rng(0)
    extra = [n for n in corrected.parameters if n not in plain.parameters]
    assert extra == [f"sphere__Heave__{k}_scale" for k in ("added_mass", "radiation",
                                                           "excitation")]
    assert corrected.params()[[corrected.parameters.index(n) for n in extra]].tolist() == [1, 1, 1]
    for _ in range(5):
        x = rng.normal(size=plain.nx)
        u, w = rng.normal(size=len(plain.inputs)), rng.normal(size=len(plain.disturbances))
        p_plain = plain.p0
        p_corr = corrected.params(**dict(zip(plain.parameters, plain.p0)))
        np.testing.assert_allclose(np.asarray(corrected.f(x, u, w, p_corr)).ravel(),
                                   np.asarray(plain.f(x, u, w, p_plain)).ravel(), rtol=1e-12,
                                   atol=1e-12)


def test_scaled_response_equals_the_hand_written_one(plants):
    _, plant = plants
    s_a, s_r, s_e, c = 1.3, 0.6, 0.8, 2.0e5
    params = {"sphere__Heave__added_mass_scale": s_a, "sphere__Heave__radiation_scale": s_r,
              "sphere__Heave__excitation_scale": s_e, "pto__damping": c}
    sys = linearize(plant, params=params)
    omega = np.linspace(0.4, 2.0, 17)
    got = statespace_response(sys, plant, omega, outputs=["heave"])[:, 0]
    hyd = plant.hydro
    A = np.interp(omega, hyd.omega, hyd.added_mass()[:, 0, 0])
    B = np.interp(omega, hyd.omega, hyd.radiation_damping()[:, 0, 0])
    A_inf = float(np.asarray(hyd.added_mass_inf)[0, 0])
    F = hyd.excitation_coefficients(0.0)[:, 0]
    F = np.conj(np.interp(omega, hyd.omega, F.real) + 1j * np.interp(omega, hyd.omega, F.imag))
    m, K = plant.scene.bodies[0].mass, hyd.hydrostatic_stiffness()[0, 0]
    expected = s_e * F / (K - omega ** 2 * (m + s_a * A_inf + s_r * (A - A_inf))
                          + 1j * omega * (s_r * B + c))
    assert np.max(np.abs(got - expected) / np.abs(expected)) < 0.02
    # and the scales matter: the unscaled plant misses by far more than that
    base = statespace_response(linearize(plant, params={"pto__damping": c}), plant, omega,
                               outputs=["heave"])[:, 0]
    assert np.max(np.abs(base - expected) / np.abs(expected)) > 0.2
