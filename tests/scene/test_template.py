"""Scene [parameters] and `repeat` entries (mbcontrol.scene.template), and the new scene tables."""
import math
import tomllib
from pathlib import Path

import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import load_scene, parse_scene

CHAIN = """
name = "chain"
[parameters]
N = 3
L = 2.0
[[body]]
repeat = "i = 1..N"
name = "b{i}"
mass = "{10 * i}"
inertia = [1.0, 1.0, 1.0]
cog = ["{(i - 1) * L + L / 2}", 0.0, "{0.5} m"]
hydro = false
[[joint]]
name = "root"
type = "fixed"
parent = "ground"
child = "b1"
point = [0.0, 0.0, 0.0]
[[joint]]
repeat = "i = 2..N"
name = "hinge{i - 1}"
type = "revolute"
parent = "b{i - 1}"
child = "b{i}"
point = ["{(i - 1) * L}", 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
"""


def _scene(text, parameters=None):
    return parse_scene(tomllib.loads(text), Path("chain.toml"), parameters)


def test_repeat_and_expressions():
    scene = _scene(CHAIN)
    assert [b.name for b in scene.bodies] == ["b1", "b2", "b3"]
    assert [b.mass for b in scene.bodies] == [10.0, 20.0, 30.0]
    assert [b.cog for b in scene.bodies] == [(1.0, 0.0, 0.5), (3.0, 0.0, 0.5), (5.0, 0.0, 0.5)]
    assert [(j.name, j.parent, j.child, j.point[0]) for j in scene.joints[1:]] == [
        ("hinge1", "b1", "b2", 2.0), ("hinge2", "b2", "b3", 4.0)]
    assert scene.parameters == {"N": 3, "L": 2.0}


def test_override_changes_the_family_member():
    scene = _scene(CHAIN, {"N": 5})
    assert len(scene.bodies) == 5 and len(scene.joints) == 5
    assert scene.parameters["N"] == 5


def test_catalogue_barge_chain_scales_with_n():
    for n in (2, 8):
        scene = load_scene("barge_chain", {"N": n})
        assert len(scene.bodies) == n and len(scene.ptos) == n - 1
        assert Path(scene.hydro.file).name == f"barge_chain_N{n}_hydro.nc"
        assert not scene.hydro.interaction
        # hinges mid-gap between neighbours: 0.6 m barges, 0.1 m gaps
        assert scene.joint(f"hinge{n - 1}").point[0] == pytest.approx((n - 1) * 0.7 - 0.05)


@pytest.mark.parametrize("change, message", [
    (("N", "{N + }"), r"cannot evaluate \{N \+ \}"),
    (("repeat", "i in 1..N"), r"repeat: expected '<name> = <first>..<last>'"),
    (("mass", "{M * 2}"), r"unknown name 'M'"),
    (("mass", "{__import__('os')}"), r"is not allowed"),
    (("repeat", "i = 1..0.5"), r"whole-number bounds"),
])
def test_template_errors_name_the_field(change, message):
    key, value = change
    text = CHAIN.replace('mass = "{10 * i}"', f'mass = "{value}"') if key in ("mass", "N") else \
        CHAIN.replace('repeat = "i = 1..N"', f'repeat = "{value}"', 1)
    with pytest.raises(SceneError, match=message):
        _scene(text)


def test_unknown_override_is_an_error():
    with pytest.raises(SceneError, match=r"\['M'\] not declared; the scene's parameters are \['L', 'N'\]"):
        _scene(CHAIN, {"M": 2})


STOP = CHAIN + """
[[end_stop]]
joint = "hinge1"
lower = "{LOWER}"
upper = "{UPPER}"
stiffness = 1e4
"""


def test_end_stop_parsed_with_units():
    scene = _scene(STOP.replace('"{LOWER}"', '"-10 deg"').replace('"{UPPER}"', '"20 deg"'))
    (stop,) = scene.end_stops
    assert stop.name == "hinge1_stop" and stop.lower == pytest.approx(-math.pi / 18)
    assert stop.upper == pytest.approx(math.pi / 9) and stop.damping == 0.0


@pytest.mark.parametrize("lower, upper, message", [
    ("0.1", "0.2", r"end_stop\[0\]\.lower: the rest position .* must lie strictly between"),
    ("-0.2", "-0.1", r"end_stop\[0\]\.upper: the rest position"),
    ("0.2", "-0.1", r"end_stop\[0\]\.upper: expected upper > lower"),
    ("-0.1", "'3 kg'", r"end_stop\[0\]\.upper: expected an angle"),
    # hinge1 is revolute: a length is refused (it was read as radians before issue 22)
    ("-0.1", "'20 mm'", r"end_stop\[0\]\.upper: expected an angle in one of \['deg', 'rad'\], got '20 mm'"),
])
def test_end_stop_narrower_than_rest_is_an_error(lower, upper, message):
    text = STOP.replace('"{LOWER}"', lower).replace('"{UPPER}"', upper.replace("'", '"'))
    with pytest.raises(SceneError, match=message):
        _scene(text)


def test_end_stop_on_unknown_joint():
    text = STOP.replace('joint = "hinge1"\nlower', 'joint = "hinge9"\nlower')
    text = text.replace('"{LOWER}"', "-0.1").replace('"{UPPER}"', "0.1")
    with pytest.raises(SceneError, match=r"end_stop\[0\]\.joint: expected a joint with one coordinate"):
        _scene(text)


def test_a_parameter_may_follow_those_before_it():
    """A derived parameter ("{expr}" of the ones declared before it) follows an override of
    them, may itself be overridden, and may not name one declared after it."""
    text = CHAIN.replace("L = 2.0", 'L = 2.0\nhalf = "{L / 2}"').replace(
        'cog = ["{(i - 1) * L + L / 2}"', 'cog = ["{(i - 1) * L + half}"')
    scene = _scene(text, {"L": 4.0})
    assert scene.parameters["half"] == 2.0 and scene.bodies[1].cog[0] == pytest.approx(6.0)
    assert _scene(text, {"half": 0.5}).bodies[0].cog[0] == pytest.approx(0.5)
    with pytest.raises(SceneError, match="parameters.half: cannot evaluate"):
        _scene(text.replace('half = "{L / 2}"', 'half = "{M / 2}"'))
    with pytest.raises(SceneError, match="parameters.L: expected a number or"):
        _scene(text.replace("L = 2.0", 'L = "two"'))
