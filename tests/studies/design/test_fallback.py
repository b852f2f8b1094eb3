"""Per-sea design in a storm (issue 58, item 6): the tuned law's failure falls back to the
saturated damper, which is checked against the controllers' own frequency-domain statistics
(controllers.impedance.fd_statistics, a separate code path) and a closed-loop simulation; a
sea no law within the PTO's limits serves raises NoLawForSea with the numbers."""
import dataclasses
import math
import re

import numpy as np
import pytest
from scipy.optimize import brentq

from controllers.impedance import fd_statistics, intrinsic_impedance
from mbcontrol import waves
from mbcontrol.controllers import make
from mbcontrol.errors import ControllerError
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.studies.design import NoLawForSea, design_for_sea, tune, tune_with_fallback
from mbcontrol.studies.design.fallback import (coulomb_limit, damping_for, equivalent_damping)

STORM = (6.13, 11.86)      # PacWave's cluster 12: the sphere's tuned damper fails there today


@pytest.fixture(scope="module")
def sphere():
    return build_plant(load_scene("sphere"))


def _sea(plant, hs, tp, duration=300.0):
    omega = plant.hydro.omega
    return waves.irregular(hs, tp, seed=0, duration=duration,
                           data_band=(float(omega[0]), float(omega[-1])))


def test_equivalent_damping_against_sampled_averages():
    """Booton's gain c erf(F / (sqrt 2 c s)) equals E[v sat(c v)] / E[v^2] over 2e6 Gaussian
    samples (standard error ~1e-3), and the describing function equals the same average over
    one period of a sinusoid; damping_for inverts it; the Coulomb limit is its c -> inf."""
    rng = np.random.default_rng(1)
    s, f_max = 1.3, 2.0e6
    v = rng.normal(0.0, s, 2_000_000)
    for c in (5e5, 1.5e6, 4e6):
        sampled = np.mean(v * np.clip(c * v, -f_max, f_max)) / np.mean(v ** 2)
        assert equivalent_damping(c, f_max, s) == pytest.approx(sampled, rel=4e-3)
        assert damping_for(float(equivalent_damping(c, f_max, s)), f_max, s) == \
            pytest.approx(c, rel=1e-8)
        t = np.linspace(0, 2 * np.pi, 200_001)[:-1]
        u = s * np.sin(t)
        regular = np.mean(u * np.clip(c * u, -f_max, f_max)) / np.mean(u ** 2)
        assert equivalent_damping(c, f_max, s, regular=True) == pytest.approx(regular, rel=1e-6)
    assert equivalent_damping(1e15, f_max, s) == pytest.approx(coulomb_limit(f_max, s), rel=1e-6)
    with pytest.raises(ControllerError, match="at most"):
        damping_for(1.01 * float(coulomb_limit(f_max, s)), f_max, s)


def test_storm_sea_falls_back_to_the_saturated_damper(sphere):
    """Sphere (force_max 2 MN, stroke_max 4 m), Hs 6.13 m, Tp 11.86 s: the tuner raises (no
    unclipped damper meets both limits: confirmed on a grid of fd_statistics), the design
    falls back to the clipped damper and says so; its equivalent damper keeps the stroke peak
    within 4 m by fd_statistics, which gives the same power and stroke as the fallback's own
    numbers, and a 300 s run clips the force at 2 MN with the stroke inside 4 m and the power
    within 5 % of the prediction (measured: 378 kW against 364 kW, max stroke 3.09 m)."""
    wave = _sea(sphere, *STORM)
    pto = sphere.scene.ptos[0]
    with pytest.raises(ControllerError):
        tune(sphere, wave, "passive", pto, True, None, [])
    Z, F = intrinsic_impedance(sphere, wave.omega, pto=pto.name, direction=wave.direction)
    grid = fd_statistics(Z, F, wave, np.geomspace(1e3, 1e9, 2000), 0.0)
    assert not np.any((grid["force_peak"] <= pto.force_max)
                      & (grid["stroke_peak"] <= pto.stroke_max))
    for name in ("passive", "reactive"):
        d = design_for_sea(sphere, wave, name)
        assert d["fell_back"] and d["fallback"]["from"] == name
        assert d["fallback"]["to"] == "passive, saturated at force_max"
        assert d["controller"] == "passive" and d["settings"]["force_max"] == pto.force_max
        assert "no damper meets both limits" in d["fallback"]["why"]
        assert any(n.startswith("FELL BACK") for n in d["notes"])
    law = tune_with_fallback(sphere, wave, "passive", pto, [])
    sat = law["tuner"]["saturated"]
    st = fd_statistics(Z, F, wave, sat["equivalent_damping"], 0.0)
    assert float(st["stroke_peak"]) <= pto.stroke_max
    assert float(st["stroke_peak"]) == pytest.approx(sat["stroke_peak_m"], rel=1e-9)
    assert float(st["power_W"]) == pytest.approx(law["predicted"], rel=1e-9)
    # the equivalent force is within what a clip at force_max can give (its Coulomb limit)
    assert float(st["force_std"]) < math.sqrt(2 / math.pi) * pto.force_max
    from mbcontrol.analysis import pto_metrics
    from mbcontrol.sim import simulate
    run = simulate(sphere, wave, duration=300.0, dt=0.05,
                   controller=make("passive", **law["parameters"]))
    m = pto_metrics(run, pto)
    assert m["max_force"] <= pto.force_max * (1 + 1e-9)
    assert m["max_stroke"] <= pto.stroke_max
    assert m["mean_power_W"] == pytest.approx(law["predicted"], rel=0.05)


def test_a_sea_no_law_serves_raises_with_the_numbers(sphere):
    """force_max 0.5 MN in the same storm: even a drive at +-0.5 MN throughout leaves the
    stroke past 4 m. Checked on fd_statistics: at the damper whose force std is the Coulomb
    limit's sqrt(2 / pi) F_max the stroke peak is past stroke_max (5.49 m)."""
    wave = _sea(sphere, *STORM)
    pto = dataclasses.replace(sphere.scene.ptos[0], force_max=5e5)
    with pytest.raises(NoLawForSea, match="survival") as caught:
        tune_with_fallback(sphere, wave, "reactive", pto, [])
    laws = [a["law"] for a in caught.value.attempts]
    assert laws == ["reactive", "passive", "passive, saturated at force_max"]
    Z, F = intrinsic_impedance(sphere, wave.omega, pto=pto.name, direction=wave.direction)
    target = math.sqrt(2 / math.pi) * pto.force_max
    c = math.exp(brentq(lambda x: float(fd_statistics(Z, F, wave, math.exp(x), 0.0)
                                        ["force_std"]) - target, math.log(1e3), math.log(1e9)))
    stroke = float(fd_statistics(Z, F, wave, c, 0.0)["stroke_peak"])
    assert stroke > pto.stroke_max
    # the message's figure: at the grid's damper nearest COULOMB_SHARE of the limit, a little
    # lighter than the limit itself, so a little more stroke (measured 5.53 against 5.49 m)
    said = float(re.search(r"stroke peak at ([0-9.]+) m", str(caught.value)).group(1))
    assert stroke <= said <= 1.02 * stroke


def test_a_sea_the_tuner_serves_does_not_fall_back(sphere):
    """Hs 2 m, Tp 9 s: the tuned law as it is, fell_back false."""
    d = design_for_sea(sphere, _sea(sphere, 2.0, 9.0), "reactive")
    assert d["fell_back"] is False and d["fallback"] is None and d["controller"] == "reactive"
