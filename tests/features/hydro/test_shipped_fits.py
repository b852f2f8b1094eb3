"""The catalogue's radiation fits ship with the package (models/radiation_fits): a fresh
machine builds every catalogue plant without fitting, and a shipped fit is the fit a fresh
run makes."""
import numpy as np
import pytest

from mbcontrol.hydro.fit import store as hydro_model   # where fits are found and made
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
    with hydro_model.recording_served_fits() as served:
        shipped = build_plant("sphere").hydro.radiation
    name = served[-1]
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


def test_a_fit_made_for_another_device_serves_when_it_meets_the_tolerance(empty_cache, monkeypatch, tmp_path):
    """The sphere with a drivetrain (its inertia changes the device, so the fit's name) is served
    the catalogue sphere's shipped fit, without fitting: that fit's response error in the new
    device, recomputed independently by plant.response_error_of, is within the tolerance and is
    what its report now says. The same fit against a tolerance it misses is not reused."""
    from tests.helpers.drivetrain_scenes import with_drivetrain
    from mbcontrol.plant import device_around, response_error_of

    def no_fitting(*args, **kwargs):
        raise AssertionError("fitted anew although a shipped fit meets the tolerance")
    monkeypatch.setattr(hydro_model, "fit_radiation", no_fitting)
    with hydro_model.recording_served_fits() as served:
        plant = build_plant(with_drivetrain(tmp_path, "sphere", gear=12.0, inertia=200.0))
    rad = plant.hydro.radiation
    assert rad.report["made_for_another_device"] in {p.name for p in hydro_model.shipped_fits_dir().iterdir()}
    worst = response_error_of(plant)
    assert rad.fit_error == rad.report["response_error"] == pytest.approx(worst["error"], rel=1e-9)
    assert worst["error"] <= plant.scene.hydro.radiation_tol and rad.report["tol_met"]
    assert served[-1] in {p.name for p in empty_cache.glob("radiation_*.npz")}   # kept
    # the gate itself: the same candidates against a tolerance the fit misses give nothing
    base = rad.report["made_for_another_device"].split("_")[1]
    device = device_around(plant.scene, plant.hydro.source, plant.hydro.data, list(rad.dofs))
    assert hydro_model._reused_fit(base, plant.hydro.data, rad.report["omega_fit"][1], 1e-3 * worst["error"],
                                   device) is None


def test_fits_are_recorded_only_for_a_caller_that_asks(empty_cache):
    """The fits served are told to an active recorder (each of nested ones), and kept nowhere
    when none is active (no module state carries them between calls)."""
    with hydro_model.recording_served_fits() as outer:
        with hydro_model.recording_served_fits() as inner:
            build_plant("sphere")
        build_plant("sphere")
    assert inner and outer == inner + inner
    build_plant("sphere")                      # nobody records: nothing kept
    assert outer == inner + inner
