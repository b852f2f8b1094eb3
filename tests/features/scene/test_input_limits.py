"""Hostile and odd scene input is refused by the field that holds it, quickly: expressions
within their limits (mbcontrol.scene.template), quantities within physical ranges
(mbcontrol.scene.units.PHYSICAL_MAX), scene files within their size (scene.load)."""
import time

import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene
from mbcontrol.scene.load import MAX_SCENE_BYTES
from mbcontrol.scene.template import MAX_EXPRESSION_CHARS, MAX_MAGNITUDE, MAX_OPERATIONS

from tests.helpers.scene_fixture import fails, variant, write

# Python's exact integer power of 9**9**9**9 never returns; each refusal here takes microseconds,
# so a second is a hang, not a slow machine.
QUICK_S = 1.0


def _mass(tmp_path, text: str):
    return write(tmp_path, variant(("mass = 10.0", f"mass = {text}")))


@pytest.mark.parametrize("expression, why", [
    ("9**9**9**9", "the power 9\\*\\*387420489 is beyond"),          # hung for ever
    ("10**19", "beyond"),                                           # just past the magnitude
    ("(2**60)*(2**60)", "beyond"),                                  # a product, not a power
    ("(" * 150 + "1" + ")" * 150, "301 characters"),                # MemoryError when longer
    ("+".join(["1"] * 40), f"{2 * 40 - 1} numbers, names and operators"),
    ("-" * 70 + "1", "numbers, names and operators"),               # a deep unary chain
    ("__import__('os').system('true')", "is not allowed"),          # calls are not arithmetic
    ("(1).real", "is not allowed"),                                 # nor attributes
    ("(-8)**0.5", "not a real number"),                             # complex, not a mass
    ("1/0", "division by zero"),
])
def test_an_expression_beyond_its_limits_is_refused_quickly(tmp_path, expression, why):
    path = _mass(tmp_path, f'"{{{expression}}}"')
    start = time.perf_counter()
    with fails(path, "body[0].mass", "cannot evaluate .*" + why):
        load_scene(path)
    assert time.perf_counter() - start < QUICK_S


def test_a_limit_message_states_the_limits(tmp_path):
    path = _mass(tmp_path, '"{9**9**9**9}"')
    with pytest.raises(SceneError) as err:
        load_scene(path)
    text = str(err.value)
    assert f"at most {MAX_EXPRESSION_CHARS} characters and {MAX_OPERATIONS}" in text
    assert f"{MAX_MAGNITUDE:g}" in text


def test_expressions_inside_the_limits_still_work(tmp_path):
    # the catalogue's longest expression has 86 characters (models/array_grid.toml); these sit
    # at the limits and must keep working: 2**59 exactly, 31 additions (63 nodes of 64)
    path = write(tmp_path, variant(("mass = 10.0", 'mass = "{2**59 / 2**59 * 10}"'),
                                   ("mass = 20.0", 'mass = "{' + "+".join(["0.5"] * 31) + ' + 4.5}"')))
    scene = load_scene(path)
    assert [b.mass for b in scene.bodies] == [10.0, 20.0]


def test_infinity_is_a_value_a_scene_may_mean(tmp_path):
    # array_grid: cutoff = inf couples every float; inf times a spacing stays inf
    from mbcontrol.scene.template import evaluate
    assert evaluate("cutoff * spacing", {"cutoff": float("inf"), "spacing": 20.0}, "f", "w") \
        == float("inf")
    with pytest.raises(SceneError, match="not a number"):
        evaluate("cutoff - cutoff", {"cutoff": float("inf")}, "f", "w")


@pytest.mark.parametrize("value, dimension", [
    ("1e30", "mass"), ('"1e12 t"', "mass"), ("-1e11", "mass"), ('"200 km"', "length"),
])
def test_a_value_far_beyond_its_physical_range_is_refused_by_its_field(tmp_path, value,
                                                                      dimension):
    """Mass 1e30 used to build a plant and fail later as a 'diverged: try a smaller dt'."""
    if dimension == "mass":
        path = _mass(tmp_path, value)
        field = "body[0].mass"
    else:
        path = write(tmp_path, variant(("cog = [0.5, 0.0, 0.0]", f"cog = [{value}, 0.0, 0.0]")))
        field = "body[0].cog"
    with fails(path, field, f".*beyond the physical range of an? {dimension}"):
        load_scene(path)


def test_the_largest_real_devices_are_inside_the_ranges(tmp_path):
    # a 6e8 kg hull (the largest floating structures) and 11 km of depth load
    path = write(tmp_path, variant(("mass = 10.0", 'mass = "6e5 t"'),
                                   ("cog = [0.5, 0.0, 0.0]", 'cog = ["11 km", 0.0, 0.0]')))
    assert load_scene(path).bodies[0].mass == 6e8


def test_an_overlong_quantity_string_is_refused_without_scanning_it(tmp_path):
    path = _mass(tmp_path, '"' + "1" * 5000 + ' kg"')
    with fails(path, "body[0].mass", "expected a number or '<number> <unit>' of at most 64"):
        load_scene(path)


def test_a_scene_file_too_large_or_not_a_file_is_refused(tmp_path):
    big = write(tmp_path, variant() + "#" * MAX_SCENE_BYTES + "\n", "big.toml")
    with pytest.raises(SceneError, match=f"{big}: .* bytes; expected a scene file of at most"):
        load_scene(big)
    folder = tmp_path / "folder.toml"
    folder.mkdir()
    with pytest.raises(SceneError, match="not a file"):
        load_scene(folder)
