"""End stops, build-time checks (unrestored free DOFs, stiff stops) and the Euler-angle guard.

References: energy conservation of an elastic stop (a conservative contact returns the
pendulum to its release height), the closed-form contact frequency sqrt(k / I) of a pendulum
on a stop, and the known ZYX singularity at pitch ±90°.
"""
import math
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import SimulationError
from mbcontrol.plant import build_plant
from mbcontrol.scene import catalogue_dir, parse_scene
from mbcontrol.sim import simulate
from tests.helpers.scene_fixture import TUMBLER

G = 9.81
PENDULUM = """
name = "pendulum"
[water]
g = 9.81
[[body]]
name = "bob"
mass = 2.0
inertia = [0.01, 0.01, 0.01]
cog = [0.0, 0.0, 1.0]          # 1 m below the pivot (z down)
hydro = false
[[joint]]
name = "swing"
type = "revolute"
parent = "ground"
child = "bob"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
[[end_stop]]
joint = "swing"
upper = 0.2
stiffness = STIFFNESS
damping = DAMPING
"""
INERTIA = 2.0 * 1.0**2 + 0.01  # about the pivot, kg m^2


def _pendulum(stiffness=2000.0, damping=0.0):
    text = PENDULUM.replace("STIFFNESS", str(stiffness)).replace("DAMPING", str(damping))
    return build_plant(parse_scene(tomllib.loads(text), Path("pendulum.toml")))


def _release(plant, angle):
    x0 = plant.x0()
    x0[plant.states.index("swing")] = angle
    return x0


def _energy(ds):
    theta, omega = ds["swing"].values, ds["swing__vel"].values
    return 0.5 * INERTIA * omega**2 + 2.0 * G * 1.0 * (1 - np.cos(theta))


def test_stop_frequency_note_is_the_contact_frequency():
    plant = _pendulum()
    note = plant.notes["end_stops"]["swing_stop"]
    # contact: k (plus the small gravity stiffness, omitted by design) on the pivot inertia
    assert note["omega_rad_s"] == pytest.approx(math.sqrt(2000.0 / INERTIA), rel=1e-12)
    assert note["rk4_max_dt_s"] == pytest.approx(2.785 / note["omega_rad_s"])


def test_elastic_stop_conserves_energy_and_bounces_back():
    plant = _pendulum()
    drift = {}
    for dt in (4e-4, 2e-4):
        # released at -0.5 rad: swings into the stop at +0.2 rad (penetrates ~0.1 rad) and back
        ds = simulate(plant, duration=4.0, dt=dt, x0=_release(plant, -0.5))
        theta, e = ds["swing"].values, _energy(ds)
        assert theta.max() > 0.2                              # it did hit the stop
        free = theta < 0.2                                    # away from the stop, E is conserved
        drift[dt] = np.max(np.abs(e[free] - e[0])) / e[0]
        # back at the release angle a period later, as without the stop
        assert theta[ds["time"].values > 1.0].min() == pytest.approx(-0.5, abs=1e-4)
    # the stop is conservative: what is lost is integration error at the kink where contact
    # starts (the force is continuous, its slope is not; RK4 drops to low order across it and
    # the error depends on where the steps fall): measured 6.3e-7 (dt 4e-4 s), 1.4e-6 (2e-4 s).
    # At full penetration (~0.05 rad) the stop holds all of E (2.4 J), so an error in the law
    # (a pull on release, a wrong sign, damping where there is none) would show at order 1.
    assert max(drift.values()) < 1e-5


def test_damped_stop_dissipates_and_never_pulls():
    plant = _pendulum(damping=40.0)
    ds = simulate(plant, duration=4.0, dt=2e-4, x0=_release(plant, -0.5))
    e = _energy(ds)
    assert e[-1] < 0.9 * e[0]                              # the stop took energy
    # one-sided: the joint load from the stop never pulls towards it (load <= 0 beyond upper);
    # here: while engaged the generalised acceleration beyond gravity points back
    theta, omega = ds["swing"].values, ds["swing__vel"].values
    alpha = np.gradient(omega, ds["time"].values)
    gravity = -2.0 * G * np.sin(theta) / INERTIA
    engaged = theta > 0.2 + 1e-3
    assert np.all(alpha[engaged] - gravity[engaged] <= 1e-6)


def test_step_beyond_stop_stability_warns():
    plant = _pendulum(stiffness=2e6)            # omega ~ 1000 rad/s, RK4 limit ~ 2.8 ms
    with pytest.warns(RuntimeWarning, match=r"end stop 'swing_stop' rings at .* RK4 is stable there only"):
        simulate(plant, duration=0.05, dt=0.01, x0=_release(plant, -0.1))


def test_free_dof_without_restoring_warns_naming_body_and_dof():
    data = tomllib.loads((catalogue_dir() / "hinged_raft.toml").read_text())
    data.pop("mooring")
    data["hydro"]["file"] = str(catalogue_dir() / "hinged_barge_hydro.nc")
    scene = parse_scene(data, catalogue_dir() / "hinged_raft.toml")
    with pytest.warns(RuntimeWarning, match=r"body 'barge1' has no restoring in Surge \(free joint 'raft'\)"):
        plant = build_plant(scene)
    assert plant.notes["free_dofs_without_restoring"] == ["barge1__Surge"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")             # the moored raft: no warning
        assert build_plant("hinged_raft").notes["free_dofs_without_restoring"] == []


@pytest.mark.filterwarnings("ignore:.*rest is not an equilibrium")   # it falls: no buoyancy
def test_euler_singularity_stops_with_a_clear_error():
    with pytest.warns(RuntimeWarning, match="no restoring"):
        plant = build_plant(parse_scene(tomllib.loads(TUMBLER), Path("tumbler.toml")))
    x0 = plant.x0()
    x0[plant.states.index("float__Pitch__vel")] = 1.0      # pitch rate 1 rad/s: 85 deg at ~1.48 s
    with pytest.raises(SimulationError, match=r"body 'box' reached a pitch of 85\.\d deg at t = 1\.4\d+ s"):
        simulate(plant, duration=3.0, dt=1e-3, x0=x0)


def test_energy_output_includes_gravity_and_stop_potentials():
    """The plant's `energy` output (kinetic + potentials) of the dry pendulum with an elastic
    stop is the pendulum's own mechanical energy (closed form) at every instant, contact
    included, and constant (the system is conservative)."""
    plant = _pendulum()
    ds = simulate(plant, duration=2.0, dt=2e-4, x0=_release(plant, -0.5))
    theta = ds["swing"].values
    stop = 0.5 * 2000.0 * np.maximum(theta - 0.2, 0.0) ** 2
    np.testing.assert_allclose(ds["energy"].values, _energy(ds) + stop, rtol=0, atol=1e-12)
    # measured drift 1.4e-6 of E0 (the kink at contact; see the elastic-stop test)
    assert np.ptp(ds["energy"].values) < 1e-5 * ds["energy"].values[0]
