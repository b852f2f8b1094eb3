"""The column-wise radiation fit for arrays (mbcontrol.hydro.fit.array_fit), checked against the data
it fits, the exact passivity test of module passivity, the kernel's own cosine transform and the
layout's symmetry; and the choice of fit by a scene."""
import numpy as np
import pytest

from mbcontrol.errors import HydroError, SceneError
from mbcontrol.hydro import fit_method, impulse_response, kernel_data
from mbcontrol.hydro.data.netcdf import read_netcdf
from mbcontrol.hydro.fit.array_fit import column_classes, fit_radiation_columns
from mbcontrol.hydro.fit.passivity import passivity_test
from mbcontrol.scene import catalogue_dir, load_scene

OMEGA_MAX = 12.0    # rad/s: array4's 40 mm mesh is resolved below this


@pytest.fixture(scope="module")
def data():
    return read_netcdf(catalogue_dir() / "array4_hydro.nc")


@pytest.fixture(scope="module")
def fit(data):
    return fit_radiation_columns(data, tol=0.02, omega_max=OMEGA_MAX)


def _square_symmetries():
    """The eight permutations of array4's floats (index i at x = i % 2, y = i // 2) under the
    square's rotations and reflections."""
    pos = np.array([[i % 2 - 0.5, i // 2 - 0.5] for i in range(4)])
    perms = []
    for R in ([[1, 0], [0, 1]], [[0, -1], [1, 0]], [[-1, 0], [0, -1]], [[0, 1], [-1, 0]],
              [[1, 0], [0, -1]], [[-1, 0], [0, 1]], [[0, 1], [1, 0]], [[0, -1], [-1, 0]]):
        moved = pos @ np.array(R, float).T
        perms.append([int(np.argmin(np.linalg.norm(pos - p, axis=1))) for p in moved])
    return perms


def test_the_square_has_one_column_class_and_each_map_is_a_symmetry_of_the_data(data):
    w, K, _ = kernel_data(data, omega_max=OMEGA_MAX)
    classes = column_classes(0.5 * (K + np.swapaxes(K, 1, 2)))
    assert [r for r, _ in classes] == [0, 0, 0, 0]
    for j, (_, perm) in enumerate(classes):
        assert perm[j] == 0                                  # the moving float onto the moving float
        assert sorted(perm) == [0, 1, 2, 3]
        err = np.linalg.norm(K[:, :, j] - K[:, perm, 0]) / np.linalg.norm(K[:, :, 0])
        assert err < 1e-3
    # a column changed by 1 % is no longer a copy: it gets its own fit
    K2 = K.copy()
    K2[:, 1, 3] *= 1.01
    K2[:, 3, 1] *= 1.01
    assert len({r for r, _ in column_classes(K2)}) > 1


def test_fit_meets_its_tolerance_against_the_data_and_reports_entries_worst_first(fit, data):
    w, K, _ = kernel_data(data, omega_max=OMEGA_MAX)
    Ks = 0.5 * (K + np.swapaxes(K, 1, 2))
    resp = fit.frequency_response(w)           # from (A, B, C): the realisation, not the fit's parts
    rms = np.sqrt(np.sum(np.abs(resp - Ks) ** 2) / np.sum(np.abs(Ks) ** 2))
    assert rms == pytest.approx(fit.fit_error, rel=1e-6)
    assert fit.fit_error <= 0.02 and fit.report["tol_met"]
    assert fit.order == sum(fit.report["poles_per_column"].values()) * 4
    errors = [e["error"] for e in fit.report["worst_entries"]]
    assert errors == sorted(errors, reverse=True) and len(errors) == 16
    # each listed error is recomputed from the data at its frequency
    top = fit.report["worst_entries"][0]
    k = int(np.argmin(np.abs(w - top["omega"])))
    i, j = (fit.dofs.index(d) for d in top["entry"])
    ref = np.max(np.abs(np.diagonal(Ks[k])))
    assert abs(resp[k, i, j] - Ks[k, i, j]) / ref == pytest.approx(top["error"], rel=1e-6)


def test_fit_is_passive_by_the_exact_test_and_enforcement_was_needed(fit):
    assert fit.report["passivity"]["corrections"] > 0       # the unconstrained columns were not passive
    exact = passivity_test(fit.A, fit.B, fit.C)             # Hamiltonian crossings + dense grid
    assert exact.passive, exact.as_dict()
    assert np.max(np.linalg.eigvals(fit.A).real) < 0


def test_fit_keeps_the_layout_symmetry_exactly(fit):
    w = np.linspace(0.3, 20.0, 200)
    Kf = fit.frequency_response(w)
    for perm in _square_symmetries():
        p = np.array(perm)
        assert np.allclose(Kf[:, p][:, :, p], Kf, rtol=0, atol=1e-12 * np.abs(Kf).max())


def test_impulse_response_matches_the_cosine_transform_of_the_damping(fit, data):
    """K(t) = (2/π)∫B cos ωt dω (module radiation, an independent quadrature of the data) against
    C e^{At} B of the fitted model: the kernel the simulation convolves."""
    t = np.linspace(0.0, 6.0, 121)
    ref = impulse_response(data, t)
    got = fit.impulse_response(t)
    scale = np.abs(ref[:, 0, 0]).max()
    assert np.abs(got - ref)[:, 0, 0].max() < 0.05 * scale        # the float's own memory
    assert np.abs(got - ref).max() < 0.08 * scale                 # every coupling


def test_an_unreachable_tolerance_is_an_error_not_a_quiet_model(data):
    with pytest.raises(HydroError, match="tolerance"):
        fit_radiation_columns(data, tol=1e-4, omega_max=OMEGA_MAX, max_order=6)


def test_a_scene_chooses_the_fit(tmp_path):
    assert fit_method("auto", [f"f{i}__Heave" for i in range(8)]) == "coupled"
    assert fit_method("auto", [f"f{i}__Heave" for i in range(9)]) == "columns"
    assert fit_method("coupled", [f"f{i}__Heave" for i in range(25)]) == "coupled"
    assert load_scene("array_grid").hydro.radiation_fit == "columns"
    text = (catalogue_dir() / "array_grid.toml").read_text().replace(
        'radiation_fit = "columns"', 'radiation_fit = "rows"')
    bad = tmp_path / "grid.toml"
    bad.write_text(text)
    with pytest.raises(SceneError, match="radiation_fit"):
        load_scene(bad)


def test_the_shunt_alone_makes_a_fit_passive(data, monkeypatch):
    """With no residue passes the band-pass terms added to the diagonal must cover every
    violation: the exact test agrees, and their real part is never negative (positive real)."""
    from mbcontrol.hydro.fit import array_passivity
    monkeypatch.setattr(array_passivity, "RESIDUE_PASSES", 0)
    model = fit_radiation_columns(data, tol=0.5, omega_max=OMEGA_MAX)
    terms = model.report["passivity"]["shunt_terms"]
    assert terms and all(b > 0 for _, _, b in terms)
    assert passivity_test(model.A, model.B, model.C).passive
    w = np.geomspace(1e-3, 1e4, 2000)
    s = array_passivity._jw(w)
    for wk, z, _ in terms:
        assert np.all(array_passivity._bandpass(s, wk, z).real >= 0)
