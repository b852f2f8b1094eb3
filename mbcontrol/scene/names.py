"""The name rule at scene load: every name a scene gives obeys `textsafe.NAME_RULE`.

Names become C identifiers and comments, FMI variable names, CasADi Function names, signal
names (`<body>__Heave`) and report cells; one rule, checked once here, keeps them all plain.
The writers escape anyway (`mbcontrol.textsafe`), so the rule is the first wall, not the only.
"""
from __future__ import annotations

import re

from ..errors import SceneError
from ..textsafe import NAME_MAX, NAME_RULE, name_problem, shown


def name_refusal(value, reserved: tuple[str, ...] = ()) -> str | None:
    """None if `value` is a name (and not one of `reserved`), else the message's "expected
    ..., got ..." part: the rule, and the value shown safely (ascii, cut at 80 characters)."""
    why = name_problem(value) or ("reserved for the world" if value in reserved else None)
    if why is None:
        return None
    also = f" (and not {', '.join(repr(r) for r in reserved)})" if reserved else ""
    return (f"expected a name without dots, spaces or '__'{also}, got {shown(value)} ({why}); "
            f"{NAME_RULE}")


def check_names(scene, top) -> None:
    """The names `Reader.name` does not see: the scene's own (when it gives none, its file's
    stem made a name by `name_from_stem`), frictions', end stops' and drags' when given (their
    defaults join checked names: "<joint>_friction"), and the keys of [parameters]. Bodies,
    joints, PTOs, moorings and obstacles are checked as they are read. `top` is the scene
    file's top-level `checks.Reader`. Raises SceneError naming the file and the field."""
    named = [("name", scene.name)]
    for kind, items in (("friction", scene.frictions), ("end_stop", scene.end_stops),
                        ("drag", scene.drags)):
        tables = top.data.get(kind) or []
        named += [(f"{kind}[{i}].name", item.name) for i, item in enumerate(items)
                  if i < len(tables) and isinstance(tables[i], dict) and "name" in tables[i]]
    keys = list(scene.parameters)
    named += [(f"parameters (key {k + 1} of {len(keys)})", key) for k, key in enumerate(keys)]
    for field, value in named:
        if refusal := name_refusal(value):
            raise SceneError(f"{top.file}: {field}: {refusal}")


def name_from_stem(stem: str) -> str:
    """A scene file's stem as a name that obeys the rule, for a scene that gives none: every
    run of other characters becomes one '_' ("my-buoy v2" -> "my_buoy_v2"), a leading digit
    gets "scene_" before it, and the result is cut to the longest length allowed."""
    words = re.findall(r"[A-Za-z0-9]+", stem.encode("ascii", "ignore").decode())
    name = "_".join(words) or "scene"
    if not name[0].isalpha():
        name = f"scene_{name}"
    return name[:NAME_MAX].rstrip("_")


def check_loop_variable(variable, file: str, where: str) -> None:
    """A `repeat = "<variable> = <first>..<last>"` loop variable obeys the rule too (it names
    a value in the scene's expressions); `where` is e.g. "body[0].repeat"."""
    if refusal := name_refusal(variable):
        raise SceneError(f"{file}: {where}: loop variable: {refusal}")
