"""The catalogue's radiation fits ship with the package (models/radiation_fits): a fresh
machine builds every catalogue plant without fitting, and a shipped fit is the fit a fresh
run makes."""
import numpy as np
import pytest

from mbcontrol.hydro import model as hydro_model
from mbcontrol.plant import build_plant
from mbcontrol.scene import list_models, load_scene


@pytest.fixture
def empty_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path))
    return tmp_path


@pytest.mark.parametrize("name", list_models())
def test_catalogue_plant_builds_from_shipped_fits(name, empty_cache, monkeypatch):
    if not load_scene(name).hydro.file:     # array_grid: BEM and fit on first use, per layout
        pytest.skip(f"{name} computes its hydrodynamics on first use: nothing is shipped")

    def no_fitting(*args, **kwargs):
        raise AssertionError(f"{name}: no shipped fit matches; run "
                             f"`python models/generate_hydro.py --ship-fits`")
    monkeypatch.setattr(hydro_model, "fit_radiation", no_fitting)
    plant = build_plant(name)
    assert plant.hydro.radiation.order > 0
    assert not list(empty_cache.glob("radiation_*.npz"))        # nothing fitted, nothing cached


def test_shipped_fit_equals_a_fresh_fit(empty_cache, monkeypatch):
    hydro_model.FITS_SERVED.clear()
    shipped = build_plant("sphere").hydro.radiation
    name = hydro_model.FITS_SERVED[-1]
    calls = []
    real = hydro_model.fit_radiation
    monkeypatch.setattr(hydro_model, "fit_radiation",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    assert (hydro_model.shipped_fits_dir() / name).exists()
    # a fresh fit of the same data, DOFs, tolerance and band: the shipped folder looked up
    # empty (the package's own files are not touched)
    monkeypatch.setattr(hydro_model, "shipped_fits_dir", lambda: empty_cache / "nothing_shipped")
    fresh = build_plant("sphere").hydro.radiation
    assert calls == [1]                                           # it really was fitted anew
    w = np.linspace(0.1, 3.0, 60)
    np.testing.assert_allclose(fresh.frequency_response(w), shipped.frequency_response(w),
                               rtol=1e-8, atol=1e-8 * np.abs(shipped.frequency_response(w)).max())
