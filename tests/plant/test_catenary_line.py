"""Catenary moorings in a scene and in the plant: forces, stiffness, tension output, errors.

References: the exact quasi-static solution of mbcontrol.plant.catenary (itself checked against
MoorPy and closed forms in test_catenary.py), mapped by hand to the body; and its stiffness
from implicit differentiation against the plant's exact Jacobian.
"""
import tomllib
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.analysis import linearize
from mbcontrol.errors import SceneError
from mbcontrol.plant import build_plant, catenary_line
from mbcontrol.scene import parse_scene

SLIDER = """
name = "moored_slider"
[[body]]
name = "buoy"
mass = 50.0
inertia = [1.0, 1.0, 1.0]
cog = [0.0, 0.0, 0.0]
hydro = false
[[joint]]
name = "surge"
type = "prismatic"
parent = "ground"
child = "buoy"
point = [0.0, 0.0, 0.0]
axis = [1.0, 0.0, 0.0]
[[mooring]]
name = "bow"
type = "catenary"
body = "buoy"
point = [-0.5, 0.0, 0.2]
anchor = [-ANCHOR_X, 0.0, 10.0]
length = 15.0
EA = 2e5
weight = 5.0
[[mooring]]
name = "stern"
type = "catenary"
body = "buoy"
point = [0.5, 0.0, 0.2]
anchor = [7.5, 0.0, 10.0]
length = 15.0
EA = 2e5
weight = 5.0
"""


def _plant():
    # symmetric lines: rest is an equilibrium along the slider (their vertical pull is taken
    # by the joint)
    text = SLIDER.replace("ANCHOR_X", "7.5")
    return build_plant(parse_scene(tomllib.loads(text), Path("slider.toml")))


def test_force_and_tension_match_the_exact_lines():
    plant = _plant()
    lines = [catenary_line(m) for m in plant.scene.moorings]
    x = plant.x0()
    x[plant.states.index("surge")] = 0.3                       # buoy moved 0.3 m forward
    y = np.asarray(plant.h(x, [], [], plant.p0)).ravel()
    accel = np.asarray(plant.f(x, [], [], plant.p0)).ravel()[plant.states.index("surge__vel")]
    exact = [line.force(np.add(line.fairlead, [0.3, 0.0, 0.0])) for line in lines]
    # slider along x: the lines' x forces over the mass (table + Newton: ~1e-9 of the tension)
    assert accel == pytest.approx(sum(f[0] for f, _ in exact) / 50.0, rel=1e-7)
    for line, (_, tension) in zip(lines, exact):
        assert y[plant.outputs.index(f"{line.name}__tension")] == pytest.approx(tension, rel=1e-7)
    assert plant.units("bow__tension") == "N"


def test_surge_stiffness_is_the_lines_stiffness():
    plant = _plant()
    sys = linearize(plant)
    A = np.asarray(sys.A)
    i, j = plant.states.index("surge__vel"), plant.states.index("surge")
    k_lines = sum(catenary_line(m).stiffness()[0, 0] for m in plant.scene.moorings)
    assert k_lines > 0
    # implicit differentiation of the exact solve vs CasADi's Jacobian of table + Newton
    assert -A[i, j] * 50.0 == pytest.approx(k_lines, rel=1e-6)


def test_anchor_beyond_reach_names_the_mooring():
    text = SLIDER.replace("ANCHOR_X", "40.0")
    with pytest.raises(SceneError, match=r"slider\.toml: mooring\[0\]\.anchor: mooring 'bow': anchor "
                                         r"\(-40, 0, 10\) is \d+ m from the fairlead, beyond the line's reach"):
        parse_scene(tomllib.loads(text), Path("slider.toml"))


def test_slack_line_and_envelope_are_reported():

    from mbcontrol.sim import simulate

    plant = _plant()
    x0 = plant.x0()
    x0[plant.states.index("surge")] = 2.5     # beyond the table's ±1.96 m; stern line goes slack
    with pytest.warns(RuntimeWarning) as caught:
        ds = simulate(plant, duration=2.0, dt=0.01, x0=x0)
    text = " ".join(str(w.message) for w in caught)
    assert "mooring 'stern' was slack at t = 0 s" in text
    assert "mooring 'bow': the fairlead left the force table's envelope" in text
    report = ds.attrs["moorings"]
    assert report["stern"]["least_stretched"]["status"] == "slack"
    assert report["bow"]["most_stretched"]["status"] == "seabed contact"
    assert report["bow"]["left_envelope"] and report["bow"]["tension_max_N"] > report["bow"]["tension_min_N"]
    assert ds["bow__span"].attrs["units"] == "m"
