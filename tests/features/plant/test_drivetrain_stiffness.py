"""A drivetrain's shaft stiffness (scene `[pto.drivetrain] stiffness`, K at the generator,
gear^2 K on the joint; WecOptTool's Z_d = i omega J + b - i K / omega times gear^2).

Independent references:
- the same motion as the drivetrain without K and an extra spring gear^2 K on the hull (a
  linear mooring in heave): in simulation and in the electrical bound with the machine's force
  limited; the force on the hull differs by exactly gear^2 K x (the machine's is the same);
- the same motion as a PTO law spring gear^2 K (negative K): the force on the hull is then the
  same and the machine's differs by gear^2 K x;
- the electrical bound with no force limit against the closed-form Thevenin optimum of the
  TSTE 2023 paper (Michelen Stroefer et al., eqs. 19-22) built from the bare hull's impedance
  and WecOptTool's drivetrain two-port, for J, b and K together;
- the force-on-hull series of the limited bound against the machine's force less
  gear^2 (J a + b v + K x) recomputed from its own series, and its check between the
  collocation points (analysis.dense) made on that force.
"""
import numpy as np
import pytest

from tests.helpers.drivetrain_scenes import DRIVETRAIN, catalogue_copy
from mbcontrol import build_plant, waves
from mbcontrol.analysis import simulate_checked as simulate  # the checked Dataset
from mbcontrol.analysis.electrical import electrical_bound
from mbcontrol.controllers.impedance import electrical_optimum, intrinsic_impedance
from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene

GEAR, KT, R, J, B = 12.0, 670.0, 20.0, 2.0, 1.0
K = 1000.0                   # N m/rad at the generator: 144 kN/m on the sphere (hydrostatic 770)
SPRING = GEAR ** 2 * K


def _scene(folder, suffix, *, stiffness=0.0, law_spring=0.0, mooring=0.0, on="machine"):
    text = f'\nforce_max_on = "{on}"\n' + (f"stiffness = {law_spring}\n" if law_spring else "")
    text += DRIVETRAIN.format(gear=GEAR, kt=KT, resistance=f"{R} ohm", inertia=J, friction=B)
    text += f"stiffness = {stiffness}\n"
    if mooring:
        text += (f'\n[[mooring]]\nname = "spring"\nbody = "sphere"\npoint = [0.0, 0.0, 2.0]\n'
                 f"stiffness = [0.0, 0.0, {mooring}]\n")
    # one radiation fit for every variant: judged by the response, each would get its own (a
    # spring or a drivetrain changes the device), and the equivalences below need the same one
    return catalogue_copy(folder, "sphere", suffix, text, kernel_judged=True)


@pytest.fixture(scope="module")
def plants(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dt_k")
    return {"K": build_plant(_scene(folder, "k", stiffness=K)),
            "K_hull": build_plant(_scene(folder, "k_hull", stiffness=K, on="hull")),
            "mooring": build_plant(_scene(folder, "mooring", mooring=SPRING)),
            "-K": build_plant(_scene(folder, "minus_k", stiffness=-K)),
            "law": build_plant(_scene(folder, "law", law_spring=-SPRING)),
            "bare": build_plant(catalogue_copy(folder, "sphere", "bare", "", kernel_judged=True))}


def test_scene_reads_a_stiffness_of_either_sign(tmp_path):
    d = load_scene(_scene(tmp_path, "a", stiffness=-15.0)).ptos[0].drivetrain
    assert d.stiffness == -15.0
    assert d.reflected_impedance(2j) == pytest.approx(GEAR ** 2 * (J * 2j + B - 15.0 / 2j))
    assert load_scene(catalogue_copy(tmp_path, "sphere", "b", DRIVETRAIN.format(
        gear=GEAR, kt=KT, resistance="1 ohm", inertia=J, friction=B))).ptos[0] \
        .drivetrain.stiffness == 0.0
    path = _scene(tmp_path, "c")
    path.write_text(path.read_text().replace("stiffness = 0.0", 'stiffness = "stiff"'))
    with pytest.raises(SceneError, match=r"drivetrain\.stiffness"):
        load_scene(path)


def test_simulated_motion_is_a_hull_spring_and_the_hull_force_differs_by_it(plants):
    """Drivetrain K against a mooring spring gear^2 K (same drivetrain without K), the same
    damper law: the same motion and machine force; hull force less by gear^2 K x. Against a
    law spring gear^2 K (drivetrain -K against law -gear^2 K): the same motion and hull force;
    the machine's carries the spring."""
    wave = waves.regular(2.0, 8.0)
    run = {k: simulate(plants[k], wave, duration=40.0, dt=0.01, params={"pto__damping": 3e5})
           for k in ("K", "mooring", "-K", "law")}
    x = run["K"].pto__position.values
    assert np.max(np.abs(x)) > 0.3
    scale = np.max(np.abs(run["K"].pto__force.values))
    for a, b, spring in (("K", "mooring", SPRING), ("-K", "law", -SPRING)):
        xa = run[a].pto__position.values
        np.testing.assert_allclose(xa, run[b].pto__position.values, atol=1e-6 * np.max(abs(xa)))
        np.testing.assert_allclose(run[a].pto__velocity.values, run[b].pto__velocity.values,
                                   atol=1e-6 * np.max(np.abs(run[a].pto__velocity.values)))
        hull_gap = run[a].pto__hull_force.values - run[b].pto__hull_force.values
        machine_gap = run[a].pto__force.values - run[b].pto__force.values
        if b == "mooring":      # the spring is not the machine's: the hull force feels it
            np.testing.assert_allclose(hull_gap, -spring * xa, atol=1e-6 * scale)
            np.testing.assert_allclose(machine_gap, 0.0, atol=1e-6 * scale)
        else:                   # the law spring is the machine's: the hull force is the same
            np.testing.assert_allclose(hull_gap, 0.0, atol=1e-6 * scale)
            np.testing.assert_allclose(machine_gap, spring * xa, atol=1e-6 * scale)


def test_energy_balances_with_the_shaft_spring(plants):
    """Pointwise: mechanical in = electrical + winding + friction + d/dt(gear^2 (J v^2 +
    K x^2) / 2); over a run: the plant's energy (the spring's potential in it) against the
    work of excitation, radiation, the PTO and the drivetrain friction."""
    from scipy.integrate import simpson
    plant = plants["-K"]
    d = plant.scene.ptos[0].drivetrain
    rng = np.random.default_rng(5)
    y_index = {name: i for i, name in enumerate(plant.outputs)}
    i_x, i_v = plant.states.index("heave"), plant.states.index("heave__vel")
    for _ in range(10):
        x = rng.normal(size=len(plant.states)) * 0.5
        u, w = rng.normal(size=1) * 1e5, rng.normal(size=len(plant.disturbances)) * 1e5
        y = np.asarray(plant.h(x, u, w, plant.p0)).ravel()
        a = float(np.asarray(plant.f(x, u, w, plant.p0)).ravel()[i_v])
        stored = d.gear_ratio ** 2 * (d.inertia * a + d.stiffness * x[i_x]) * x[i_v]
        out = [y[y_index[f"pto__{k}"]] for k in ("electrical_power", "winding_loss",
                                                 "friction_loss", "mechanical_power")]
        assert out[3] == pytest.approx(out[0] + out[1] + out[2] + stored, rel=1e-12, abs=1e-6)
    ds = simulate(plant, waves.regular(2.0, 9.0), duration=60.0, dt=0.002,
                  params={"pto__damping": 3e5})
    t = ds.time.values
    net = (ds.excitation_power - ds.radiated_power - ds.pto__power - ds.pto__friction_loss).values
    scale = simpson(np.abs(ds.excitation_power.values), x=t)
    assert abs(float(ds.energy[-1] - ds.energy[0]) - simpson(net, x=t)) < 1e-6 * scale


def _thevenin_power(plant_bare, wave, J, b, K):
    """The paper's eqs. 19-22: Z_i the bare hull's (exp(+i omega t)), the drivetrain as
    WecOptTool's two-port Z11 = -gear^2 (i w J + b - i K / w), Z12 = Z21 = -gear kt', Z22 = R;
    V_th = Z21 F_e / (Z_i - Z11), Z_th = Z22 + Z12 Z21 / (Z_i - Z11), P = |V_th|^2 / (8 Re
    Z_th)."""
    w = wave.omega
    Zi, F = intrinsic_impedance(plant_bare, w, direction=wave.direction)
    z11 = -GEAR ** 2 * (1j * w * J + b - 1j * K / w)
    z12 = -np.sqrt(1.5) * KT * GEAR
    v_th = z12 / (Zi - z11) * F * wave.amplitude
    z_th = R + z12 * z12 / (Zi - z11)
    return float(np.sum(np.abs(v_th) ** 2 / (8 * z_th.real)))


@pytest.mark.parametrize("period", [6.0, 9.0, 12.0])
@pytest.mark.parametrize("which", ["K", "-K"])
def test_unlimited_bound_is_the_thevenin_optimum(plants, which, period):
    wave = waves.regular(2.0, period)
    sign = 1.0 if which == "K" else -1.0
    expected = _thevenin_power(plants["bare"], wave, J, B, sign * K)
    assert electrical_bound(plants[which], wave).electrical_W == pytest.approx(expected,
                                                                               rel=1e-5)
    assert electrical_optimum(plants[which], wave)["power_W"] == pytest.approx(expected,
                                                                               rel=1e-9)
    other = _thevenin_power(plants["bare"], wave, J, B, -sign * K)
    assert abs(other / expected - 1) > 1e-3          # K is seen


def test_limited_bounds(plants):
    """Machine force limited: the drivetrain K's bound is the mooring spring's. Hull force
    limited: its series is the machine's force less gear^2 (J a + b v + K x), and it holds the
    limit, on the collocation grid and between its points."""
    wave = waves.regular(2.0, 8.0)
    free = electrical_bound(plants["K"], wave, omega_max=6.0)
    limit = 0.5 * free.mechanical.max_force
    a = electrical_bound(plants["K"], wave, force_max=limit, omega_max=6.0)
    b = electrical_bound(plants["mooring"], wave, force_max=limit, omega_max=6.0)
    assert a.electrical_W < 0.99 * free.electrical_W
    assert a.electrical_W == pytest.approx(b.electrical_W, rel=1e-5)
    hull = electrical_bound(plants["K_hull"], wave, force_max=limit, omega_max=6.0)
    assert abs(hull.electrical_W / a.electrical_W - 1) > 1e-3
    m = hull.mechanical
    assert m.max_force == pytest.approx(limit, rel=1e-4)
    machine = (m.force_coefficients[None, :] * np.exp(-1j * np.outer(m.time, m.omega))).sum(1).real
    n = m.time.size
    spectrum = np.fft.rfft(m.velocity)
    accel = np.fft.irfft(1j * 2 * np.pi * np.fft.rfftfreq(n, m.period / n) * spectrum, n)
    expected = machine - GEAR ** 2 * (J * accel + B * m.velocity + K * m.position)
    np.testing.assert_allclose(m.force, expected, atol=1e-6 * limit)
    # between the collocation points (analysis.dense) the same force, not the machine's
    assert abs(np.max(np.abs(machine)) / limit - 1) > 0.05
    assert np.max(np.abs(m.force)) <= m.max_force_dense < 1.03 * limit
