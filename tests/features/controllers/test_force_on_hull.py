"""Where a PTO's force limit acts (`[[pto]] force_max_on`, issue 36): on the machine (the
command, as before) or, with a drivetrain, on the hull (the machine's force less the
drivetrain's reflected inertia and friction forces, WecOptTool's PTO force). Checked against
the simulated plant: its hull force against the machine force and the measured acceleration,
and a damper tuned to the hull limit against the hull force it produces."""
import numpy as np
import pytest

from tests.helpers.drivetrain_scenes import DRIVETRAIN, catalogue_copy
from mbcontrol import waves
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene

GEAR, INERTIA, FRICTION = 12.0, 200.0, 100.0      # 28.8 t and 14.4 kN s/m at the hull


def _scene(folder, on: str | None, drivetrain: bool = True):
    text = (f'\nforce_max_on = "{on}"\n' if on else "") + (DRIVETRAIN.format(
        gear=GEAR, kt=6.7, resistance="0.5 ohm", inertia=INERTIA, friction=FRICTION)
        if drivetrain else "")
    return catalogue_copy(folder, "sphere", f"{on}_{drivetrain}", text)


@pytest.fixture(scope="module")
def plants(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hull")
    return {on: build_plant(load_scene(_scene(folder, on))) for on in ("hull", "machine")}


def test_the_scene_says_where_and_refuses_what_cannot_be(tmp_path):
    with pytest.raises(ValueError, match="force_max_on.*needs a \\[pto.drivetrain\\]"):
        load_scene(_scene(tmp_path, "hull", drivetrain=False))
    with pytest.raises(ValueError, match="force_max_on"):
        load_scene(_scene(tmp_path, "shaft"))
    pto = load_scene(_scene(tmp_path, None)).ptos[0]
    assert pto.force_max_on == "machine" and pto.limited_force("wec") == "hull"


def test_the_bounds_limit_the_force_the_scene_names(plants):
    """The electrical and mechanical bounds of the hull-limited scene are the machine-limited
    scene's bounds asked for the hull force, and their force series (the hull's) hold it."""
    from mbcontrol.analysis import pseudo_spectral_bound
    from mbcontrol.analysis.electrical import electrical_bound
    wave = waves.regular(2.0, 9.0)
    free = electrical_bound(plants["machine"], wave, omega_max=6.0)
    limit = 0.5 * free.mechanical.max_force                      # binds on both forces
    on_hull = electrical_bound(plants["hull"], wave, force_max=limit, omega_max=6.0)
    asked = electrical_bound(plants["machine"], wave, force_max=limit, omega_max=6.0,
                             force_on="hull")
    machine = electrical_bound(plants["machine"], wave, force_max=limit, omega_max=6.0)
    assert on_hull.electrical_W == pytest.approx(asked.electrical_W, rel=1e-6)
    assert abs(on_hull.electrical_W / machine.electrical_W - 1) > 1e-3
    limit = 0.5 * pseudo_spectral_bound(plants["machine"], wave).max_force
    mech = pseudo_spectral_bound(plants["hull"], wave, force_max=limit)
    assert mech.max_force == pytest.approx(limit, rel=1e-3)
    assert mech.mean_power != pytest.approx(
        pseudo_spectral_bound(plants["machine"], wave, force_max=limit).mean_power, rel=1e-3)


def test_a_damper_tuned_to_the_hull_limit_holds_it_in_simulation(plants):
    """optimal_damping with the hull limit binding: the passive law runs without a command
    clip (the limit is not on the machine); the simulated hull force, which the plant gives
    as <pto>__hull_force and which equals the machine force less gear^2 (J a + b v) from the
    record, has its amplitude at the limit (linear theory's prediction) and the metrics
    report it."""
    from mbcontrol.analysis import pto_metrics
    from mbcontrol.controllers import make
    from mbcontrol.controllers.passive import optimal_damping
    from mbcontrol.sim import simulate
    plant = plants["hull"]
    wave = waves.regular(2.0, 9.0)
    c_free, _ = optimal_damping(plant, wave)
    free = simulate(plant, wave, duration=90.0, dt=0.01, controller=make("passive",
                                                                         damping=c_free))
    limit = 0.85 * pto_metrics(free, plant.scene.ptos[0])["max_force"]   # binds
    c, _ = optimal_damping(plant, wave, force_max=limit)
    assert c != pytest.approx(c_free, rel=0.05)
    law = make("passive", damping=c)
    run = simulate(plant, wave, duration=90.0, dt=0.01, controller=law)
    assert law.saturation[0] == np.inf                           # no clip on the machine
    t, v = run["time"].values, run["pto__velocity"].values
    a = np.gradient(v, t)
    expected = run["pto__force"].values - GEAR ** 2 * (INERTIA * a + FRICTION * v)
    window = t > 45.0
    hull = run["pto__hull_force"].values
    assert np.max(np.abs(hull - expected)[window]) < 0.01 * limit
    metrics = pto_metrics(run, plant.scene.ptos[0])
    assert metrics["force_max_on"] == "hull" and metrics["max_force"] > 0.95 * limit
    # linear theory holds the hull force's first harmonic at the limit (the plant's nonlinear
    # hydrostatics add harmonics to the acceleration: the peak is 3-6 % above it)
    basis = np.exp(1j * wave.omega[0] * t[window])
    first = 2 * abs(np.mean(hull[window] * np.conj(basis)))
    assert first == pytest.approx(limit, rel=0.01)
    machine = run["pto__force"].values[window]
    assert 2 * abs(np.mean(machine * np.conj(basis))) < 0.9 * limit      # not the machine's


def test_the_mpc_holds_a_hull_limit_in_simulation(tmp_path):
    """The MPC's hull-force rows (the hull's force at both ends of every held step, its
    acceleration from the continuous model with the force's feedthrough): with the limit on
    the hull it keeps the simulated force on the hull (the plant's <pto>__hull_force, the
    machine's less gear^2 (J a + b v)) within the limit, with the oracle forecast and, after
    its warm-up, the causal AR one, while the machine's own force is not what is held; the
    NMPC still refuses."""
    from mbcontrol.analysis import pto_metrics
    from mbcontrol.controllers import make
    from mbcontrol.sim import simulate
    wave = waves.regular(2.0, 9.0)

    def run(limit, forecast="known", duration=60.0):
        path = _scene(tmp_path, "hull")
        path.write_text(path.read_text().replace("force_max = 2.0e6", f"force_max = {limit}"))
        plant = build_plant(load_scene(path))
        mpc = make("mpc", horizon_s=6.0, dt_s=0.2, wave=wave, forecast=forecast)
        out = simulate(plant, wave, duration=duration, dt=0.02, controller=mpc)
        start = max(duration / 2, mpc.warm_up_end + 15.0)   # the damper's warm-up and
        window = out["time"].values > start                 # the hand-over left out
        assert start <= duration - 30.0
        return plant, {k: np.max(np.abs(out[f"pto__{k}"].values[window]))
                       for k in ("hull_force", "force")}, pto_metrics(out, plant.scene.ptos[0])
    _, free, _ = run(1e9)
    limit = 0.6 * free["hull_force"]              # the drivetrain's inertia force dominates
    plant, held, metrics = run(limit)
    assert held["hull_force"] < 1.02 * limit < free["hull_force"]
    assert held["force"] < 0.6 * limit            # the machine's force is a different one
    assert metrics["force_max_on"] == "hull" and metrics["mean_power_W"] > 0
    _, causal, _ = run(limit, forecast="ar", duration=100.0)
    assert causal["hull_force"] < 1.02 * limit
    with pytest.raises(ValueError, match="limits the force on the hull"):
        make("nmpc", wave=wave, horizon_s=4.0, dt_s=0.2).reset(plant)
