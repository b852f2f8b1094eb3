"""`mbcontrol codesign` (studies.codesign): the optimiser against the grid's best, a study
resumed after an interruption, a geometry met twice solved once, and the --json contract."""
import json
from pathlib import Path

import numpy as np
import pytest

from tests.helpers.drivetrain_scenes import DRIVETRAIN, catalogue_copy
from mbcontrol.cli import main
from mbcontrol.studies.codesign import Spec, codesign
from mbcontrol.studies.codesign.objectives import evaluate

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
    import mbcontrol.hydro.bem.solve as bem
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


def test_a_sites_bound_is_its_seas_conjugate_bounds_weighted(tmp_path):
    """With seas instead of a wave, a bound objective is the site's annual energy of the
    bound. Without force or stroke limits each sea's QP optimum is the closed-form complex-
    conjugate bound sum a_k^2 |E_k|^2 / (8 Re Z_k); weighted by hand it gives the same MWh."""
    from mbcontrol.analysis.bounds import complex_conjugate_bound
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import load_scene
    from mbcontrol.studies.sweep.runner import sea_wave
    from mbcontrol.waves.sites import read_seas
    scene = catalogue_copy(tmp_path, "sphere", "free", "")
    scene.write_text("\n".join(line for line in scene.read_text().splitlines()
                               if not line.startswith(("force_max", "stroke_max"))))
    seas = tmp_path / "seas.csv"
    seas.write_text("Hm0,Tp,weights\n1.0,7.0,0.5\n2.0,9.0,0.3\n3.0,11.0,0.2\n")
    spec = Spec(model=str(scene), objective="mechanical_bound", seas=str(seas), duration=120.0)
    got = evaluate(spec, {}, {})
    plant = build_plant(load_scene(str(scene)))
    by_hand = sum(sea.weight * complex_conjugate_bound(plant, sea_wave(plant, sea, 120.0)).power
                  for sea in read_seas(seas)) * 8766 / 1e6
    assert got["valid"] and got["objective"] == pytest.approx(by_hand, rel=1e-6)
    assert len(got["details"]["mean_power_W"]) == 3
    with pytest.raises(ValueError, match="a wave or --seas, not both"):
        Spec(model=str(scene), objective="mechanical_bound", seas=str(seas), wave=WAVE)
    with pytest.raises(ValueError, match="needs a wave"):
        Spec(model=str(scene), objective="controller", seas=str(seas), controller="passive")


def test_against_a_second_objective_compares_the_optima(geared, tmp_path, capsys):
    """--against evaluates the same points under a second objective. The electrical bound
    is the mechanical bound less the machine's losses, so it is the lower curve at every
    gear; the verdict compares the optima with error bars (none for bounds)."""
    png = tmp_path / "against.png"
    code = main(["codesign", geared, "--vary", "gear=20,35,50,80", "--objective",
                 "electrical_bound", "--against", "mechanical_bound", "--wave", "regular",
                 "--height", "2", "--period", "9", "--plot", str(png), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0 and out["against"]["objective_name"] == "mechanical_bound"
    for mine, theirs in zip(out["points"], out["against"]["points"]):
        assert mine["params"] == theirs["params"] and mine["objective"] < theirs["objective"]
    shares = [s["share"] for s in out["comparison"]["share_of_other"]]
    assert all(0 < s < 1 for s in shares)
    verdict = out["comparison"]["verdict"]
    same = out["best"]["params"] == out["against"]["best"]["params"]
    assert verdict == ("same optimum" if same else "moved")    # no error bars: any gap counts
    assert png.stat().st_size > 10_000


def test_the_verdict_reads_the_error_bars():
    from mbcontrol.studies.codesign.compare import compare_optima

    def study(name, values, errors):
        points = [{"params": {"r2": r}, "objective": v, "valid": True, "error_95": e}
                  for r, v, e in zip((0.1, 0.5, 0.9), values, errors)]
        top = max(points, key=lambda p: p["objective"])
        return {"objective_name": name, "points": points,
                "best": {k: top[k] for k in ("params", "objective", "error_95")}}
    bound = study("electrical_bound", [10.0, 12.0, 14.0], [None] * 3)
    clear = compare_optima(study("annual_energy", [9.0, 8.0, 6.0], [0.5] * 3), bound)
    assert clear["verdict"] == "moved" and clear["difference"] == pytest.approx(3.0)
    assert clear["difference_95"] == pytest.approx(0.5 * 2 ** 0.5)
    close = compare_optima(study("annual_energy", [6.2, 6.1, 6.0], [0.5] * 3), bound)
    assert close["verdict"] == "moved within the error bars"
    failing = study("annual_energy", [9.0, 8.0, 6.0], [0.5] * 3)
    failing["points"][2].update(valid=False, reasons=["31 seas failed"])
    assert compare_optima(failing, bound)["verdict"] == "moved: the other optimum is not valid here"
    flat = study("mechanical_bound", [14.0, 14.0, 14.0], [None] * 3)      # a tie: no move
    assert compare_optima(study("annual_energy", [9.0, 8.0, 6.0], [0.5] * 3),
                          flat)["verdict"] == "same optimum"
    same = compare_optima(study("annual_energy", [5.0, 6.0, 7.0], [0.5] * 3), bound)
    assert same["verdict"] == "same optimum"
    assert [s["share"] for s in same["share_of_other"]] == pytest.approx([0.5, 0.5, 0.5])


def test_unlike_powers_are_not_compared(geared, capsys):
    """annual_energy weighs absorbed (mechanical) power, as sweep does: set against the
    electrical bound it would credit the controller with the machine's losses."""
    code = main(["codesign", geared, "--vary", "gear=40", "--objective", "annual_energy",
                 "--controller", "reactive", "--seas", "unused.csv", "--against",
                 "electrical_bound"])
    assert code == 1 and "compare it with mechanical_bound" in capsys.readouterr().err
