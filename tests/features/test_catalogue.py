"""Every catalogue model loads, builds and rests in equilibrium, and its precomputed hydro
data were made from what its scene file says (so regenerating reproduces them)."""
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import readme
from mbcontrol.hydro import read_netcdf
from mbcontrol.plant import build_plant
from mbcontrol.scene import list_models, load_scene


@pytest.mark.parametrize("name", list_models())
def test_hydro_file_matches_scene(name):
    scene = load_scene(name)
    if not scene.hydro.file:
        pytest.skip(f"{name} has no precomputed hydro file")
    data = read_netcdf(scene.hydro.file)
    assert data.attrs["rho"] == scene.water.rho and data.attrs["g"] == scene.water.g
    assert data.attrs["depth"] == scene.water.depth
    if scene.hydro.omega:       # the grid the scene asks for is the grid in the file
        np.testing.assert_allclose(data["omega"].values, scene.hydro.omega, rtol=1e-12)
    if scene.hydro.source:      # converted from third-party data: which file, mapped how
        assert data.attrs["converted_from"] == Path(scene.hydro.source).name
    for body in (b for b in scene.bodies if b.hydro):
        if "mass" in data:      # a BEM run of ours records the mass it used
            np.testing.assert_allclose(data["mass"].sel(body=body.name).values, body.mass)
        # the body frames are at the scene's CoGs
        np.testing.assert_allclose(data["cog"].sel(body=body.name).values, body.cog)
        dofs = {d.split("__")[1] for d in data["radiating_dof"].values.tolist()
                if d.startswith(body.name + "__")}
        assert dofs == set(scene.hydro.dofs)


@pytest.mark.parametrize("name", list_models())
def test_model_builds_at_rest(name):
    plant = build_plant(name)
    xdot = np.asarray(plant.f(plant.x0(), 0, 0, plant.p0)).ravel()
    # rest is an equilibrium: masses are given to ~10 digits (rho V), so the drift left is
    # below 1e-9 g, nothing a simulation could show
    assert np.max(np.abs(xdot)) < 1e-9 * plant.scene.water.g
    rad = plant.hydro.radiation
    assert np.max(np.linalg.eigvals(rad.A).real) < 0                      # stable
    assert rad.report["passivity"]["passive"]                              # passive (exact test)


@pytest.mark.parametrize("name", list_models())
def test_radiation_fit_meets_scene_tolerance(name):
    """The fit each scene ships meets its tolerance, and the README's table of catalogue fits
    shows it as it is: the measure that judged it, its DOFs, states and error."""
    plant = build_plant(name)
    tol = load_scene(name).hydro.radiation_tol
    if name in KNOWN_FIT_SHORTFALL:       # the data's own limit, stated and held to it
        tol = KNOWN_FIT_SHORTFALL[name]
    rad = plant.hydro.radiation
    assert rad.fit_error <= tol
    _, dofs, judged, states, error = readme.row("catalogue fit", name)[:5]
    assert judged.startswith("response" if rad.report.get("response_error") is not None else "kernel")
    assert readme.numbers(dofs) == [len(rad.dofs)] and readme.numbers(states) == [rad.order]
    assert abs(readme.numbers(error)[0] - 100 * rad.fit_error) <= 0.0051     # shown to 0.01 %


# flume_section: its strip heave damping wiggles below 4.5 rad/s (a residue of differencing two
# prisms, models/flume_section_2d.py) which no passive fit follows: the heave group alone is 9.6 %
# (it warns, loudly, on every load), sway and roll 0.75 %, total 4.24 % at 24 states (3.65 % at 50
# before issue 20, whose fits no longer retarget every group when one cannot meet tol)
KNOWN_FIT_SHORTFALL = {"flume_section": 0.043}


# wave band per model (rad/s): where its seas carry energy (tank models: periods 0.5-3 s)
WAVE_BANDS = {"hinged_barge": (3.0, 14.0), "hinged_raft": (3.0, 14.0), "raft3": (3.0, 12.0),
              "barge_chain": (3.0, 12.0), "array4": (2.0, 12.0), "array_grid": (2.0, 12.0), "flap_pair": (1.0, 4.5),
              "sphere": (0.3, 2.5), "rm3": (0.3, 2.0), "rm3_moored": (0.3, 2.0),
              "wavestar": (2.0, 12.0),
              "flume_section": (4.0, 10.0), "oswec": (0.3, 2.0), "wavebot": (1.0, 6.0)}
# oswec: the band includes its 18 s pitch resonance (0.347 rad/s), damped almost only by the PTO,
# where the radiation damping is 1e-3 of its peak; a fit judged by a global norm over the band was
# 16 % under the BEM-direct peak there (15.4 against 18.3 rad/m), so this band used to start at
# 0.37 rad/s. Judged per frequency in its response band (issue 20), it holds to 2 % through it.


def test_every_model_has_a_wave_band():
    assert set(WAVE_BANDS) == set(list_models())


@pytest.mark.parametrize("name", list_models())
def test_linearisation_matches_frequency_domain(name):
    """The linearised control-plant (state-space radiation, exact Jacobians) against the
    frequency-domain solution straight from the BEM data, per joint coordinate and heading.

    Measure: amplitude error |(|H_ss| - |H_fd|)| relative to the coordinate's peak |H_fd| over
    the band (a response notch makes a per-frequency ratio meaningless), within 2 % (issue 4),
    and the per-frequency ratio within 2 % wherever the response is at least half its peak."""
    from mbcontrol.analysis import frequency_domain_response, linearize, statespace_response

    plant = build_plant(name)
    linear_only = {n: 0.0 for n in plant.parameters if n.endswith("__coulomb")}  # no Coulomb in FD
    sys = linearize(plant, params=linear_only)
    omegas = np.geomspace(*WAVE_BANDS[name], 25)
    coords = list(plant.topology.tree.coordinate_names)
    for direction in plant.hydro.data["wave_direction"].values:
        fd = np.abs(frequency_domain_response(plant, omegas, outputs=coords, params=linear_only,
                                              direction=float(direction)))
        ss = np.abs(statespace_response(sys, plant, omegas, outputs=coords, direction=float(direction)))
        peak = fd.max(axis=0)
        moving = peak > 1e-6 * peak.max()          # e.g. sway of a head-sea model: nothing to compare
        tol = np.array([KNOWN_LTI_SHORTFALL.get((name, c), 0.02) for c in coords])
        assert np.all((np.abs(ss - fd) <= tol * peak)[:, moving]), (name, direction)
        strong = fd >= 0.5 * peak
        assert np.all((np.abs(ss / np.where(strong, fd, 1) - 1) <= tol)[strong]), (name, direction)


# flume_section's heave: the strip data's wiggles below 4.5 rad/s (above) pull its radiation
# fit off: measured 5.3 % of the peak (amplitude) and 6.8 % (ratio) since issue 20's fits (2.3 %
# and 3.2 % before: its heave group then got more states, retargeted with the others); sway and
# roll are held to 2 %
# rm3_moored's surge and pitch: its lines' stiffness gives the device a surge mode (66 s,
# barely damped), and its fit meets the device's response at 0.4 rad/s to 10 % at best (guide:
# catalogue fits); measured 2.75 % (surge) and 2.20 % (pitch) of the peak there, heave 0.26 %
KNOWN_LTI_SHORTFALL = {("flume_section", "heave"): 0.07,
                       ("rm3_moored", "plate_motion__Surge"): 0.03,
                       ("rm3_moored", "plate_motion__Pitch"): 0.03}
