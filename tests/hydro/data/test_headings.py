"""Excitation between the hydro data's headings (mbcontrol.hydro.data.headings) and the headings a
spread needs: each value by hand from the data, each error with its file and its fix."""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import HydroError
from mbcontrol.hydro import HydroModel, headings_for_spread, read_netcdf
from mbcontrol.hydro.data.headings import covers_circle, heading_matrix

MODELS = Path(__file__).resolve().parents[3] / "models"


@pytest.fixture(scope="module")
def array4():
    """The catalogue's four-float array: data at headings 0 and 45 deg (no fit needed here)."""
    path = MODELS / "array4_hydro.nc"
    data = read_netcdf(path)
    dofs = tuple(str(d) for d in data["influenced_dof"].values)
    return HydroModel(dofs, data, None, str(path))


def test_float_direction_keeps_the_exact_match(array4):
    w = array4.omega[[3, 10]]
    F45 = array4.data["excitation_force"].sel(wave_direction=math.pi / 4, omega=w).transpose(
        "omega", "influenced_dof").values
    # a float on a data heading: the data's own numbers, bit for bit
    assert np.array_equal(array4.excitation_at(w, math.pi / 4), F45)
    with pytest.raises(HydroError, match="headings = \\[\"10 deg\"\\]"):
        array4.excitation_at(w, math.radians(10.0))   # a float between headings: not guessed


def test_per_component_directions_interpolate_in_the_complex_plane(array4):
    w = array4.omega[[3, 10, 20]]
    F = array4.data["excitation_force"].sel(omega=w).transpose(
        "wave_direction", "omega", "influenced_dof").values            # (2, 3, n_dof)
    d = np.radians([0.0, 22.5, 45.0 - 1e-9])
    got = array4.excitation_at(w, d)
    # 0 deg: the data; 22.5 deg: half way between 0 and 45 deg; 45: the data
    assert got[0] == pytest.approx(F[0, 0], rel=1e-12)
    assert got[1] == pytest.approx(0.5 * (F[0, 1] + F[1, 1]), rel=1e-12)
    assert got[2] == pytest.approx(F[1, 2], rel=1e-9)


def test_direction_outside_the_headings_names_the_file_and_the_fix(array4):
    w = array4.omega[[3, 4]]
    with pytest.raises(HydroError) as err:
        array4.excitation_at(w, np.radians([20.0, 60.0]))
    text = str(err.value)
    assert "array4_hydro.nc" in text and "[0.0, 45.0] deg" in text and "60 deg" in text
    assert "[hydro]" in text and "headings = [" in text     # the line to add to the scene


def test_headings_wrap_only_where_they_cover_the_circle():
    circle = np.radians(np.arange(-180, 180, 15))
    half = np.radians(np.arange(-90, 91, 15))
    assert covers_circle(circle) and not covers_circle(half)
    # a smooth periodic excitation-like function of heading, sampled every 15 deg: the periodic
    # spline gives it back between the samples, across the wrap at +-180 deg too, to 5e-4
    # (cubic: error ~ h^4 f / 384 with h = 0.26 rad, f <= 16 for the 2nd harmonic)
    def f(b):
        return np.exp(2j * b) + 0.3 * np.cos(b) + 0.1j * np.sin(3 * b)
    d = np.radians([172.5, -172.5, 7.0, -97.5, 180.0])
    M = heading_matrix(circle, d, "circle.nc")
    assert M @ f(circle) == pytest.approx(f(d), abs=5e-4)
    assert M.sum(axis=1) == pytest.approx(1.0, abs=1e-12)      # constants are kept
    # over a sector the not-a-knot spline is exact for a cubic in heading
    d = np.radians([-89.0, -3.0, 44.0, 89.9])
    assert heading_matrix(half, d, "half.nc") @ (half ** 3 - half) == pytest.approx(
        d ** 3 - d, abs=1e-12)
    with pytest.raises(HydroError, match="outside"):
        heading_matrix(half, [math.radians(100.0)], "half.nc")


def test_headings_for_spread():
    # 30 deg: mean +- 90 deg on 15 deg steps
    h = headings_for_spread(0.0, math.radians(30.0))
    assert np.degrees(h) == pytest.approx(np.arange(-90, 91, 15))
    # 70 deg: +-210 deg reaches round: the whole circle, 24 headings 15 deg apart
    full = headings_for_spread(1.0, math.radians(70.0))
    assert full.size == 24 and covers_circle(full)
    # a coarse step is refined to stay within it
    assert np.max(np.diff(headings_for_spread(0.2, math.radians(10.0), math.radians(7.0)))) \
        <= math.radians(7.0) + 1e-12


def test_axisymmetric_data_serve_every_direction_in_heave_only(array4):
    from mbcontrol.hydro.data.headings import axisymmetric_headings
    from mbcontrol.plant import build_plant
    rm3 = build_plant("rm3")             # [hydro] axisymmetric = true: float and plate in heave
    hydro = rm3.hydro
    assert hydro.data.sizes["wave_direction"] == 24
    w = hydro.omega[[5, 40, 90]]
    one = hydro.excitation_at(w, 0.0)                          # the WAMIT file's own heading
    # a spline through equal values is that value (its cardinal functions sum to one): 1e-13
    assert hydro.excitation_at(w, np.radians([-170.0, 33.0, 97.5])) == pytest.approx(one,
                                                                                      rel=1e-13)
    # four floats off the z axis, in heave: refused, naming the data
    single = array4.data.isel(wave_direction=[0])
    with pytest.raises(HydroError, match="array4.*z axis"):
        axisymmetric_headings(single, array4.source)
