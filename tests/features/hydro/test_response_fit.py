"""Radiation fits judged by what the device does (issue 37): the error that sets the order is the
change the fit makes in the device's own response (module mbcontrol.hydro.fit.response_error), checked
here against independent paths: the linearised CasADi plant against the BEM-direct frequency-domain
solution and the BEM-direct PTO admittance (mbcontrol.analysis), and a time-domain run.

flap14 (tests/hydro/data) is a held-out flap nobody tuned a fit for: no [hydro] response_band."""
import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.analysis import (frequency_domain_response, linearize, regular_wave_amplitudes,
                                statespace_response)
from mbcontrol.analysis.ports import port_responses
from mbcontrol.hydro import fit_radiation
from mbcontrol.hydro.fit.radiation import RadiationFitWarning
from mbcontrol.plant import build_plant, device_around, linear_params
from mbcontrol.scene import load_scene

FLAP = str(Path(__file__).resolve().parents[2] / "hydro" / "data" / "flap14.toml")


@pytest.fixture(scope="module")
def flap():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RadiationFitWarning)   # its report is asserted on below
        return build_plant(FLAP)


def _free_admittance(plant, omega):
    """(fitted, BEM-direct) PTO admittance, PTO free: the linearised state-space plant (exp(+iωt),
    conjugated to the BEM's exp(-iωt)) and mbcontrol.analysis.ports straight from the data."""
    sys = linearize(plant, params=linear_params(plant, ["pto"]))
    A, B, C = (np.asarray(m) for m in (sys.A, sys.B, sys.C))
    iu, iy = sys.input_labels.index("u__pto"), sys.output_labels.index("pto__velocity")
    fitted = np.array([C[iy] @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B[:, iu]) for w in omega])
    return np.conj(fitted), port_responses(plant, omega, ["pto"])[0][:, 0, 0]


def test_held_out_flap_matches_its_frequency_domain_solution(flap):
    """Time domain (the nonlinear plant with the fitted radiation, started on its periodic
    solution, 1 cm waves) against the BEM-direct frequency-domain solution at 12, 14 and 16 s:
    within 2 % (issue 37; with the kernel-judged fit it was +0.1 %, -0.9 %, -3.6 %). Measured
    +0.06 %, +0.01 %, +0.01 %."""
    assert load_scene(FLAP).hydro.response_band is None
    assert flap.hydro.radiation.report["limited_by"] == "device response"
    omegas = 2 * np.pi / np.array([12.0, 14.0, 16.0])
    td = regular_wave_amplitudes(flap, linearize(flap), omegas, ["hinge"], height=0.01, periods_measure=4)[:, 0]
    fd = np.abs(frequency_domain_response(flap, omegas, outputs=["hinge"]))[:, 0]
    np.testing.assert_allclose(td, fd, rtol=0.02)


def test_the_reported_response_error_is_the_admittance_error(flap):
    """The fit's response error (one coordinate: |Y_fit / Y_data - 1| where the device moves) is
    what an independent path measures: the linearised plant's PTO admittance against the BEM-direct
    one, at the frequency the report names and as the largest over the band."""
    rep = flap.hydro.radiation.report
    w = flap.hydro.omega
    fitted, data = _free_admittance(flap, w)
    rel = np.abs(fitted / data - 1)
    k = int(np.argmin(np.abs(w - rep["response_worst"]["omega"])))
    assert rep["response_worst"]["weight"] == 1.0 and rep["fit_error"] == rep["response_error"]
    assert rel[k] == pytest.approx(rep["response_error"], rel=1e-3)
    assert rel.max() == pytest.approx(rep["response_error"], rel=1e-3)


def test_kernel_error_where_the_device_does_not_move_is_accepted():
    """rm3 judged by its response (the catalogue ships it judged by the kernel): the fit's kernel
    is off by more than 100 % at its worst frequency (the plate's small damping at the band's
    edge), yet it meets its tolerance on the response, and the linearised plant's motion there
    agrees with the BEM-direct solution within that tolerance of each coordinate's peak (the
    catalogue's TD = FD measure). Measured: kernel 499 %, response 0.69 %, 44 states."""
    scene = load_scene("rm3")
    scene = dataclasses.replace(scene, hydro=dataclasses.replace(scene.hydro, fit_judged_by="response"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RadiationFitWarning)
        plant = build_plant(scene)
    rep = plant.hydro.radiation.report
    assert rep["tol_met"] and rep["response_error"] <= rep["tol"] and rep["band_error"] > 1.0
    omega = np.array([rep["worst"]["omega"]])
    coords = list(plant.topology.tree.coordinate_names)
    ss = statespace_response(linearize(plant), plant, omega, outputs=coords)
    band = np.geomspace(0.3, 2.0, 25)
    peak = np.abs(frequency_domain_response(plant, band, outputs=coords)).max(axis=0)
    fd = frequency_domain_response(plant, omega, outputs=coords)
    assert np.all(np.abs(ss - fd)[0] <= rep["tol"] * peak)


def test_a_large_response_error_is_refused_and_confirmed(flap):
    """Too few poles: the fit warns with its response error and where, and the linearised plant's
    admittance, against the BEM-direct one, confirms the number."""
    scene = load_scene(FLAP)
    hydro = flap.hydro
    device = device_around(scene, hydro.source, hydro.data, hydro.dofs)
    with pytest.warns(RadiationFitWarning, match=r"response error .* in the device's response") as caught:
        model = fit_radiation(hydro.data, list(hydro.dofs), tol=0.01, max_order=2, passive=False, device=device)
    rep = model.report
    assert rep["response_error"] > 0.05 and f"{rep['response_error']:.2%}" in str(caught[0].message)
    assert f"{rep['response_worst']['omega']:.4g} rad/s" in str(caught[0].message)
    from mbcontrol.hydro import HydroModel
    coarse = build_plant(scene, HydroModel(hydro.dofs, hydro.data, model, hydro.source))
    worst = rep["response_worst"]
    fitted, data = _free_admittance(coarse, np.array([worst["omega"]]))
    assert np.abs(fitted / data - 1)[0] * worst["weight"] == pytest.approx(rep["response_error"], rel=1e-3)
