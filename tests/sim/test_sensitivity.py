"""Forward sensitivities through the compiled integrator (mbcontrol.sim.sensitivity) against
central finite differences of the same simulation.

For explicit Runge-Kutta steps the augmented system is the exact derivative of the discrete
map, so the only difference from a central difference is the difference's own error,
O(h^2) truncation plus round-off / h: with h = 1e-4 relative it is below 1e-6 of the
derivative's range (measured 1e-7 to 1e-8)."""
import numpy as np
import pytest

from mbcontrol import build_plant, waves
from mbcontrol.sim import simulate_batch
from mbcontrol.sim.sensitivity import sensitivity_name, sensitivity_plant


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere", hydro_corrections=True)


@pytest.mark.parametrize("name", ["pto__damping", "sphere__Heave__added_mass_scale",
                                  "sphere__Heave__radiation_scale",
                                  "sphere__Heave__excitation_scale"])
def test_sensitivity_equals_central_difference(sphere, name):
    names = ["pto__damping", "sphere__Heave__added_mass_scale", "sphere__Heave__radiation_scale",
             "sphere__Heave__excitation_scale"]
    augmented = sensitivity_plant(sphere, names, ["heave", "pto__force"])
    wave = waves.regular(2.0, 8.0, phase=0.4)
    p = sphere.params(pto__damping=3e5, sphere__Heave__added_mass_scale=1.1)
    run = dict(duration=60.0, dt=0.1, audit=False)
    ds = simulate_batch(augmented, [wave], [np.asarray(p)], **run)
    i = sphere.parameters.index(name)
    step = 1e-4 * max(abs(p[i]), 1.0)
    ys = []
    for sign in (1, -1):
        q = p.copy()
        q[i] += sign * step
        ys.append(simulate_batch(sphere, [wave], [q], **run))
    for output in ("heave", "pto__force"):
        fd = (ys[0][output].values[0] - ys[1][output].values[0]) / (2 * step)
        exact = ds[sensitivity_name(output, name)].values[0]
        assert np.ptp(fd) > 0                     # the parameter does move this output
        assert np.max(np.abs(exact - fd)) < 1e-6 * np.ptp(fd)


def test_sensitivity_plant_keeps_the_plant_and_names_errors(sphere):
    augmented = sensitivity_plant(sphere, ["pto__damping"], ["heave"])
    assert augmented.outputs[:len(sphere.outputs)] == sphere.outputs
    assert augmented.nx == 2 * sphere.nx
    ds0 = simulate_batch(sphere, [waves.regular(1.0, 9.0)], None, duration=30.0, dt=0.1,
                         audit=False)
    ds1 = simulate_batch(augmented, [waves.regular(1.0, 9.0)], None, duration=30.0, dt=0.1,
                         audit=False)
    # the original states and outputs are untouched by the appended equations: the same
    # numbers up to round-off (the compiler reassociates sums differently in a larger function)
    np.testing.assert_allclose(ds1["heave"].values, ds0["heave"].values, rtol=1e-12, atol=1e-15)
    with pytest.raises(KeyError, match="unknown parameter"):
        sensitivity_plant(sphere, ["pto__dampin"], ["heave"])
    with pytest.raises(KeyError, match="unknown output"):
        sensitivity_plant(sphere, ["pto__damping"], ["heav"])
