"""How the CLI says that a result is INVALID: what failed on one line, what to do on the next."""
from __future__ import annotations

import re

_REMEDY = re.compile(r"\. Remedy: ([^;]*)")


def invalid_lines(reasons, indent: str = "  ") -> list[str]:
    """Per reason: "INVALID: what failed" and, below it, "remedy: what to do"."""
    from ..analysis import split_remedy
    lines = []
    for reason in reasons:
        what, remedy = split_remedy(reason)
        lines.append(f"{indent}INVALID: {what}")
        if remedy:
            lines.append(f"{indent}  remedy: {remedy}")
    return lines


def without_remedies(joined: str) -> tuple[str, list[str]]:
    """A sweep case's reasons ("; "-joined) without their remedies, and the remedies."""
    return _REMEDY.sub("", joined), _REMEDY.findall(joined)
