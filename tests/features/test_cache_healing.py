"""A cache or store entry that cannot be read is no failure that sticks (mbcontrol.cache): it is
named (a CacheWarning), moved aside as `<name>.corrupt-<time>` beside it (kept for a look) and
made again once, giving what a clean run gives; made again and still unreadable, it is an
EnvironmentProblem naming it. Each entry is damaged as a full disk or a kill leaves it: cut to
a third of its bytes."""
import json
import os
import re

import numpy as np
import pytest

from mbcontrol import cache
from mbcontrol.cache import CacheWarning
from mbcontrol.errors import EnvironmentProblem


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A fresh cache of this test's own."""
    path = tmp_path / "cache"
    monkeypatch.setenv("MBCONTROL_CACHE", str(path))
    monkeypatch.setenv("MBCONTROL_QUIET", "1")
    return path


def _truncate(path):
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])


def _set_aside(path) -> list:
    return sorted(path.parent.glob(path.name + ".corrupt-*"))


def _named(path) -> str:
    """A warning's text that names `path` and says it was moved aside."""
    return rf"{re.escape(str(path))} is damaged or unreadable .* moved aside to {re.escape(path.name)}\.corrupt-"


def test_a_truncated_radiation_fit_is_set_aside_and_fitted_again(folder):
    from mbcontrol.hydro import fit_hydro_model, read_netcdf
    from mbcontrol.scene import load_scene
    data = read_netcdf(load_scene("sphere").hydro.file)
    # tolerance 0.3: no shipped fit has it, so the fit is cached (1 s: 4 states)
    clean = fit_hydro_model(data, ["sphere__Heave"], 0.3, "sphere").radiation
    (entry,) = folder.glob("radiation_*.npz")
    _truncate(entry)                       # was: zipfile.BadZipFile on every later run
    with pytest.warns(CacheWarning, match=_named(entry)):
        again = fit_hydro_model(data, ["sphere__Heave"], 0.3, "sphere").radiation
    assert len(_set_aside(entry)) == 1 and entry.exists()
    for name in ("A", "B", "C", "D"):     # the same fit: same data, same deterministic fitter
        np.testing.assert_array_equal(getattr(again, name), getattr(clean, name))
    with np.load(entry) as z:              # and the rebuilt entry is whole
        np.testing.assert_array_equal(z["A"], clean.A)


def test_a_truncated_bem_run_is_set_aside_and_solved_again(folder):
    """A Capytaine run's cache (bem_<key>.nc), read back from the cache folder."""
    from mbcontrol.hydro import BemBody, compute
    body = BemBody(name="ball", geometry={"type": "sphere", "radius": 1.0, "center": [0, 0, 0]},
                   cog=(0, 0, 0), mass=2094.4, panel_size=0.5, dofs=("Heave",))
    run = dict(rho=1000.0, g=9.81, depth=np.inf, omegas=[1.0, 2.0], cache_dir=cache.cache_dir(),
               progress=False)
    clean = compute([body], **run)
    (entry,) = folder.glob("bem_*.nc")
    _truncate(entry)                      # was: HydroError "delete it to recompute", every run
    with pytest.warns(CacheWarning, match=_named(entry)):
        again = compute([body], **run)
    assert len(_set_aside(entry)) == 1 and entry.exists()
    for var in ("added_mass", "radiation_damping", "excitation_force"):
        np.testing.assert_array_equal(again[var].values, clean[var].values)


def test_a_truncated_converted_source_is_set_aside_and_converted_again(folder, tmp_path):
    """A scene's own BEM file ([hydro] source), converted and cached as source_<key>.nc."""
    from mbcontrol.hydro import load_hydro_data
    from mbcontrol.scene import catalogue_dir, load_scene
    from tests.helpers.reader_data import SPHERE
    if not SPHERE.exists():
        pytest.skip(f"reference data not found in {SPHERE.parent}")
    text = (catalogue_dir() / "sphere.toml").read_text()
    text = re.sub(r'^file = ".*"\s*(#.*)?$', "", text, count=1, flags=re.M)
    text = re.sub(r'^source = ".*"$', f'source = "{SPHERE}"', text, count=1, flags=re.M)
    (tmp_path / "my_sphere.toml").write_text(text)
    scene = load_scene(tmp_path / "my_sphere.toml")
    assert scene.hydro.file is None and scene.hydro.source
    _, clean = load_hydro_data(scene, ["sphere__Heave"])
    (entry,) = folder.glob("source_*.nc")
    _truncate(entry)                      # was: HydroError "delete it to recompute", every run
    with pytest.warns(CacheWarning, match=_named(entry)):
        _, again = load_hydro_data(scene, ["sphere__Heave"])
    assert len(_set_aside(entry)) == 1 and entry.exists()
    for var in ("added_mass", "radiation_damping", "excitation_force"):
        np.testing.assert_array_equal(again[var].values, clean[var].values)


def _sweep(capsys, store, *extra):
    from mbcontrol.cli import main
    code = main(["sweep", "sphere", "--hs", "1", "2", "--tp", "8", "--duration", "60", "--dt",
                 "0.1", "--workers", "0", "--store", str(store), "--allow-invalid", "--json",
                 *extra])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_a_truncated_sweep_case_is_run_again_and_the_others_kept(folder, tmp_path, capsys):
    store = tmp_path / "store"
    clean = _sweep(capsys, store)
    cases = sorted((store / "cases").glob("*.json"))
    assert (clean["computed"], clean["reused"], len(cases)) == (2, 0, 2)
    _truncate(cases[0])                   # was: a bare JSONDecodeError, no path, every rerun
    with pytest.warns(CacheWarning, match=rf"sweep case record {_named(cases[0])}.*running "
                                          rf"the case again"):
        again = _sweep(capsys, store)
    assert (again["computed"], again["reused"]) == (1, 1)     # resumes: one case re-run
    assert len(_set_aside(cases[0])) == 1 and json.loads(cases[0].read_text())
    assert [r["mean_power_W"] for r in again["seas"]] == [r["mean_power_W"] for r in clean["seas"]]
    assert again["weighted_mean_power_W"] == clean["weighted_mean_power_W"]


def test_a_truncated_compiled_library_is_set_aside_too(folder):
    """The compiled cache's own check (size and SHA-256) now keeps the damaged file."""
    import subprocess
    import sys

    from mbcontrol.sim import compiled
    if compiled.compiler() is None:
        pytest.skip("no C compiler")
    code = ("import casadi as ca; from mbcontrol.sim import compiled; x = ca.SX.sym('x'); "
            "compiled.compile_function(ca.Function('heal_test', [x], [x * x + 1]))")
    subprocess.run([sys.executable, "-c", code], check=True, env=os.environ.copy())
    (library,) = (folder / "compiled").glob("heal_test_*.so")
    _truncate(library)
    import casadi as ca
    x = ca.SX.sym("x")
    with pytest.warns(RuntimeWarning, match=_named(library)):
        f = compiled.compile_function(ca.Function("heal_test", [x], [x * x + 1]))
    assert float(f(3.0)) == 10.0 and len(_set_aside(library)) == 1


def test_an_entry_unreadable_when_made_again_is_an_environment_problem(folder):
    """What a failing disk does: whatever is written reads back damaged. Both copies kept."""
    entry = cache.cache_dir() / "thing.json"
    entry.write_text('{"half')

    def make(path):
        path.write_text('{"still half')

    with pytest.warns(CacheWarning), \
            pytest.raises(EnvironmentProblem, match=rf"{re.escape(str(entry))}: the cache entry "
                                                    rf"was made again and still cannot be read"):
        cache.load_or_make(entry, lambda p: json.loads(p.read_text()), make)
    assert len(_set_aside(entry)) == 2 and not entry.exists()


def test_a_rebuild_by_another_process_is_not_set_aside(folder):
    """Two processes read one damaged entry; the first sets it aside and writes a good one:
    the second, whose read failed on the old file, must not move the new one away."""
    entry = cache.cache_dir() / "shared.json"
    entry.write_text('{"half')
    seen = entry.stat()
    os.unlink(entry)
    entry.write_text('{"whole": 1, "padding": "changes the size"}')        # the rebuild
    assert cache.set_aside(entry, "JSONDecodeError", seen=seen) is None
    assert json.loads(entry.read_text())["whole"] == 1 and not _set_aside(entry)


def test_a_truncated_co_design_point_is_evaluated_again(tmp_path):
    """A co-design store's point record, as a sweep's case (was: a bare JSONDecodeError)."""
    from mbcontrol.studies.codesign.study import Store
    Store(tmp_path).put("point", {"objective": 1.5, "valid": True})
    path = tmp_path / "points" / "point.json"
    _truncate(path)
    with pytest.warns(CacheWarning, match=rf"{_named(path)}.*evaluating the point again"):
        assert Store(tmp_path).get("point") is None           # so the study evaluates it
    assert len(_set_aside(path)) == 1


def test_a_truncated_parsed_csv_is_set_aside_and_parsed_again(folder, tmp_path):
    """The parsed-CSV cache of measured records (was: zipfile.BadZipFile)."""
    from mbcontrol.studies.identify import read_csv
    csv = tmp_path / "run.csv"
    csv.write_text("Time [s],Heave [m]\n0,0.0\n0.1,0.5\n0.2,1.0\n")
    clean = read_csv(csv)
    (entry,) = (folder / "records").glob("csv_*.npz")
    _truncate(entry)
    with pytest.warns(CacheWarning, match=_named(entry)):
        again = read_csv(csv)
    assert len(_set_aside(entry)) == 1
    np.testing.assert_array_equal(again.channel("Heave"), clean.channel("Heave"))
    np.testing.assert_array_equal(again.time, clean.time)
