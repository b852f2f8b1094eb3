"""How the CLI says that a result is INVALID (what failed on one line, what to do on the
next), and that a command could not run (one line and its exit status)."""
from __future__ import annotations

import errno
import os
import re
import warnings

from ..atomic import ENVIRONMENT_ERRNOS, environment_problem
from ..cache import EntrySetAside
from ..errors import EnvironmentProblem, MbcontrolError

BAD_INPUT = 1        # the exit statuses of the command's docstring (mbcontrol --help)
ENVIRONMENT = 5

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


def refusal(exc: BaseException) -> tuple[int | None, str]:
    """(exit status, one line) for an error a user can act on: bad input (mbcontrol's own
    errors: 1) or the machine's refusal (EnvironmentProblem, or an OSError of a full disk,
    missing permission or a read-only file system that no writer named, a cache entry
    set aside: 5); (None, "") for
    anything else, a bug, which keeps its traceback."""
    if isinstance(exc, (EnvironmentProblem, EntrySetAside)):
        return ENVIRONMENT, str(exc)
    if isinstance(exc, MbcontrolError):   # an error may say it is a result (a sea no law serves)
        return getattr(exc, "exit_status", BAD_INPUT), str(exc)
    if not isinstance(exc, OSError) or exc.errno not in ENVIRONMENT_ERRNOS:
        return None, ""
    if exc.filename:
        return ENVIRONMENT, str(environment_problem(exc, exc.filename, "using"))
    return ENVIRONMENT, (f"{exc.strerror or exc} ({errno.errorcode.get(exc.errno, exc.errno)}); "
                         f"free some space, or fix the permissions of the folders the command "
                         f"writes, or write elsewhere (for the cache: "
                         f"MBCONTROL_CACHE=/another/folder)")


def format_warning(message, category, filename, lineno, line=None) -> str:
    """The toolbox's own warnings as sentences for the user, without the source line that
    issued them; anything else (numpy, a dependency) in Python's usual form."""
    if os.sep + "mbcontrol" + os.sep in filename or os.sep + "controllers" + os.sep in filename:
        return f"mbcontrol: warning: {message}\n"
    return _PYTHON_FORMAT(message, category, filename, lineno, line)


_PYTHON_FORMAT = warnings.formatwarning


def said_once(show):
    """`show` (warnings.showwarning) that says each warning once per command: the same text
    from two places (a plant assembled twice, a fit read back from the cache) is one warning."""
    said = set()

    def show_once(message, category, filename, lineno, file=None, line=None):
        key = (category, str(message))
        if key not in said:
            said.add(key)
            show(message, category, filename, lineno, file, line)
    return show_once
