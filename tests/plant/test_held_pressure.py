"""The nonlinear pressure sampled once per step ([hydro] nonlinear_update = "step";
mbcontrol.plant.held_pressure), on the R = 5 m hemisphere in heave (sphere_nonlinear.toml) on
the panel path, 104 points.

References: the plant's own f (the held f given the exact load must be f, to round-off); the
closed-form waterplane stiffness of a hemisphere, rho g pi R^2 (the held load's rest increment
in heave); the same plant stepped with the load at every stage ("stage"): the held steps must
converge to it at first order in dt, as the method's error analysis says (halving dt halves
the difference), and stay within 0.1 % of it in a steep sea at the default dt.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol import sim, waves
from mbcontrol.errors import SceneError
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene

SCENE = Path(__file__).with_name("sphere_nonlinear.toml")
RHO, G, RADIUS = 1000.0, 9.81, 5.0


def _plant(update: str):
    scene = load_scene(str(SCENE))
    hydro = dataclasses.replace(scene.hydro, nonlinear_path="panels", nonlinear_panel_size=2.0,
                                nonlinear_update=update)
    return build_plant(dataclasses.replace(scene, hydro=hydro))


@pytest.fixture(scope="module")
def plants():
    return {update: _plant(update) for update in ("stage", "step")}


def test_the_held_f_given_the_exact_load_is_f(plants):
    plant = plants["step"]
    held = plant.held
    rng = np.random.default_rng(5)
    for _ in range(5):
        x = rng.normal(size=plant.nx) * 0.5
        x[0] = rng.uniform(-2.0, 2.0)                      # heave, m: wet surface changes
        w = rng.normal(size=len(plant.disturbances)) * 0.3
        u, p = np.zeros(len(plant.inputs)), plant.p0
        load = held.load(x[:plant.n_q], w)
        exact = np.asarray(plant.f(x, u, w, p)).ravel()
        np.testing.assert_allclose(np.asarray(held.f(x, u, w, p, load)).ravel(), exact,
                                   rtol=1e-12, atol=1e-12 * np.max(np.abs(exact)))


def test_the_rest_increments_are_the_waterplane_stiffness_and_the_linear_froude_krylov(plants):
    plant = plants["step"]
    held, body = plant.held, plant.pressure[0]
    # heave along +z (down): sinking by dq adds rho g pi R^2 dq of buoyancy, upwards
    closed_form = -RHO * G * math.pi * RADIUS ** 2
    assert held.stiffness[0, 0] == pytest.approx(closed_form, rel=0.015)   # 104 points: 0.9 %
    # per field row, the load's increment is the surface's linear Froude-Krylov force in heave;
    # the excitation row (BEM minus that force) does not move the pressure at all
    assert held.per_row[0, 0] == 0.0
    np.testing.assert_allclose(held.per_row[0, 1:], body.linear_fk[2], rtol=1e-12,
                               atol=1e-9 * np.max(np.abs(body.linear_fk[2])))


def test_held_steps_converge_to_the_stage_steps_at_first_order(plants):
    sea = waves.irregular(2.5, 8.0, seed=1, duration=60.0)        # steep: Hs 2.5 m, Tp 8 s
    gaps = []
    for dt in (0.02, 0.01):
        heave = {update: sim.simulate(plant, sea, duration=60.0, dt=dt, params=plant.params(
            pto__damping=1.0e6))["heave"].values for update, plant in plants.items()}
        gaps.append(np.sqrt(np.mean((heave["step"] - heave["stage"]) ** 2))
                    / np.sqrt(np.mean(heave["stage"] ** 2)))
    # measured: 5.4e-4 at 0.02 s, 2.7e-4 at 0.01 s (100 s record), ratio 2.00
    assert gaps[1] < 1e-3
    assert 1.6 < gaps[0] / gaps[1] < 2.5


def test_the_setting_needs_the_nonlinear_pressure(tmp_path):
    text = SCENE.read_text().replace('hydrostatics = "nonlinear"', 'hydrostatics = "linear"')
    text = text.replace('froude_krylov = "nonlinear"', 'nonlinear_update = "step"')
    text = text.replace('file = "../../models/', f'file = "{SCENE.parents[2]}/models/')
    text = text.replace('source = "../../../shared/', f'source = "{SCENE.parents[3]}/shared/')
    path = tmp_path / "held_linear.toml"
    path.write_text(text)
    with pytest.raises(SceneError, match=r"nonlinear_update.*hydrostatics = \"nonlinear\""):
        load_scene(str(path))
    path.write_text(SCENE.read_text().replace(
        'froude_krylov = "nonlinear"', 'froude_krylov = "nonlinear"\nnonlinear_update = "often"')
        .replace('file = "../../models/', f'file = "{SCENE.parents[2]}/models/')
        .replace('source = "../../../shared/', f'source = "{SCENE.parents[3]}/shared/'))
    with pytest.raises(SceneError, match="nonlinear_update"):
        load_scene(str(path))


def test_plants_derived_with_their_own_f_do_not_hold_the_original(plants):
    """A plant rebuilt around another f (the linearised plant of a fidelity search, the
    sensitivity plant) must step that f: a held load of the original would replace it."""
    from mbcontrol.plant.fidelity import linearised_plant
    from mbcontrol.sim import sensitivity_plant
    plant = plants["step"]
    assert linearised_plant(plant).held is None
    assert sensitivity_plant(plant, ["pto__damping"], ["heave"]).held is None
