"""Sweeps with the nonlinear plant where the linear range is left (--nonlinear invalid): a sea
whose linear run is INVALID for its motions runs again on the nonlinear plant, and only that
sea; its record is then exactly what a plain sweep of the nonlinear scene gives for it.

The catalogue sphere (models/sphere.toml, R = 5 m, heave, PTO damper 1e6 N s/m): in Hs 2 m,
Tp 9 s its relative heave stays inside the draft, in Hs 8 m it does not (3.66 m against 3.33) (the check of
mbcontrol.analysis.validity). References: the linear sweep (the sea left alone must not
change) and the sweep of the scene with the nonlinear pair itself (--nonlinear always).
"""
from __future__ import annotations

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest

from mbcontrol.errors import SceneError
from mbcontrol.plant import with_nonlinear_pressure
from mbcontrol.scene import load_scene
from mbcontrol.studies.sweep import grid, sweep

SEAS = grid([2.0, 8.0], [9.0])
RUN = dict(duration=120.0, dt=0.05, progress=False, workers=0,
           params={"pto__damping": 1e6})


@pytest.fixture(scope="module")
def sweeps():
    return {mode: sweep("sphere", SEAS, nonlinear=mode, **RUN)
            for mode in ("scene", "invalid", "always")}


def test_only_the_sea_that_leaves_the_linear_range_runs_nonlinear(sweeps):
    linear, _ = sweeps["scene"]
    mixed, summary = sweeps["invalid"]
    assert bool(linear["valid"].isel(sea=0, seed=0)) and not bool(linear["valid"].isel(sea=1, seed=0))
    assert "linear hydrodynamics do not hold" in str(linear["invalid_reasons"].isel(sea=1, seed=0).values)
    assert mixed["nonlinear_model"].values[:, 0].tolist() == [False, True]
    assert bool(mixed["valid"].isel(sea=1, seed=0))          # a number where there was none
    # the calm sea is untouched: the same record as the linear sweep's
    assert float(mixed["mean_power_W"].isel(sea=0, seed=0)) == float(linear["mean_power_W"].isel(sea=0, seed=0))
    rows = summary["seas"]
    assert [r["nonlinear_cases"] for r in rows] == [0, 1]
    assert rows[0]["linear_mean_power_W"] is None
    assert rows[1]["linear_mean_power_W"] == pytest.approx(
        float(linear["mean_power_W__unchecked"].isel(sea=1, seed=0)), rel=1e-12)
    assert summary["provenance"]["nonlinear"] == "invalid"
    # the JSON keys are there when no sea leaves the range too
    _, calm = sweep("sphere", grid([2.0], [9.0]), nonlinear="invalid", **RUN)
    assert calm["seas"][0]["nonlinear_cases"] == 0 and calm["seas"][0]["linear_mean_power_W"] is None


def test_the_escalated_sea_is_the_nonlinear_plants_own_run(sweeps):
    mixed, _ = sweeps["invalid"]
    nonlinear, _ = sweeps["always"]
    assert float(mixed["mean_power_W"].isel(sea=1, seed=0)) == pytest.approx(
        float(nonlinear["mean_power_W"].isel(sea=1, seed=0)), rel=1e-12)
    # the nonlinear plant absorbs less than linear theory claims in the steep sea (the
    # buoyancy lost as the sphere leaves the water), and about the same in the small one
    linear, _ = sweeps["scene"]
    ratio = float(nonlinear["mean_power_W"].isel(sea=1, seed=0)) / float(
        linear["mean_power_W__unchecked"].isel(sea=1, seed=0))
    assert ratio < 0.97
    assert float(nonlinear["mean_power_W"].isel(sea=0, seed=0)) == pytest.approx(
        float(linear["mean_power_W"].isel(sea=0, seed=0)), rel=0.03)


def test_a_scene_without_surfaces_is_refused_naming_the_body():
    sphere = load_scene("sphere")               # its body without [body.geometry]
    bare = dataclasses.replace(sphere, bodies=tuple(dataclasses.replace(b, geometry=None)
                                                    for b in sphere.bodies))
    with pytest.raises(SceneError, match="body 'sphere'.*geometry"):
        with_nonlinear_pressure(bare)


def test_cli_flag_and_json_contract(tmp_path):
    out = subprocess.run([sys.executable, "-m", "mbcontrol", "sweep", "sphere", "--hs", "2",
                          "8", "--tp", "9", "--duration", "120", "--dt", "0.05", "--param",
                          "pto__damping=1e6", "--nonlinear", "invalid", "--workers", "0",
                          "--json"], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    summary = json.loads(out.stdout)
    assert [r["nonlinear_cases"] for r in summary["seas"]] == [0, 1]
    assert np.isfinite(summary["seas"][1]["mean_power_W"])
