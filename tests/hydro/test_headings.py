"""Excitation between the hydro data's headings (mbcontrol.hydro.headings) and the headings a
spread needs: each value by hand from the data, each error with its file and its fix."""
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import HydroError
from mbcontrol.hydro import HydroModel, headings_for_spread, read_netcdf
from mbcontrol.hydro.headings import covers_circle, heading_weights

MODELS = Path(__file__).resolve().parents[2] / "models"


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
    assert covers_circle(circle) and not covers_circle(np.radians(np.arange(-90, 91, 15)))
    # 172.5 deg between 165 and 180 (= -180) deg: half way, across the wrap
    lo, hi, t = heading_weights(circle, [math.radians(172.5), math.radians(-172.5)], "x")
    assert {circle[lo[0]], circle[hi[0]]} == {circle[-1], circle[0]} and t[0] == pytest.approx(0.5)
    assert t[1] == pytest.approx(0.5)
    with pytest.raises(HydroError, match="outside"):
        heading_weights(np.radians(np.arange(-90, 91, 15)), [math.radians(100.0)], "half.nc")


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
