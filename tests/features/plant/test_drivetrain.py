"""A PTO's drivetrain (scene [pto.drivetrain]; mbcontrol.plant.units.drivetrain_signals):
parsing with units, its signals, and energy conserved two ways: the drivetrain's own balance
(mechanical in = electrical out + winding and friction losses + its stored kinetic energy)
pointwise and over a run, and the whole plant's, dE/dt = excitation - radiated - PTO -
drivetrain friction, over a simulated run; the reflected inertia and friction read back from
the plant's exact Jacobians (the dynamics, not the output formulas)."""
import numpy as np
import pytest

from tests.helpers.drivetrain_scenes import with_drivetrain
from mbcontrol import build_plant, waves
from mbcontrol.analysis import simulate_checked as simulate  # the checked Dataset
from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    path = with_drivetrain(tmp_path_factory.mktemp("dt"), "sphere", gear=12.0, kt=670.0,
                           resistance="20 ohm", inertia=2.0, friction=1.0)
    return build_plant(path)


def test_scene_reads_the_drivetrain_with_units(tmp_path):
    path = with_drivetrain(tmp_path, "sphere", kt=6.7, resistance="500 mohm")
    text = path.read_text() + 'winding_inductance = "2 mH"\ncurrent_max = "1.2 kA"\n'
    path.write_text(text)
    d = load_scene(path).ptos[0].drivetrain
    assert (d.winding_resistance, d.winding_inductance, d.current_max) == (0.5, 2e-3, 1200.0)
    assert d.kt == pytest.approx(6.7 * np.sqrt(1.5)) and d.force_per_current == 12 * d.kt
    path.write_text(text.replace("phases = 3", "phases = 2"))
    with pytest.raises(SceneError, match=r"pto\[0\]\.drivetrain\.phases: expected 1 or 3"):
        load_scene(path)
    path.write_text(text.replace('"500 mohm"', '"5 kg"'))
    with pytest.raises(SceneError, match=r"drivetrain\.winding_resistance: expected a resistance"):
        load_scene(path)


def test_inertia_needs_a_joint(tmp_path):
    path = with_drivetrain(tmp_path, "wavestar", inertia=0.1)        # a PTO between points
    with pytest.raises(SceneError, match=r"drivetrain\.inertia: a drivetrain inertia needs a "
                                         r"PTO on a joint"):
        load_scene(path)


def test_signals_and_their_units(sphere):
    units = {s: sphere.units(s) for s in sphere.outputs if s.startswith("pto__")}
    assert units == {"pto__position": "m", "pto__velocity": "m/s", "pto__force": "N",
                     "pto__power": "W", "pto__current": "A", "pto__voltage": "V",
                     "pto__winding_loss": "W", "pto__friction_loss": "W",
                     "pto__electrical_power": "W", "pto__mechanical_power": "W",
                     "pto__hull_force": "N"}


def test_drivetrain_balance_pointwise(sphere):
    """At random states and commands: the joint's mechanical power = electrical + winding +
    friction + d/dt(gear^2 J v^2 / 2), with the acceleration from the plant's own f."""
    d = sphere.scene.ptos[0].drivetrain
    rng = np.random.default_rng(3)
    y_index = {name: i for i, name in enumerate(sphere.outputs)}
    j_vel = sphere.states.index("heave__vel")
    for _ in range(20):
        x = rng.normal(size=len(sphere.states)) * 0.5
        u, w = rng.normal(size=1) * 1e5, rng.normal(size=len(sphere.disturbances)) * 1e5
        y = np.asarray(sphere.h(x, u, w, sphere.p0)).ravel()
        a = float(np.asarray(sphere.f(x, u, w, sphere.p0)).ravel()[j_vel])
        v = x[j_vel]
        stored = d.gear_ratio ** 2 * d.inertia * v * a
        out = [y[y_index[f"pto__{k}"]] for k in ("electrical_power", "winding_loss",
                                                 "friction_loss", "mechanical_power")]
        assert out[3] == pytest.approx(out[0] + out[1] + out[2] + stored, rel=1e-12, abs=1e-6)
        # the force on the hull: the machine's less the reflected inertia and friction forces
        hull = y[y_index["pto__force"]] - d.gear_ratio ** 2 * (d.inertia * a + d.friction * v)
        assert y[y_index["pto__hull_force"]] == pytest.approx(hull, rel=1e-12, abs=1e-6)
        current = y[y_index["pto__force"]] / d.force_per_current
        assert y[y_index["pto__current"]] == pytest.approx(current, rel=1e-12)
        assert y[y_index["pto__voltage"]] == pytest.approx(
            d.winding_resistance * current + d.kt * d.gear_ratio * v, rel=1e-12, abs=1e-9)


def test_whole_plant_energy_balance_over_a_run(sphere):
    """E(t) - E(0) = integral of (excitation - radiated - PTO - drivetrain friction) power, to
    1e-6 of the excitation's work: Simpson's rule on a 2 ms grid of a 60 s run."""
    ds = simulate(sphere, waves.regular(2.0, 9.0), duration=60.0, dt=0.002,
                  params={"pto__damping": 3e5})
    from scipy.integrate import simpson
    t = ds.time.values
    net = (ds.excitation_power - ds.radiated_power - ds.pto__power - ds.pto__friction_loss).values
    gained = float(ds.energy[-1] - ds.energy[0])
    work = simpson(net, x=t)
    scale = simpson(np.abs(ds.excitation_power.values), x=t)
    assert abs(gained - work) < 1e-6 * scale, (gained, work, scale)
    d = sphere.scene.ptos[0].drivetrain
    # the drivetrain's own balance, integrated: in = out + losses + stored
    into = simpson(ds.pto__mechanical_power.values, x=t)
    out = simpson((ds.pto__electrical_power + ds.pto__winding_loss
                   + ds.pto__friction_loss).values, x=t)
    stored = 0.5 * d.gear_ratio ** 2 * d.inertia * float(ds.pto__velocity[-1] ** 2
                                                          - ds.pto__velocity[0] ** 2)
    assert abs(into - out - stored) < 1e-6 * abs(into)


def test_reflected_inertia_and_friction_are_in_the_dynamics(sphere):
    """The linear mass and damping read off the plant's Jacobians at rest (what the
    frequency-domain solution and the bounds use): the body's mass plus gear^2 J, the PTO
    damping plus gear^2 b."""
    from mbcontrol.analysis.frequency import mechanical_matrices
    d = sphere.scene.ptos[0].drivetrain
    m = mechanical_matrices(sphere, {"pto__damping": 0.0})
    assert m.mass[0, 0] == pytest.approx(sphere.scene.bodies[0].mass
                                         + d.gear_ratio ** 2 * d.inertia, rel=1e-12)
    assert m.damping[0, 0] == pytest.approx(d.gear_ratio ** 2 * d.friction, rel=1e-9)
