"""The public API (issue 59, items 3 and 4): `import mbcontrol as mbc`, one simulate, one
result type. The snippet of the issue runs and round-trips through netCDF; the Result's
numbers are checked against what made them by another road: python-control's own response
of the linearised plant, and linear theory straight from the BEM data."""
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest

import mbcontrol as mbc

ROOT = Path(__file__).resolve().parents[1]
DAMPING = 6e5           # N s/m, the case: the sphere in a regular 8 s wave, H 1 m
HEIGHT, PERIOD, DURATION = 1.0, 8.0, 120.0


@pytest.fixture(scope="module")
def snippet(tmp_path_factory):
    """The issue's snippet as written, run in a temporary folder: (result, its file)."""
    folder = tmp_path_factory.mktemp("api")
    with _inside(folder):
        r = mbc.simulate("sphere", wave=mbc.regular(height=1.0, period=8.0), controller="passive",
                         settings={"damping": 6e5}, duration=120)
        r.to_xarray().to_netcdf("r.nc")
    print(r.valid, r.mean_power_W["pto"])
    return r, folder / "r.nc"


class _inside:
    def __init__(self, folder):
        self.folder, self.before = folder, None

    def __enter__(self):
        import os
        self.before = os.getcwd()
        os.chdir(self.folder)

    def __exit__(self, *exc):
        import os
        os.chdir(self.before)


def test_the_snippet_runs_and_round_trips_through_netcdf(snippet):
    import xarray as xr
    r, path = snippet
    assert r.valid is True and r.invalid_reasons == []
    assert set(r.mean_power_W) == {"pto"} and r.mean_power_W["pto"] > 0
    with xr.open_dataset(path) as raw:            # plain xarray: attrs as JSON strings
        back = mbc.Result.from_xarray(raw.load())
    # a file holds float64 as it is: the numbers come back bit for bit
    assert back.mean_power_W == r.mean_power_W and back.valid == r.valid
    assert back.state_names == r.state_names and back.output_names == r.output_names
    assert np.array_equal(back.outputs, r.outputs) and np.array_equal(back.states, r.states)
    assert back.provenance == r.provenance and back.summary == r.summary
    # the library's own writer and reader give the same
    again = mbc.Result.read(r.to_netcdf(path.with_name("again.nc")))
    assert again.mean_power_W == r.mean_power_W and np.array_equal(again.inputs, r.inputs)


def test_a_bare_simulate_dataset_is_refused_by_from_xarray():
    import xarray as xr
    with pytest.raises(mbc.InputError, match="Result.from_run"):
        mbc.Result.from_xarray(xr.Dataset(attrs={"model": "sphere"}))


def test_the_result_names_its_signals(snippet):
    r, _ = snippet
    plant = mbc.load("sphere")
    assert r.state_names == tuple(plant.states) and r.input_names == ("u__pto",)
    assert r.time[0] == 0.0 and r.time[-1] == pytest.approx(DURATION)
    assert r.states.shape == (r.time.size, len(plant.states))
    assert r.outputs.shape == (r.time.size, len(plant.outputs))
    assert np.array_equal(r["pto__power"], r.outputs[:, plant.outputs.index("pto__power")])
    assert r.units("pto__force") == "N"
    assert r.provenance["controller"]["name"] == "passive"
    assert r.provenance["parameters"]["pto__damping"] == 0.0     # the controller owns the PTO
    with pytest.raises(KeyError, match="not a signal"):
        r["no_such_signal"]


def test_to_timeresponse_replays_through_the_linearised_plant():
    """The sphere (linear hydrostatics and radiation) is its own linearisation: python-control
    driven by the recorded inputs (u then w, as linearize orders them) from the recorded
    initial state reproduces the Result's outputs. The scene's PTO law (u = 0) is used, so that
    the inputs are smooth: linear interpolation of the 8 s wave's w between 0.01 s samples
    errs by (omega dt)^2 / 8 = 7.7e-6 of its amplitude (measured 5.3e-6), hence 2e-5."""
    import control
    r = mbc.simulate("sphere", mbc.regular(HEIGHT, PERIOD), params={"pto__damping": DAMPING},
                     duration=DURATION)
    tr = r.to_timeresponse()
    assert isinstance(tr, control.TimeResponseData)
    assert list(tr.output_labels) == list(r.output_names)
    assert list(tr.state_labels) == list(r.state_names)
    assert list(tr.input_labels) == ["u__pto", "w__sphere__Heave"]
    assert np.array_equal(tr.outputs, r.outputs.T) and np.array_equal(tr.time, r.time)
    sys_ = mbc.linearize(mbc.load("sphere"), params=r.provenance["parameters"])
    assert list(sys_.input_labels) == list(tr.input_labels)
    replay = control.forced_response(sys_, T=tr.time, U=tr.inputs, X0=r.states[0])
    for name in ("heave", "heave__vel", "pto__force"):     # the outputs linear in x, u, w
        i = tr.output_labels.index(name)
        scale = np.max(np.abs(tr.outputs[i]))
        assert np.max(np.abs(replay.outputs[i] - tr.outputs[i])) < 2e-5 * scale, name


def test_mean_power_agrees_with_linear_theory(snippet):
    """P = 1/2 c omega^2 |X|^2 a^2 with X the heave per unit amplitude straight from the BEM
    data (no radiation fit, no time stepping; phasor convention irrelevant: |X|). 1 %: the
    controller's command is held over each 0.01 s step (a half-step delay, omega dt / 2 =
    0.4 % of phase; measured -0.32 %) and the radiation fit errs by 0.06 %."""
    r, _ = snippet
    omega = 2 * np.pi / PERIOD
    X = mbc.frequency_domain_response(mbc.load("sphere"), [omega],
                                      params={"pto__damping": DAMPING}, outputs=["heave"])
    theory = 0.5 * DAMPING * omega ** 2 * abs(X[0, 0]) ** 2 * (HEIGHT / 2) ** 2
    assert r.mean_power_W["pto"] == pytest.approx(theory, rel=0.01)


def test_a_controller_instance_runs_as_its_name_and_settings(snippet):
    r, _ = snippet
    instance = mbc.controllers.make("passive", damping=DAMPING)
    same = mbc.simulate("sphere", mbc.regular(HEIGHT, PERIOD), controller=instance,
                        duration=DURATION)
    assert np.array_equal(same.outputs, r.outputs) and same.mean_power_W == r.mean_power_W
    with pytest.raises(mbc.InputError, match="registry name"):
        mbc.simulate("sphere", controller=instance, settings={"damping": 1.0})


def test_batch_and_convolution_return_the_same_type():
    """The batch steps both cases in one compiled call with the same method and step as
    simulate: the same numbers to the last bit. The convolution reference uses the BEM
    kernel instead of the fitted radiation states: its power within 0.5 % (fit error 0.06 %,
    measured 0.04 %)."""
    waves = [mbc.regular(HEIGHT, PERIOD), mbc.regular(HEIGHT, 6.0)]
    params = {"pto__damping": DAMPING}
    batch = mbc.simulate_batch("sphere", waves, params, duration=DURATION)
    assert [type(b) for b in batch] == [mbc.Result, mbc.Result]
    for wave, b in zip(waves, batch):
        one = mbc.simulate("sphere", wave, params=params, duration=DURATION)
        assert b.valid and np.array_equal(b.outputs, one.outputs)
        assert b.mean_power_W == one.mean_power_W
    reference = mbc.simulate_convolution("sphere", waves[0], duration=DURATION, params=params)
    assert isinstance(reference, mbc.Result) and reference.state_names == ()
    assert reference.valid
    assert reference.mean_power_W["pto"] == pytest.approx(batch[0].mean_power_W["pto"],
                                                          rel=0.005)
    assert reference.to_timeresponse().states.shape == (0, reference.time.size)


def test_an_invalid_run_warns_and_says_why():
    """30 s of an 8 s wave: after its 16 s ramp the statistics window holds under two
    periods, a transient (analysis.validity: at least 10, so 96 s)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = mbc.simulate("sphere", mbc.regular(HEIGHT, PERIOD), controller="passive",
                         settings={"damping": DAMPING}, duration=30)
    assert not r.valid and "simulate at least 96 s" in r.invalid_reasons[0]
    assert [w for w in caught if issubclass(w.category, RuntimeWarning)
            and "physics checks" in str(w.message)]


def test_load_takes_every_way_of_naming_a_model():
    plant = mbc.load("sphere")
    assert mbc.load(plant) is plant
    assert mbc.load(ROOT / "models" / "sphere.toml").states == plant.states
    assert mbc.load(mbc.load_scene("sphere")).states == plant.states
    with pytest.raises(mbc.InputError, match="catalogue name"):
        mbc.load(3.0)


def test_jonswap_defaults_and_default_durations():
    from mbcontrol.api import default_duration
    sea = mbc.jonswap(2.0, 9.0)
    assert sea.settings["gamma"] == 3.3 and sea.settings["hs"] == 2.0
    assert 2 * np.pi / sea.d_omega == pytest.approx(600.0)       # the documented grid
    assert default_duration(sea) == pytest.approx(600.0)
    assert default_duration(mbc.regular(1.0, 8.0)) == pytest.approx(240.0)   # 30 periods
    assert default_duration(None) == 60.0


def test_the_face_is_the_curated_list():
    assert dir(mbc) == sorted(mbc.__all__ + ["__version__"])
    assert 25 <= len(mbc.__all__) <= 35
    for name in mbc.__all__:
        value = getattr(mbc, name)
        assert (value.__doc__ or "").strip(), f"mbcontrol.{name} has no docstring"
    for required in ("load", "simulate", "regular", "jonswap", "linearize", "design", "sweep",
                     "controllers", "Result"):
        assert required in mbc.__all__
    assert mbc.controllers.__name__ == "mbcontrol.controllers"
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert mbc.__version__ == version == "0.2.0"


def test_import_mbcontrol_stays_cheap():
    """The face loads nothing heavy until a name is used (tests/features/cli/test_startup.py's rule)."""
    probe = ("import sys\nimport mbcontrol as mbc\ndir(mbc)\nmbc.__version__\n"
             "print(*[m for m in ('casadi', 'xarray', 'control', 'capytaine', 'dask') "
             "if m in sys.modules])")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == ""
