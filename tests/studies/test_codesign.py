"""`mbcontrol codesign` (studies.codesign): the optimiser against the grid's best, a study
resumed after an interruption, a geometry met twice solved once, and the --json contract."""
import json
from pathlib import Path

import numpy as np
import pytest

from drivetrain_scenes import DRIVETRAIN, catalogue_copy
from mbcontrol.cli import main
from mbcontrol.studies.codesign import Spec, codesign

WAVE = {"kind": "regular", "height": 2.0, "period": 9.0}

DRUM = """name = "drum"
[parameters]
r = 1.0
[water]
rho = 1025.0
[hydro]
omega = { min = 0.4, max = 3.0, n = 8 }
panel_size = 0.6
dofs = ["Heave"]
[[body]]
name = "drum"
mass = "displaced"
inertia = [1e4, 1e4, 1e4]
cog = [0.0, 0.0, 0.0]
geometry = { type = "revolution", profile = [["{r}", -0.5], ["{r}", 1.0], [0.0, 1.0]] }
[[joint]]
name = "heave"
type = "prismatic"
parent = "ground"
child = "drum"
point = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
[[pto]]
name = "pto"
joint = "heave"
force_max = 2e4
"""


@pytest.fixture(scope="module")
def geared(tmp_path_factory):
    """The sphere with a drivetrain whose gear is a scene parameter: the electrical bound has
    an interior optimum where the reflected rotor inertia (gear^2 x 500 kg m^2) tunes heave."""
    text = DRIVETRAIN.format(gear='"{gear}"', kt=6.7, resistance="0.5 ohm", inertia=500.0,
                             friction=1.0) + "\n[parameters]\ngear = 12.0\n"
    return str(catalogue_copy(tmp_path_factory.mktemp("gear"), "sphere", "gear", text))


def test_the_optimiser_finds_the_grids_best(geared):
    spec = Spec(model=geared, objective="electrical_bound", wave=WAVE)
    grid = codesign(spec, vary={"gear": list(np.arange(25.0, 61.0, 1.0))})
    found = codesign(spec, optimize={"gear": (10.0, 160.0)}, max_evals=40)
    assert found["search"].startswith("bounded Brent") and found["computed"] <= 40
    assert found["best"]["objective"] >= grid["best"]["objective"]      # a finer optimum
    assert abs(found["best"]["params"]["gear"] - grid["best"]["params"]["gear"]) < 1.0
    assert grid["best"]["objective"] > 2 * max(p["objective"] for p in grid["points"]
                                               if abs(p["params"]["gear"] - 49) > 8)


def test_an_interrupted_study_resumes(geared, tmp_path, monkeypatch):
    import mbcontrol.studies.codesign.study as study
    spec = Spec(model=geared, objective="electrical_bound", wave=WAVE)
    real, seen = study.evaluate, []

    def interrupted(spec, point, roles):
        if len(seen) == 2:
            raise KeyboardInterrupt           # the user's ^C: not a failed point
        seen.append(point)
        return real(spec, point, roles)
    monkeypatch.setattr(study, "evaluate", interrupted)
    with pytest.raises(KeyboardInterrupt):
        codesign(spec, vary={"gear": [30.0, 40.0, 50.0]}, store=tmp_path)
    assert len(list((tmp_path / "points").glob("*.json"))) == 2
    monkeypatch.setattr(study, "evaluate", real)
    again = codesign(spec, vary={"gear": [30.0, 40.0, 50.0]}, store=tmp_path)
    assert (again["computed"], again["reused"]) == (1, 2)
    assert [p["params"]["gear"] for p in again["points"]] == [30.0, 40.0, 50.0]


def test_a_geometry_met_again_is_not_solved_again(tmp_path, monkeypatch):
    """Two studies without a store share only the BEM cache (by content): the drum of radius
    1 m, solved in the first, is not solved in the second; the new radius is."""
    import mbcontrol.hydro.bem as bem
    import mbcontrol.hydro.model as model
    scene = tmp_path / "drum.toml"
    scene.write_text(DRUM)
    monkeypatch.setattr(model, "cache_dir", lambda: tmp_path / "cache")
    real, solves = bem._solve, []

    def counted(*args, **kwargs):
        solves.append(1)
        return real(*args, **kwargs)
    monkeypatch.setattr(bem, "_solve", counted)
    spec = Spec(model=str(scene), objective="mechanical_bound",
                wave={"kind": "regular", "height": 1.0, "period": 6.0})
    first = codesign(spec, vary={"r": [1.0]})
    once = len(solves)
    second = codesign(spec, vary={"r": [1.0, 1.2]})
    assert once >= 1 and len(solves) == 2 * once
    assert second["points"][0]["objective"] == pytest.approx(first["points"][0]["objective"])
    assert all(p["valid"] for p in second["points"])


def test_json_contract_and_figure(geared, tmp_path, capsys):
    png = tmp_path / "codesign.png"
    code = main(["codesign", geared, "--vary", "gear=40,50", "--objective", "electrical_bound",
                 "--per", "rated_force", "--wave", "regular", "--height", "2", "--period", "9",
                 "--plot", str(png), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert set(out) >= {"points", "best", "objective_name", "provenance"}
    assert set(out["points"][0]) >= {"params", "objective", "valid", "wall_s"}
    assert out["objective_name"] == "electrical_bound per rated_force"
    kn = out["points"][0]["details"]["cost_proxy"]["value"]
    assert kn == pytest.approx(2000.0)                  # the sphere's 2 MN in kN
    assert out["best"]["params"] == {"gear": 50.0} and Path(png).stat().st_size > 10_000
    code = main(["codesign", geared, "--vary", "gear=x", "--wave", "regular", "--height", "2",
                 "--period", "9"])
    assert code == 1 and "--vary gear=x: expected NAME=v1,v2" in capsys.readouterr().err
