"""mbcontrol's one netCDF codec (mbcontrol.results): what xarray cannot write as is (complex
values, bool, dict and infinite attributes) comes back as it went in, from every writer
(hydro caches, `simulate --out`, sweeps, benchmarks) through one reader."""
import numpy as np
import pytest
import xarray as xr

from mbcontrol.hydro import read_netcdf, write_netcdf_atomic
from mbcontrol.results import (DataFileError, RunInfo, read_dataset, run_info, save_dataset,
                               write_dataset)


@pytest.fixture
def awkward():
    omega = np.linspace(0.5, 2.0, 4)
    ds = xr.Dataset({"K": (("omega", "dof"), np.outer(omega, [1, 2]) * (1 - 0.5j),
                           {"units": "N/m", "symmetric": True}),
                     "power": ("omega", omega ** 2, {"units": "W"})},
                    coords={"omega": omega, "dof": ["Heave", "Pitch"]})
    ds.attrs.update(model="sphere", fitted=False, settings={"tol": 0.02, "dofs": [2, 4]},
                    limit=np.inf, n=3, controller=None)
    return ds


@pytest.mark.parametrize("writer", [write_dataset, save_dataset, write_netcdf_atomic])
def test_every_writer_round_trips_through_the_one_reader(tmp_path, awkward, writer):
    path = writer(awkward, tmp_path / "data.nc")
    back = read_dataset(path)
    xr.testing.assert_identical(back, awkward)
    assert back.attrs["settings"] == {"tol": 0.02, "dofs": [2, 4]} and back.attrs["fitted"] is False
    assert back["K"].attrs["symmetric"] is True and back["K"].dtype.kind == "c"
    xr.testing.assert_identical(read_netcdf(path), awkward)
    assert [p.name for p in tmp_path.iterdir()] == ["data.nc"]        # nothing half written


def test_a_bad_file_is_named(tmp_path):
    with pytest.raises(DataFileError, match="missing.nc: no such file"):
        read_dataset(tmp_path / "missing.nc")
    (tmp_path / "bad.nc").write_text("not netCDF")
    with pytest.raises(DataFileError, match="bad.nc: unreadable or corrupt netCDF file"):
        read_dataset(tmp_path / "bad.nc")


def test_the_run_record_is_python_in_a_process_and_json_only_in_its_file(tmp_path):
    """simulate's Dataset carries its record as dicts (RunInfo reads them, no JSON parsed);
    the file holds JSON strings, which the one reader, and run_info on a Dataset opened by
    plain xarray, turn back into the same record."""
    from mbcontrol import waves
    from mbcontrol.controllers import make
    from mbcontrol.plant import build_plant
    from mbcontrol.sim import simulate
    plant = build_plant("sphere")
    wave = waves.regular(1.0, 8.0, ramp_time=8.0)
    ds = simulate(plant, wave, duration=16.0, dt=0.05, controller=make("passive", damping=2e5))
    assert isinstance(ds.attrs["wave"], dict) and isinstance(ds.attrs["parameters"], dict)
    run = run_info(ds)
    assert isinstance(run, RunInfo) and run.model == "sphere"
    assert run.wave == wave.describe() and run.controller["damping"] == 2e5
    assert list(run.parameters) == list(plant.parameters)
    assert run.parameters["pto__damping"] == 0.0           # the controller owns the PTO force
    assert run.statistics_from_s is None and run.warm_up_s == 0.0
    path = save_dataset(ds, tmp_path / "run.nc")
    assert run_info(read_dataset(path)) == run
    with xr.open_dataset(path) as plain:                 # another tool's view: JSON strings
        assert isinstance(plain.attrs["wave"], str)
        assert run_info(plain) == run
