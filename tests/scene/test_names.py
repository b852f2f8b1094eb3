"""The name rule (`mbcontrol.textsafe.NAME_RULE`) at scene load: every name a scene gives,
refused with a SceneError naming the file and the field, the name shown safely (ascii, cut
at 80 characters: no newline or escape sequence reaches a terminal). Each case is a variant
of the valid fixture (`scene_fixture.VALID`), as in test_checks.py."""
from __future__ import annotations

import re

import pytest

from mbcontrol.errors import SceneError
from mbcontrol.scene import list_models, load_scene
from mbcontrol.textsafe import NAME_MAX, NAME_RULE, name_problem
from tests.helpers.scene_fixture import VALID, fails, variant, write

# the issue's PTO name, as TOML writes it: a newline, then a compiled #include
ISSUE_NAME = r'"pto*/\n#include\t\"/some/file\"\n/*"'
MOORING = '\n[[mooring]]\nname = "m1"\nbody = "b"\npoint = [1.5, 0.0, 0.0]\nstiffness = [1.0, 1.0, 1.0]\n'
FRICTION = '\n[[friction]]\nname = "f1"\njoint = "jb"\nviscous = 1.0\n'
END_STOP = '\n[[end_stop]]\nname = "s1"\njoint = "jb"\nlower = -1.0\nupper = 1.0\nstiffness = 1.0\n'


def _refused(path, field: str):
    """The SceneError for `field`, checked for the rule's text and a message of one line."""
    with fails(path, field, r"expected a name") as caught:
        load_scene(path)
    message = str(caught.value)
    assert NAME_RULE in message
    assert message.isprintable() and message.isascii()    # nothing raw reaches a terminal
    return message


def test_the_issues_pto_name_is_refused(tmp_path):
    path = write(tmp_path, variant(('name = "pb"', f"name = {ISSUE_NAME}")))
    message = _refused(path, "pto[0].name")
    assert r"""'pto*/\n#include\t"/some/file"\n/*'""" in message     # ascii() of the name


@pytest.mark.parametrize("field, edits", [
    ("name", [('name = "two_link"', r'name = "two*/link"')]),
    ("body[1].name", [('name = "b"', r'name = "b\nc"'), ('child = "b"', r'child = "b\nc"')]),
    ("joint[1].name", [('name = "jb"', r'name = "j\tb"'), ('joint = "jb"', r'joint = "j\tb"')]),
    ("pto[0].name", [('name = "pb"', 'name = "p-b"')]),
    ("pto[0].name", [('name = "pb"', 'name = "pb_"')]),                     # trailing '_'
    ("pto[0].name", [('name = "pb"', 'name = "p\\u00e9"')]),                 # non-ASCII
    ("pto[0].name", [('name = "pb"', f'name = "{"p" * (NAME_MAX + 1)}"')]),  # too long
    ("parameters (key 1 of 1)", [('damping = 2.0', 'damping = 2.0\n\n[parameters]\n'
                                                   '__import__ = 1.0')]),
    ("mooring[0].name", [('damping = 2.0', 'damping = 2.0\n' + MOORING.replace('"m1"', '"m&1"'))]),
    ("friction[0].name", [('damping = 2.0', 'damping = 2.0\n' + FRICTION.replace('"f1"', '"f<1>"'))]),
    ("end_stop[0].name", [('damping = 2.0', 'damping = 2.0\n' + END_STOP.replace('"s1"', "'s$(x)'"))]),
])
def test_every_named_entity_is_checked(tmp_path, field, edits):
    _refused(write(tmp_path, variant(*edits)), field)


def test_a_long_hostile_name_is_shown_cut(tmp_path):
    """10 kB of name: the message shows about 80 characters of it and says how long it was."""
    name = "p\\n#x" * 2000
    path = write(tmp_path, variant(('name = "pb"', f'name = "{name}"')))
    message = _refused(path, "pto[0].name")
    assert len(message) < len(str(path)) + 1000 and "(8000 characters)" in message


def test_a_file_stem_becomes_a_name_when_the_scene_gives_none(tmp_path):
    """Without `name`, the scene takes its file's stem made a name: a file name is the user's
    to choose (my-buoy.toml), a scene name reaches C and signal names."""
    text = VALID.replace('name = "two_link"\n', "", 1)
    for stem, name in (("two-link", "two_link"), ("two_link", "two_link"),
                       ("2 links\n#x", "scene_2_links_x"), ("__", "scene"),
                       ("bou\u00e9e v2", "boue_v2")):
        path = write(tmp_path, text, f"{stem}.toml")
        assert load_scene(path).name == name


def test_names_at_the_limits_and_the_defaults_load(tmp_path):
    """64 characters, digits and single underscores; defaulted friction names, repeated
    bodies and parameters: all within the rule."""
    long = ("p" + "_1" * NAME_MAX)[:NAME_MAX - 1] + "2"
    assert len(long) == NAME_MAX
    text = variant(('name = "pb"', f'name = "{long}"'),
                   ('damping = 2.0', 'damping = 2.0\n' + FRICTION.replace('name = "f1"\n', "")
                    + '\n[parameters]\nL2 = 1.5\n'))
    scene = load_scene(write(tmp_path, text))
    assert scene.ptos[0].name == long and scene.frictions[0].name == "jb_friction"


def test_ground_stays_reserved_for_the_world(tmp_path):
    path = write(tmp_path, variant(('name = "b"', 'name = "ground"'), ('child = "b"', 'child = "ground"')))
    with fails(path, "body[1].name", r".*reserved for the world"):
        load_scene(path)


@pytest.mark.parametrize("model", list_models())
def test_every_catalogue_scene_obeys_the_rule(model):
    scene = load_scene(model)
    names = [scene.name, *scene.parameters] + [x.name for group in (
        scene.bodies, scene.joints, scene.ptos, scene.frictions, scene.moorings, scene.drags,
        scene.end_stops, scene.obstacles) for x in group]
    assert [n for n in names if name_problem(n)] == []


def test_unknown_references_are_shown_safely(tmp_path):
    """A reference (a PTO's joint) is not a name the scene gives, but its message shows it
    the same safe way."""
    path = write(tmp_path, variant(('joint = "jb"', r'joint = "j\u001b[2Jb"')))
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert "\x1b" not in str(caught.value) and r"\x1b[2Jb" in str(caught.value)
