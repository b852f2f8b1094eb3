"""The PTO's linear view is computed in one place (mbcontrol.analysis.pto_thevenin,
exp(-i omega t)); the controllers' intrinsic impedance (exp(+i omega t)) converts it at its
edge. Reference: the derivation the controllers used before, independent of the Thevenin
code: two frequency-domain solutions with different PTO damping, V(c) = F_eq / (Z_i + c)."""
import numpy as np
import pytest

from mbcontrol.analysis import frequency_domain_response
from mbcontrol.controllers.impedance import base_params, intrinsic_impedance
from mbcontrol.plant import build_plant


def _two_solutions(plant, omega, name, params):
    base = base_params(plant, name, params)
    beside = base[f"{name}__damping"]

    def velocity(c):
        return frequency_domain_response(plant, omega, params={**base, f"{name}__damping": beside + c},
                                         outputs=[f"{name}__velocity"])[:, 0]
    v0, c = velocity(0.0), 1.0
    Z = c * velocity(c) / (v0 - velocity(c))
    c = float(np.median(np.abs(Z)))            # a damper of Z_i's size: well conditioned
    Z = c * velocity(c) / (v0 - velocity(c))
    return Z, v0 * Z


@pytest.mark.parametrize("model", ["sphere", "hinged_barge"])
@pytest.mark.parametrize("beside", [False, True])
def test_intrinsic_impedance_is_the_thevenin_view_converted(model, beside):
    plant = build_plant(model)
    name = plant.scene.ptos[0].name
    omega = np.linspace(plant.hydro.omega[1], plant.hydro.omega[-2], 40)
    params = {f"{name}__damping": 1e3, f"{name}__stiffness": 50.0} if beside else None
    Z, F = intrinsic_impedance(plant, omega, pto=name, params=params)
    Z_ref, F_ref = _two_solutions(plant, omega, name, params)
    np.testing.assert_allclose(Z, Z_ref, rtol=1e-10)
    np.testing.assert_allclose(F, F_ref, rtol=1e-10)
