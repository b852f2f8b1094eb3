"""Farms (mbcontrol.studies.farm, `sweep --isolated`): the q-factor of an array of one is 1, an
axisymmetric float absorbs the same power from every heading, and the coupled farm's simulated
power equals the frequency-domain solution computed here from the BEM data alone."""
import json

import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.analysis.metrics import pto_metrics
from mbcontrol.cli import main
from mbcontrol.hydro import matrix
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate
from mbcontrol.studies.farm import device_count, farm_sweep
from mbcontrol.studies.sweep import grid

SHORT = dict(duration=40.0, dt=0.02, workers=0, progress=False)


def test_an_array_of_one_has_q_one_and_no_preferred_heading():
    ds, summary = farm_sweep("array_grid", grid([0.04], [1.0, 1.3]), scene_params={"n": 1},
                             isolated={"n": 1}, vary={"direction": [0.0, 45.0]}, **SHORT)
    q = np.array(summary["farm"]["q_factor"])
    assert q.shape == (2, 2) and np.allclose(q, 1.0, rtol=0, atol=1e-12)
    power = ds["mean_power_W"].mean("seed").values        # (sea, direction)
    assert np.all(power > 0)
    # a vertical cylinder: the two headings' excitation differs only by the mesh's discretisation
    assert np.allclose(power[:, 0], power[:, 1], rtol=2e-3)
    assert summary["farm"]["devices"] == summary["farm"]["isolated_devices"] == 1


def test_sweep_isolated_json_contract(capsys, tmp_path):
    seas = tmp_path / "seas.csv"
    seas.write_text("Hm0,Tp,weights\n0.03,1.0,0.6\n0.05,1.3,0.4\n")
    code = main(["sweep", "array_grid", "--scene-param", "n=1", "--isolated", "n=1", "--seas", str(seas),
                 "--duration", "30", "--dt", "0.02", "--workers", "0", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    s = json.loads(out)
    assert set(s["farm"]) == {"devices", "isolated_devices", "isolated_scene_params", "q_factor",
                              "annual_energy_isolated_MWh", "q_annual", "isolated_invalid_cases",
                              "isolated_wall_time_s"}
    assert s["farm"]["q_annual"] == pytest.approx(1.0, abs=1e-12)
    assert s["annual_energy_MWh"] == pytest.approx(s["farm"]["annual_energy_isolated_MWh"], rel=1e-12)
    assert all(row["q_factor"] == pytest.approx(1.0, abs=1e-12) for row in s["seas"])


def test_coupled_farm_power_equals_the_frequency_domain_solution():
    """Four coupled floats (2 x 2, 1 m apart) in a regular wave: each PTO's mean power from the
    time-domain plant (radiation fit, Cummins) against P_i = ½ c ω² |X_i|² with
    [-ω²(M + A(ω)) - iω(B(ω) + c) + K] X = F(ω) from the BEM data (no fit, no time stepping)."""
    scene = load_scene("array_grid", {"n": 2})
    plant = build_plant(scene)
    assert device_count("array_grid", {"n": 2}) == 4
    data, dofs = plant.hydro.data, list(plant.hydro.dofs)
    w_all = data["omega"].values
    k = int(np.argmin(np.abs(w_all - 5.0)))
    w = float(w_all[k])                                    # a BEM frequency: no interpolation
    c = scene.ptos[0].damping
    A = matrix(data["added_mass"], dofs)[k]
    B = matrix(data["radiation_damping"], dofs)[k]
    K = matrix(data["hydrostatic_stiffness"], dofs)
    F = data["excitation_force"].sel(wave_direction=0.0, influenced_dof=dofs).isel(omega=k).values
    M = np.diag([b.mass for b in scene.bodies])
    amplitude = 0.01
    X = np.linalg.solve(-w**2 * (M + A) - 1j * w * (B + c * np.eye(4)) + K, F * amplitude)
    expected = 0.5 * c * w**2 * np.abs(X) ** 2
    period = 2 * np.pi / w
    wave = waves.regular(2 * amplitude, period, direction=0.0)
    out = simulate(plant, wave, duration=40 * period, dt=period / 100, method="rk4")
    start = 25 * period
    got = np.array([pto_metrics(out, p, start=start, end=start + 15 * period)["mean_power_W"]
                    for p in scene.ptos])
    assert np.all(np.abs(got / expected - 1) < 0.02), (got, expected)
    # the interaction is real: the floats alone would absorb measurably different power
    alone = 0.5 * c * w**2 * np.abs(F * amplitude / (-w**2 * (np.diag(M) + np.diag(A))
                                                     - 1j * w * (np.diag(B) + c) + np.diag(K))) ** 2
    assert np.max(np.abs(alone / expected - 1)) > 0.05


def _fd_power(n, beta):
    """(ω, total PTO power per unit wave amplitude²) of the n x n grid in regular waves of heading
    beta, from its BEM data alone (frequency-domain solution, the scene's PTO damping)."""
    scene = load_scene("array_grid", {"n": n})
    plant = build_plant(scene)
    data, dofs = plant.hydro.data, list(plant.hydro.dofs)
    w = data["omega"].values
    A, B = matrix(data["added_mass"], dofs), matrix(data["radiation_damping"], dofs)
    K = matrix(data["hydrostatic_stiffness"], dofs)
    F = data["excitation_force"].sel(wave_direction=beta, influenced_dof=dofs).values
    M, c, eye = np.diag([b.mass for b in scene.bodies]), scene.ptos[0].damping, np.eye(len(dofs))
    P = [np.sum(0.5 * c * wk**2 * np.abs(np.linalg.solve(-wk**2 * (M + A[k]) - 1j * wk * (B[k] + c * eye)
                                                          + K, F[k])) ** 2) for k, wk in enumerate(w)]
    return w, np.array(P)


def test_q_factor_follows_the_interference_trend():
    """Wave-farm literature (Budal 1977, Falnes 1980, Babarit 2010): q -> 1 in long waves (the
    floats see the same wave and radiate little), then oscillates about 1 as kd grows, above 1
    (constructive interference) and below it (shading) in turn. Here for 2 x 2 floats 1 m apart,
    head seas, the scene's passive damping."""
    w, farm = _fd_power(2, 0.0)
    _, alone = _fd_power(1, 0.0)
    q, kd = farm / (4 * alone), w**2 / 9.81 * 1.0
    assert np.all(np.abs(q[kd < 0.4] - 1) < 0.01)
    band = (kd > 2) & (kd < 12)           # below the mesh limit of the 80 mm panels
    assert q[band].max() > 1.2 and q[band].min() < 0.8
    crossings = np.count_nonzero(np.diff(np.sign(q[band] - 1)))
    assert crossings >= 3
