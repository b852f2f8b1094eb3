"""The flume section against the real tank data (../shared/data/tank): its 2-D hydro data
against the Haskind relation, its natural periods against the decay tests, and the identified
model against every usable run of the three 2-DOF series, with cross-validation by series."""
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import readme
from mbcontrol.hydro import read_netcdf
from mbcontrol.hydro.model import fit_band_limit
from mbcontrol.scene import load_scene
from mbcontrol.studies.identify import ExtrapolationWarning, IdentifiabilityWarning, fit
from mbcontrol.studies.identify.extrapolation import radiation_limit
from mbcontrol.studies.identify import report as rep
from mbcontrol.studies.identify.flume import load_runs
from mbcontrol.studies.identify.setup import flume_identification, prediction
from mbcontrol.waves import group_velocity

TANK = Path(__file__).resolve().parents[5] / "shared" / "data" / "tank"
if not TANK.exists():
    pytest.skip(f"tank data not found at {TANK}", allow_module_level=True)
RHO, G, SPAN, DEPTH = 1000.0, 9.81, 0.586, 1.0


def _data():
    return read_netcdf(load_scene("flume_section").hydro.file)


def _entry(ds, var, dof):
    d = f"section__{dof}"
    return ds[var].sel(radiating_dof=d, influenced_dof=d).values


@pytest.mark.parametrize("dof", ["Sway", "Roll"])
def test_strip_data_obey_haskind(dof):
    """B = |X|^2 / (2 rho g c_g L) for a 2-D body symmetric about its centre plane: radiation
    and diffraction, solved separately by the BEM, must agree over the tank band (heave's
    excitation is set from this relation by the generating script, so it is no check)."""
    ds = _data()
    band = (ds["omega"].values >= 4.0) & (ds["omega"].values <= 9.3)
    X = ds["excitation_force"].sel(influenced_dof=f"section__{dof}").isel(wave_direction=0)
    cg = np.array([group_velocity(w, DEPTH, G) for w in ds["omega"].values])
    ratio = np.abs(X.values) ** 2 / (2 * RHO * G * cg * SPAN * _entry(ds, "radiation_damping", dof))
    assert np.all(np.abs(ratio[band] - 1) < 0.04), ratio[band]


def _natural_period(ds, dof, inertia, stiffness):
    """T_n with omega^2 (I + A(omega)) = C, by fixed point on the data's A(omega)."""
    w, A = ds["omega"].values, _entry(ds, "added_mass", dof)
    omega = math.sqrt(stiffness / inertia)
    for _ in range(50):
        omega = math.sqrt(stiffness / (inertia + np.interp(omega, w, A)))
    return 2 * math.pi / omega


def test_natural_periods_match_the_decay_tests():
    """The tank README's decay tests: heave 1.17 s; roll 1.28 s with sway clamped. Mass and
    inertia as the scene has them (heave moves section and axle; roll the section only)."""
    ds, scene = _data(), load_scene("flume_section")
    bodies = {b.name: b for b in scene.bodies}
    K = {d: _entry(ds, "hydrostatic_stiffness", d) for d in ("Heave", "Roll")}
    heave = _natural_period(ds, "Heave", bodies["section"].mass + bodies["axle"].mass,
                            float(K["Heave"]))
    roll = _natural_period(ds, "Roll", bodies["section"].inertia[0][0], float(K["Roll"]))
    assert heave == pytest.approx(1.17, rel=0.03)
    assert roll == pytest.approx(1.28, rel=0.03)


@pytest.fixture(scope="module")
def runs():
    with pytest.warns(UserWarning, match="4061_2"):          # its sway track is flat zero
        return load_runs(sorted((TANK / "scenario_c").glob("[456]*.csv.xz")), drop_bad=True)




def _readme_row(first_cell: str) -> dict:
    """A row of the README's identification table (RMS relative amplitude error per DOF), read
    from README.md itself so the two cannot drift apart."""
    header = readme.table("", with_header=True)[0]            # | | sway | heave | roll |
    cells = readme.row("", first_cell)
    return {dof.capitalize(): readme.numbers(cell)[0] / 100 for dof, cell in
            zip(header[1:], cells[1:])}


README_IDENTIFIED = _readme_row("identified")
README_HELD_OUT = _readme_row("each series predicted")      # worst over the series


def _errors(problem, values, omega_max=np.inf):
    rows = [r for r in rep.amplitude_rows(problem, values) if r["omega"] <= omega_max]
    return {c: e["rms_relative_error"] for c, e in rep.channel_errors(rows).items()}


def test_identified_model_reproduces_every_run(runs):
    """All 31 usable runs, the scene's default parameters, Gauss-Newton on the harmonic cost:
    each free DOF within the README's identified errors (its table, read here). Where the radiation
    model was fitted (the runs at or below 6.67 rad/s, the last BEM frequency under the data's
    mesh limit, 6.99 rad/s; 18 of the 31, the other 13 flagged as extrapolated) roll and sway at
    least twice as close as the model with the scene's values (potential flow, rig data), heave
    closer. Above it the model extrapolates the fit (runs at 7-9.3 rad/s): there two passive fits
    of equal error in the band (1 % in sway and roll) put the identified sway 6.6 % or 7.8 % off
    over all runs (the previous parameter set), so no improvement ratio is claimed there (issue
    21: extrapolation said aloud)."""
    assert len(runs) == 31
    with pytest.warns(ExtrapolationWarning, match=r"fit runs 4101_2 \(7\), .* rad/s: above the "
                                                  r"radiation fit's 6.67 rad/s"):
        problem = flume_identification("flume_section", None, runs=runs)
    fitted = radiation_limit(problem)          # the last BEM frequency under the mesh limit
    scene = load_scene("flume_section")
    assert fitted == pytest.approx(6.672, abs=1e-3)
    assert fit_band_limit(read_netcdf(scene.hydro.file), scene.hydro.fit_omega_max) \
        == pytest.approx(6.99, abs=0.01)
    # the scene's set (chosen by cross-validation): none at a bound, every sigma finite
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fit(problem, "gauss-newton")
    assert not [w for w in caught if issubclass(w.category, IdentifiabilityWarning)], caught
    assert result.at_bound == {} and all(np.isfinite(list(result.std.values())))
    assert 0.7 < result.values["section__Roll__radiation_scale"] < 1.0
    rows = rep.amplitude_rows(problem, result.values)
    assert {r["run"] for r in rows if r["extrapolated"]} == {r.name for r in runs
                                                             if r.omega > fitted}
    assert len({r["run"] for r in rows if r["extrapolated"]}) == 13
    # the data's floor: repetitions within a series agree to 1.3-2.1 % RMS (measured)
    floor = rep.repeatability(rows)
    assert {c: f["sets"] for c, f in floor.items()} == {"Heave": 4, "Roll": 7, "Sway": 5}
    assert all(f["rms_relative_spread"] < 0.025 for f in floor.values()), floor
    after = _errors(problem, result.values)
    assert set(after) == {"Sway", "Heave", "Roll"}
    # the README's table, half a point allowed for another machine's rounding
    for dof, claimed in README_IDENTIFIED.items():
        assert after[dof] <= claimed + 0.005, (dof, after)
    before, after = _errors(problem, {}, fitted), _errors(problem, result.values, fitted)
    assert before["Roll"] >= 2 * after["Roll"] and before["Sway"] >= 2 * after["Sway"], \
        (before, after)
    assert after["Heave"] < before["Heave"]
    assert 0.7 < result.values["section__Roll__added_mass_scale"] < 1.0


@pytest.mark.parametrize("held_out", [4, 5, 6])
def test_cross_validation_by_series(runs, held_out):
    """Each series predicted by a fit on the other two: every free DOF within the README's
    worst held-out error for that DOF (its table, read here; issue 21 asks at most 20 %)."""
    train = [r for r in runs if not r.name.startswith(str(held_out))]
    test = [r for r in runs if r.name.startswith(str(held_out))]
    problem = flume_identification("flume_section", None, runs=train)
    result = fit(problem, "gauss-newton")
    predicted = _errors(prediction(problem, test), result.values)
    for dof, error in predicted.items():
        assert error <= README_HELD_OUT[dof] + 0.005, (dof, predicted)
