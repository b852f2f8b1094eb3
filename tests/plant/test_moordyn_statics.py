"""MoorDyn lines in the linear model (mbcontrol.plant.moordyn_statics, moordyn_loads): the
lines' pull and stiffness at rest, and the rest they move the plant to.

References, independent of the code under test:
- MoorPy's quasi-static model of the same MoorDyn file (elastic catenaries with seabed
  contact, its free buoys equilibrated) and its analytic coupled stiffness
  (System.getCoupledStiffnessA), for RM3's three chains with subsurface buoys;
- a conservative mooring's stiffness is symmetric: J's asymmetry measures its noise;
- hydrostatics: at the moored rest of the heave-only sphere the lines' vertical pull equals
  rho g A_wp times the sinkage.
"""
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.plant import build_plant
from mbcontrol.plant.process import assemble_plant
from mbcontrol.scene import TO_MOORDYN
from mbcontrol.scene.moordyn_file import read_moordyn, run_text

pytest.importorskip("moordyn")
ROOT = Path(__file__).resolve().parents[2]
SPHERE = ROOT / "tests" / "sim" / "moordyn" / "sphere_moored.toml"


def _moorpy(lines, points, tmp_path, monkeypatch):
    """MoorPy's (pull (3, n), stiffness -dF/dP (3n, 3n)) at the Coupled points, n-frame."""
    moorpy = pytest.importorskip("moorpy")
    monkeypatch.setenv("PYTHONBREAKPOINT", "0")       # MoorPy calls breakpoint() on odd input
    path = tmp_path / "lines.txt"
    path.write_text(run_text(read_moordyn(lines), points.T * TO_MOORDYN, {}))
    system = moorpy.System(file=str(path))
    system.initialize()
    assert system.solveEquilibrium(tol=1e-4)
    flip = np.tile(TO_MOORDYN, points.shape[1])                 # MoorPy is z-up, as MoorDyn
    K = flip[:, None] * system.getCoupledStiffnessA(lines_only=True) * flip[None, :]
    pull = np.array([p.getForces(lines_only=True) for p in system.pointList if p.type == -1])
    return pull.T * TO_MOORDYN[:, None], K


@pytest.mark.parametrize("scene, lines, pull_rtol, entry_tol, diagonal_rtol", [
    # RM3's statics ship with the catalogue (models/rm3_moored_lines.statics.json, made by
    # this code: models/generate_hydro.py --ship-fits); 15 and 5 lumped segments: measured,
    # the pulls 0.31 %, J 2.4 % of its largest entry, its diagonal 8.7 % (the transverse
    # entries, tension over length, small)
    ("rm3_moored", ROOT / "models" / "rm3_moored_lines.txt", 0.005, 0.03, 0.10),
    # the sphere's are made here; 10 segments of 16 m: the pulls 0.67 %, J 5.8 % of its
    # largest entry, its diagonal 8.3 % low (MoorDyn alone: 3.1 % low in tension at 10
    # segments, 0.6 % at 40, whose J is MoorPy's to 0.38 %, too slow to make here)
    (str(SPHERE), SPHERE.with_name("sphere_lines.txt"), 0.01, 0.07, 0.10)])
def test_the_lines_pull_and_stiffness_are_moorpys(scene, lines, pull_rtol, entry_tol,
                                                  diagonal_rtol, tmp_path, monkeypatch):
    """F_0 and J = dF/dP at the Coupled points against MoorPy's quasi-static model."""
    g = assemble_plant(scene, radiation=False).moordyn[0]
    pull, K = _moorpy(lines, g.rest, tmp_path, monkeypatch)
    np.testing.assert_allclose(g.pull, pull, rtol=pull_rtol, atol=50.0)
    scale = np.max(np.abs(K))
    assert np.max(np.abs(-g.stiffness - K)) < entry_tol * scale
    np.testing.assert_allclose(np.diag(-g.stiffness), np.diag(K), rtol=diagonal_rtol)
    # symmetric to the noise of the settled forces (measured 0.21 % and 0.09 %)
    assert np.max(np.abs(g.stiffness - g.stiffness.T)) < 0.005 * scale


def test_the_moored_rest_balances_the_lines_pull_with_hydrostatics():
    """The heave-only sphere: its rest sinks until rho g pi R^2 dz holds the lines' vertical
    pull there, which the plant's quasi-static part gives at the moved fairleads."""
    plant = build_plant(str(SPHERE))
    rest = plant.x0()
    sink = rest[plant.states.index("heave")]
    g = plant.moordyn[0]
    moved = g.rest + np.array([[0.0], [0.0], [sink]])
    pull = g.pull + (g.stiffness @ (moved - g.rest).T.ravel()).reshape(-1, 3).T
    stiffness = 1000.0 * 9.81 * math.pi * 5.0 ** 2              # the scene's water, R = 5 m
    # the hydro data's waterplane is its mesh's: measured 0.011 % off pi R^2
    assert sink == pytest.approx(pull[2].sum() / stiffness, rel=1e-3)
    assert 0.15 < sink < 0.18                                  # 3 x 42.8 kN down
    assert plant.notes["moored_rest"] == {"heave": pytest.approx(sink)}
    # rest is an equilibrium of the plant: its accelerations vanish there
    xdot = np.asarray(plant.f(rest, np.zeros(len(plant.inputs)),
                              np.zeros(len(plant.disturbances)), plant.p0)).ravel()
    assert np.max(np.abs(xdot)) < 1e-9


def test_the_statics_served_are_recorded_only_for_a_caller_that_asks():
    """generate_hydro --ship-fits records the statics the catalogue's plants ask for: RM3's,
    from the file shipped beside its lines; with no recorder active nothing is kept."""
    from mbcontrol.plant import recording_served_statics, shipped_statics
    lines = ROOT / "models" / "rm3_moored_lines.txt"
    with recording_served_statics() as served:
        assemble_plant("rm3_moored", radiation=False)
    assert {Path(file).name for file, _, _ in served} == {lines.name}   # twice, one key
    shipped = json.loads(shipped_statics(lines).read_text())
    assert all(shipped[key] == statics for _, key, statics in served)
    n = len(served)
    assemble_plant("rm3_moored", radiation=False)     # nobody records: nothing kept
    assert len(served) == n
