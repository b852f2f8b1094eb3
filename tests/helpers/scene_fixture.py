"""A small valid scene (`VALID`: two bodies on revolute joints) and helpers to write one-line
variants of it and to expect a SceneError naming file, field and expectation; shared by the
scene tests (tests/scene/)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from mbcontrol.errors import SceneError

VALID = """\
name = "two_link"
description = "test fixture: two bodies on revolute joints"

[[body]]
name = "a"
mass = 10.0
inertia = [1.0, 2.0, 3.0]
cog = [0.5, 0.0, 0.0]
hydro = false

[[body]]
name = "b"
mass = 20.0
inertia = [4.0, 5.0, 6.0]
cog = [1.5, 0.0, 0.0]
hydro = false

[[joint]]
name = "ja"
type = "revolute"
parent = "ground"
child = "a"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]

[[joint]]
name = "jb"
type = "revolute"
parent = "a"
child = "b"
point = [1.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]

[[pto]]
name = "pb"
joint = "jb"
damping = 2.0
"""


# a dry box on a free joint: no buoyancy, no restoring; it falls (tests/plant)
TUMBLER = """
name = "tumbler"
[[body]]
name = "box"
mass = 1.0
inertia = [0.1, 0.2, 0.3]
cog = [0.0, 0.0, 0.0]
hydro = false
[[joint]]
name = "float"
type = "free"
parent = "ground"
child = "box"
"""


def variant(*edits: tuple[str, str], base: str = VALID) -> str:
    """VALID with each (old, new) applied; old must occur exactly once, so edits stay precise."""
    text = base
    for old, new in edits:
        assert text.count(old) == 1, f"fixture edit {old!r} is not unique"
        text = text.replace(old, new)
    return text


def write(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def hydro_table(body: str) -> tuple[str, str]:
    """An edit appending a [hydro] table with `body` to VALID."""
    return ("damping = 2.0", "damping = 2.0\n\n[hydro]\n" + body)


def jb_type(kind: str) -> tuple[str, str]:
    """An edit changing the type of joint jb (joint[1])."""
    return ('name = "jb"\ntype = "revolute"', f'name = "jb"\ntype = "{kind}"')


B_HYDRO = "cog = [1.5, 0.0, 0.0]\nhydro = false"       # body b's last lines, unique in VALID


def fails(path: Path, field: str, expected: str):
    """pytest.raises for a SceneError reading '<file>: <field>: <expected...>'.

    `field` is matched literally; `expected` is a regular expression.
    """
    return pytest.raises(SceneError, match=re.escape(f"{path}: {field}: ") + expected)
