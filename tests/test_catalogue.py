"""Every catalogue model loads, builds and rests in equilibrium, and its precomputed hydro
data were made from what its scene file says (so regenerating reproduces them)."""
from pathlib import Path

import numpy as np
import pytest

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
    plant = build_plant(name)
    assert plant.hydro.radiation.fit_error <= load_scene(name).hydro.radiation_tol
