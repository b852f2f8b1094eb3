"""Radiation fits judged where the device responds (issue 20, item 2): with the kernel measure
(``fit_judged_by = "kernel"``) the error that sets the order is relative per frequency in the
response band, so a low-frequency mode's small damping counts (and the global norm holds above
it); a fit that misses its tolerance says so, with the value and where; no pole is slower than
the data can resolve. Uses the shipped catalogue data (the OSWEC's kernel-judged fit is made on
an empty cache in about a second)."""
import warnings

import numpy as np
import pytest

from mbcontrol.hydro import model as hydro_model
from mbcontrol.hydro.fit.kernel import kernel_data
from mbcontrol.hydro.fit.radiation import RadiationFitWarning, fit_radiation
from mbcontrol.hydro.fit.fit_error import part_errors
from mbcontrol.hydro.fit.vector_fit import SLOW_POLE
from mbcontrol.plant import build_plant
from mbcontrol.scene import list_models, load_scene

from tests.helpers.kernel_fits import judged_by_kernel


@pytest.fixture
def empty_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("MBCONTROL_CACHE", str(tmp_path))
    return tmp_path


def _quiet_plant(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RadiationFitWarning)   # asserted on its own below
        return build_plant(name)


def test_oswec_damping_per_frequency_in_its_response_band(empty_cache):
    """The flap's pitch mode (~0.35 rad/s, 18 s) lies in its response band (0.3-2 rad/s): the
    fitted damping, against the BEM data at every frequency there, within the tolerance asked
    for. A global error norm alone let the hinge damping be off by ~100 % near the mode (where it
    is 1e-3 of its peak): measured before this change, 14.2 % at 0.31 rad/s (tol 0.5 %, global)."""
    scene = judged_by_kernel("oswec")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plant = build_plant(scene)
    hydro = plant.hydro
    rad, tol = hydro.radiation, scene.hydro.radiation_tol
    assert scene.hydro.response_band == (0.3, 2.0) and rad.report["response_band"] == [0.3, 2.0]
    w, K, dofs = kernel_data(hydro.data, list(rad.dofs), rad.report["omega_fit"][1])
    assert dofs == ["flap__Surge", "flap__Pitch"]
    K = 0.5 * (K + np.swapaxes(K, 1, 2))                       # as fitted (BEM reciprocity)
    fit = rad.frequency_response(w)
    band = (w >= 0.3) & (w <= 2.0)
    # the damping part of the error, recomputed here from its definition: per frequency, in
    # D K D (each DOF's peak 1), relative to the largest damping entry there (at least 1 %)
    d = 1 / np.sqrt(np.max(np.abs(np.einsum("kii->ki", K)), axis=0))
    dd = np.outer(d, d)[None]
    size = np.maximum(np.max(np.abs((K * dd).real), axis=(1, 2)), 0.01)
    damping = np.max(np.abs(((fit - K) * dd).real), axis=(1, 2)) / size
    assert damping[band].max() <= tol
    assert not [c for c in caught if issubclass(c.category, RadiationFitWarning)]
    # the hinge's own damping Jᵀ B J (hinge below the CoG: pitch rate θ' moves the CoG at
    # -lever θ' in surge), which has cancellation between the entries; around the mode (0.3-0.5
    # rad/s) and over the band. Measured 0.42 % and 0.53 % (51 states); the global-norm fit before
    # this change (0.45 %, 42 states): 15.8 % near the mode, 14.2 % per-frequency damping error
    lever = scene.joints[0].point[2] - scene.bodies[0].cog[2]
    J = np.array([-lever, 1.0])
    b_bem = np.einsum("i,kij,j->k", J, K.real, J)
    b_fit = np.einsum("i,kij,j->k", J, fit.real, J)
    rel = np.abs(b_fit / b_bem - 1)
    assert rel[(w >= 0.3) & (w <= 0.5)].max() <= 0.01 and rel[band].max() <= 0.02


def test_oswec_error_is_per_frequency_in_band_or_global(empty_cache):
    """fit_error is the larger of the in-band per-frequency error and the global RMS error; the
    report locates the worst in-band point."""
    hydro = _quiet_plant(judged_by_kernel("oswec")).hydro
    rad = hydro.radiation
    w, K, dofs = kernel_data(hydro.data, list(rad.dofs), rad.report["omega_fit"][1])
    Ks = 0.5 * (K + np.swapaxes(K, 1, 2))                                   # symmetrised, as fitted
    fit = rad.frequency_response(w)
    band = (w >= 0.3) & (w <= 2.0)
    e = part_errors(fit, Ks, w, np.diag(hydro.added_mass_inf)) * band[:, None, None]
    rms = np.sqrt(np.sum(np.abs(fit - K) ** 2) / np.sum(np.abs(K) ** 2))
    assert rad.report["band_error"] == pytest.approx(e.max(), rel=1e-6)
    assert rad.report["rms_error"] == pytest.approx(rms, rel=1e-6)
    assert rad.fit_error == pytest.approx(max(e.max(), rms), rel=1e-6)
    worst = rad.report["worst"]
    k, i, j = np.unravel_index(np.argmax(e), e.shape)
    assert worst["omega"] == pytest.approx(w[k]) and worst["entry"] == [dofs[i], dofs[j]]


def test_part_errors_scale_invariant_and_floored():
    """Same error in any DOF units (congruence scaling), and K -> 0 at ω -> 0 asks no more
    than FLOOR of the peak."""
    rng = np.random.default_rng(0)
    w, ainf = np.linspace(0.1, 2.0, 20), np.array([0.3, 0.5])
    K = rng.normal(size=(20, 2, 2)) + 1j * rng.normal(size=(20, 2, 2))
    K = K + np.swapaxes(K, 1, 2)
    fit = K * (1 + 0.01 * rng.normal(size=K.shape))
    s = np.array([1e3, 1e-2])
    S = np.diag(s)
    np.testing.assert_allclose(part_errors(S @ fit @ S, S @ K @ S, w, ainf * s**2), part_errors(fit, K, w, ainf),
                               rtol=1e-10)
    tiny = K.copy()
    tiny[0] *= 1e-9
    assert np.max(part_errors(tiny + 1e-12, tiny, w, ainf)[0]) < 1e-6


def test_missed_tolerance_warns_with_value_and_place(empty_cache):
    """A fit that cannot meet its tolerance warns: achieved value, frequency, entry; the
    report says the same, and a shipped or cached fit that missed warns again when loaded."""
    data = _quiet_plant("sphere").hydro.data
    with pytest.warns(RadiationFitWarning) as caught:
        m = fit_radiation(data, dofs=["sphere__Heave"], tol=1e-6, max_order=4, passive=False, omega_max=8.0)
    rep = m.report
    assert not rep["tol_met"] and m.fit_error > 1e-6
    text = str(caught[0].message)
    assert f"{m.fit_error:.2%}" in text and "tol 0.00%" in text
    if rep["limited_by"] == "response band":
        assert f"{rep['worst']['omega']:.4g} rad/s" in text and "K[sphere__Heave, sphere__Heave]" in text
        assert rep["worst"]["error"] == pytest.approx(m.fit_error)
    else:
        assert "global RMS" in text and rep["rms_error"] == pytest.approx(m.fit_error)
    arrays = dict(A=m.A, B=m.B, C=m.C, D=m.D, dofs=np.array(m.dofs), order=m.order, fit_error=m.fit_error,
                  entry_errors=m.entry_errors, report=__import__("json").dumps(rep))
    with pytest.warns(RadiationFitWarning, match="misses its tolerance"):
        hydro_model.model_from_arrays(arrays)


@pytest.mark.parametrize("name", list_models())
def test_no_pole_slower_than_the_data(name, request):
    """Every shipped catalogue fit: every pole decays at least at SLOW_POLE × the lowest fitted
    ω (wavestar's fit had a pole at -0.0016 1/s, and a design waited 7,650 s for it). A scene
    with a hydro file is judged on an empty cache, so that its shipped fit is the one served;
    one without (wavebot, array_grid: BEM and fit on first use) ships nothing, and shares the
    suite's cache rather than solving its BEM again."""
    if load_scene(name).hydro.file:
        request.getfixturevalue("empty_cache")
    rad = _quiet_plant(name).hydro.radiation
    floor = SLOW_POLE * rad.report["omega_fit"][0]
    assert np.max(np.linalg.eigvals(rad.A).real) <= -0.99 * floor
    assert rad.report["slowest_decay"] >= 0.99 * floor
    assert rad.report["passivity"]["passive"]


def test_hydro_command_reports_where_the_fit_is_judged(capsys):
    """`mbcontrol hydro`: text and --json show the tolerance, the response band, the worst
    in-band error (value, ω, entry, part) and the global RMS error, from the fit's own report."""
    import json

    from mbcontrol.cli import main

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RadiationFitWarning)
        assert main(["hydro", "oswec", "--judged-by", "kernel", "--json"]) == 0
        rep = json.loads(capsys.readouterr().out)
        assert main(["hydro", "oswec", "--judged-by", "kernel"]) == 0
        text = capsys.readouterr().out
    assert rep["response_band"] == [0.3, 2.0] and rep["tol"] == 0.01 and rep["tol_met"] is True
    worst = rep["worst"]
    assert rep["fit_error"] == max(rep["band_error"], rep["rms_error"]) and worst["error"] == rep["band_error"]
    assert 0.3 <= worst["omega"] <= 2.0 and worst["entry"][0].startswith("flap__")
    assert f"fit error {rep['fit_error']:.2%} (tol 1.00%)" in text and "in 0.3-2 rad/s" in text
    assert f"at {worst['omega']:.4g} rad/s" in text and f"global RMS {rep['rms_error']:.2%}" in text
    # beside it, the response error this kernel-judged fit causes (what would have judged it)
    assert rep["judged_by"] == "kernel" and rep["response_worst"]["error"] == rep["response_error"] > 0
    assert f"its response error (not what judges this fit): {rep['response_error']:.2%}" in text


@pytest.mark.parametrize("name", ["rm3", "hinged_raft"])
def test_response_error_of_a_plant_is_what_its_fit_reports(name):
    """plant.response_error_of, which `mbcontrol hydro` uses for kernel-judged fits, recomputes a
    response-judged fit's own reported error: the same data, band and reciprocity (rm3's K is
    symmetrised, hinged_raft's is not: its asymmetry is over 1 %)."""
    from mbcontrol.plant import response_error_of
    plant = _quiet_plant(name)
    rad = plant.hydro.radiation
    assert rad.report["symmetrized"] is (name == "rm3")
    worst = response_error_of(plant)
    assert worst["error"] == pytest.approx(rad.report["response_error"], rel=1e-9)
    reported = rad.report["response_worst"]
    assert (worst["omega"], worst["what"]) == (reported["omega"], reported["what"])


def test_response_band_must_be_low_high(tmp_path):
    """A bad [hydro] response_band is an error naming the file, the field and what was expected."""
    from mbcontrol.errors import SceneError

    from pathlib import Path

    text = Path(load_scene("sphere").path).read_text()
    bad = tmp_path / "sphere.toml"
    bad.write_text(text.replace("response_band = [0.3, 2.5]", "response_band = [2.5, 0.3]")
                   .replace('file = "sphere_hydro.nc"', 'file = "unused.nc"'))
    with pytest.raises(SceneError, match=r"sphere.toml.*hydro.response_band.*\[low, high\] in rad/s"):
        load_scene(str(bad))
