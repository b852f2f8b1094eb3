"""Units in scene files: "60 mm", "5 deg" and friends to SI (mbcontrol.scene.units)."""
from __future__ import annotations

import math
from pathlib import Path

import pytest

from mbcontrol.scene.units import UnitError, to_si

# ----------------------------------------------------------------------------- units.to_si

def test_to_si_conversions():
    # Factors from the SI definitions (1 mm = 1e-3 m, 1 deg = pi/180 rad, 1 Hz = 2 pi rad/s
    # for an angular frequency); one multiplication each: 1e-15 relative covers the rounding.
    assert to_si("25 mm", "length") == pytest.approx(0.025, rel=1e-15)
    assert to_si("25mm", "length") == pytest.approx(0.025, rel=1e-15)     # space optional
    assert to_si("1.5e3 mm", "length") == pytest.approx(1.5, rel=1e-15)
    assert to_si("-2 cm", "length") == pytest.approx(-0.02, rel=1e-15)
    assert to_si("2 km", "length") == 2000.0
    assert to_si("180 deg", "angle") == pytest.approx(math.pi, rel=1e-15)
    assert to_si("5 deg", "angle") == pytest.approx(5 * math.pi / 180, rel=1e-15)
    assert to_si("1 Hz", "frequency") == pytest.approx(2 * math.pi, rel=1e-15)
    assert to_si("0.25 Hz", "frequency") == pytest.approx(math.pi / 2, rel=1e-15)
    assert to_si("3 rad/s", "frequency") == 3.0
    assert to_si("2 t", "mass") == 2000.0
    assert to_si("1 min", "time") == 60.0
    assert to_si("1 kg m^2", "inertia") == 1.0


def test_to_si_plain_numbers():
    # numbers are SI already, whatever the dimension, including no dimension
    for dimension in ("length", "mass", "angle", "frequency", None):
        assert to_si(3, dimension) == 3.0 and isinstance(to_si(3, dimension), float)
        assert to_si(-0.5, dimension) == -0.5
        assert to_si("7", dimension) == 7.0          # a string without a unit is a number
        assert to_si(".5", dimension) == 0.5


@pytest.mark.parametrize("value, dimension, message", [
    ("heavy", "mass", r"expected a number or '<number> <unit>', got 'heavy'"),
    ("", "length", r"expected a number or '<number> <unit>', got ''"),
    ("mm 25", "length", r"expected a number or '<number> <unit>'"),
    ("3 kg", "length", r"expected a length in one of \['cm', 'km', 'm', 'mm'\], got '3 kg'"),
    ("5 deg", "mass", r"expected a mass in one of \['g', 'kg', 't'\], got '5 deg'"),
    ("1 Hz", "angle", r"expected an? angle in one of"),
    ("2 N*s/m", None, r"expected a plain SI number here, got a unit in '2 N\*s/m'"),
    (True, "mass", r"expected a number, got the boolean True"),
    (None, "mass", r"expected a number, got NoneType None"),
    ([1.0], "length", r"expected a number, got list \[1\.0\]"),
])
def test_to_si_errors(value, dimension, message):
    with pytest.raises(UnitError, match=message):
        to_si(value, dimension)


def _copy(tmp_path, model: str, *edits) -> Path:
    """A catalogue scene copied elsewhere, its hydro file pointed back at the catalogue's."""
    from mbcontrol.scene import catalogue_dir
    text = (catalogue_dir() / f"{model}.toml").read_text()
    text = text.replace(f'file = "{model}_hydro.nc"', f'file = "{catalogue_dir()}/{model}_hydro.nc"')
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / f"my_{model}.toml"
    path.write_text(text)
    return path


def test_pto_limits_take_units_of_their_joint(tmp_path):
    """A prismatic PTO's limits in "MN" and "mm", a revolute one's in "N m" and "deg": the same
    SI values as the catalogue's plain numbers; a moment on a prismatic joint is refused,
    naming the file, the field and what was expected."""
    from mbcontrol.errors import SceneError
    from mbcontrol.scene import load_scene
    sphere = load_scene(str(_copy(tmp_path, "sphere", ("force_max = 2.0e6", 'force_max = "2 MN"'),
                                  ("stroke_max = 4.0", 'stroke_max = "4000 mm"'))))
    assert (sphere.ptos[0].force_max, sphere.ptos[0].stroke_max) == (2.0e6, 4.0)
    barge = load_scene(str(_copy(tmp_path, "hinged_barge", ("force_max = 5.0", 'force_max = "5 N m"'))))
    assert barge.ptos[0].force_max == 5.0
    bad = _copy(tmp_path, "sphere", ("force_max = 2.0e6", 'force_max = "2 MN m"'))
    with pytest.raises(SceneError, match=r"my_sphere.toml.*force_max: expected a force in one "
                                         r"of \['MN', 'N', 'kN'\], got '2 MN m'"):
        load_scene(str(bad))


def test_a_copied_scene_names_its_missing_hydro_file_and_the_remedy(tmp_path):
    from mbcontrol.errors import HydroError
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import catalogue_dir
    path = tmp_path / "my_sphere.toml"
    path.write_text((catalogue_dir() / "sphere.toml").read_text())
    with pytest.raises(HydroError) as err:
        build_plant(str(path))
    text = str(err.value)
    assert text.startswith(f"{path}: [hydro] file 'sphere_hydro.nc'")
    assert f"cp {catalogue_dir() / 'sphere_hydro.nc'} {tmp_path}/" in text
    assert "[hydro] omega" in text
    assert "Its [hydro] source" in text and "sphere.out is not there either" in text
