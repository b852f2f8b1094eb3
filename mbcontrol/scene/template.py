"""Scene parameters and repeated entries: one file for a family of devices.

    [parameters]
    N = 4                                   # barges in the chain
    L = 0.6

    [[body]]
    repeat = "i = 1..N"                     # one body per i = 1, 2, ..., N
    name = "barge{i}"
    cog = ["{(i - 1) * (L + 0.1) + L / 2}", 0.0, 0.0]

`repeat = "<var> = <first>..<last>"` (inclusive; bounds are expressions) copies an array-of-
tables entry once per value. In any string, `{expr}` is replaced by the value of an arithmetic
expression (+ - * / // % **, parentheses, numbers, parameter and loop names); a string that is
nothing but one `{expr}` becomes the number itself. Overrides (``load_scene(name, {"N": 8})``)
replace [parameters] values before anything is expanded.
"""
from __future__ import annotations

import ast
import math
import operator
import re
import time

from ..errors import SceneError
from .names import check_loop_variable

_BRACES = re.compile(r"\{([^{}]+)\}")
_REPEAT = re.compile(r"^\s*([A-Za-z_]\w*)\s*=\s*(.+?)\s*\.\.\s*(.+?)\s*$")
_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
        ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
        ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}
MAX_REPEAT = 1000
# An expression is scene arithmetic ("{(i - 1) * (L + 0.1)}"), not a program: these bounds hold
# every one to microseconds (Python's integer power alone would run for ever on "{9**9**9**9}",
# and a long chain of brackets exhausts the parser's memory).
MAX_EXPRESSION_CHARS = 200
MAX_OPERATIONS = 64          # nodes of the parsed expression: numbers, names and operators
MAX_MAGNITUDE = 1e18         # |value| of every intermediate result; far past any SI quantity
MAX_SECONDS = 0.1            # a guard beside the bounds above, never reached by them
LIMITS = (f"at most {MAX_EXPRESSION_CHARS} characters and {MAX_OPERATIONS} numbers, names and "
          f"operators, every intermediate value infinite or within +-{MAX_MAGNITUDE:g}")


def expand(data: dict, file: str, overrides: dict | None = None) -> tuple[dict, dict]:
    """(data with [parameters] removed, repeats expanded and {expr} substituted; the values used)."""
    data = dict(data)
    params = data.pop("parameters", {})
    if not isinstance(params, dict):
        raise SceneError(f"{file}: parameters: expected a table of numbers")
    derived = {}           # "{expr}" of the parameters declared before it: h2 from r2
    for key, value in params.items():
        if isinstance(value, str) and value.strip().startswith("{") and value.strip().endswith("}"):
            derived[key] = value.strip()[1:-1]
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(f"{file}: parameters.{key}: expected a number or an \"{{expr}}\" of "
                             f"the parameters before it, got {value!r}")
    unknown = sorted(set(overrides or {}) - set(params))
    if unknown:
        raise SceneError(f"{file}: parameters: {unknown} not declared; the scene's parameters are "
                         f"{sorted(params) or 'none'}")
    values = {k: v for k, v in params.items() if k not in derived}
    values.update({k: v for k, v in (overrides or {}).items() if k not in derived})
    for key, text in derived.items():             # in declaration order; an override wins
        values[key] = (overrides or {}).get(key, evaluate(text, values, file,
                                                          f"parameters.{key}"))
    values = {k: values[k] for k in params}
    out = {}
    for key, value in data.items():
        if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            out[key] = [e for k, entry in enumerate(value)
                        for e in _repeat(entry, values, file, f"{key}[{k}]")]
        else:
            out[key] = _substitute(value, values, file, key)
    return out, dict(values) if params else {}


def _repeat(entry: dict, values: dict, file: str, where: str) -> list[dict]:
    if "repeat" not in entry:
        return [_substitute(entry, values, file, where)]
    spec = entry["repeat"]
    match = _REPEAT.match(spec) if isinstance(spec, str) else None
    if not match:
        raise SceneError(f"{file}: {where}.repeat: expected '<name> = <first>..<last>', got {spec!r}")
    var, first, last = match.groups()
    check_loop_variable(var, file, f"{where}.repeat")
    lo, hi = (evaluate(x, values, file, f"{where}.repeat") for x in (first, last))
    if lo != int(lo) or hi != int(hi) or hi - lo + 1 > MAX_REPEAT:
        raise SceneError(f"{file}: {where}.repeat: expected whole-number bounds at most {MAX_REPEAT} "
                         f"apart, got {lo}..{hi}")
    body = {k: v for k, v in entry.items() if k != "repeat"}
    return [_substitute(body, {**values, var: i}, file, f"{where}({var}={i})")
            for i in range(int(lo), int(hi) + 1)]


def _substitute(value, values: dict, file: str, where: str):
    if isinstance(value, dict):
        return {k: _substitute(v, values, file, f"{where}.{k}") for k, v in value.items()}
    if isinstance(value, list):
        return [_substitute(v, values, file, f"{where}[{k}]") for k, v in enumerate(value)]
    if not isinstance(value, str) or "{" not in value:
        return value
    whole = _BRACES.fullmatch(value.strip())
    if whole:
        return evaluate(whole.group(1), values, file, where)
    return _BRACES.sub(lambda m: _format(evaluate(m.group(1), values, file, where)), value)


def _format(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else repr(float(x))


def evaluate(text: str, values: dict, file: str, where: str) -> float:
    """Value of an arithmetic expression over `values` (numbers only; no calls, no attributes),
    within LIMITS: a SceneError naming the field and the limit otherwise."""
    def refuse(what: str, limit: bool = False):
        expected = LIMITS if limit else f"arithmetic on numbers and the parameters {sorted(values)}"
        raise SceneError(f"{file}: {where}: cannot evaluate {{{_shown(text)}}}: {what}; "
                         f"expected {expected}") from None
    if len(text) > MAX_EXPRESSION_CHARS:
        refuse(f"{len(text)} characters", limit=True)
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError, MemoryError, RecursionError) as exc:
        refuse(f"not an expression ({type(exc).__name__})")
    n_nodes = sum(1 for node in ast.walk(tree.body)
                  if not isinstance(node, (ast.operator, ast.unaryop, ast.expr_context)))
    if n_nodes > MAX_OPERATIONS:
        refuse(f"{n_nodes} numbers, names and operators", limit=True)
    try:
        return _eval(tree.body, values, time.monotonic() + MAX_SECONDS)
    except KeyError as exc:
        refuse(f"unknown name {exc}")
    except _Limit as exc:
        refuse(str(exc), limit=True)
    except (ValueError, ZeroDivisionError, OverflowError, TypeError) as exc:
        refuse(str(exc) or type(exc).__name__)


def _shown(text: str, limit: int = 60) -> str:
    """The expression as a message may show it: printable ASCII, cut at `limit` characters."""
    safe = "".join(ch if " " <= ch <= "~" else "?" for ch in text[:limit])
    return safe + ("..." if len(text) > limit else "")


class _Limit(ValueError):
    """An expression passed one of LIMITS."""


def _eval(node, values, deadline: float):
    if time.monotonic() > deadline:
        raise _Limit(f"took longer than {MAX_SECONDS} s")
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        return _bounded(node.value)
    if isinstance(node, ast.Name):
        return _bounded(values[node.id])
    if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
        left, right = _eval(node.left, values, deadline), _eval(node.right, values, deadline)
        if isinstance(node.op, ast.Pow):
            _check_power(left, right)
        return _bounded(_OPS[type(node.op)](left, right))
    if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
        return _bounded(_OPS[type(node.op)](_eval(node.operand, values, deadline)))
    raise ValueError(f"'{_shown(ast.unparse(node))}' is not allowed")


def _bounded(value):
    """`value` if real and within +-MAX_MAGNITUDE, or infinite (a scene's "none": depth = inf,
    cutoff = inf); a float's arithmetic costs the same whatever its size, an integer's not."""
    if isinstance(value, complex):
        raise ValueError("the result is not a real number")
    if math.isnan(value):
        raise ValueError("the result is not a number (nan)")
    if not math.isinf(value) and abs(value) > MAX_MAGNITUDE:
        raise _Limit(f"a value ({_shown(repr(value), 30)}) beyond +-{MAX_MAGNITUDE:g}")
    return value


def _check_power(base, exponent) -> None:
    """Refuse a power whose result would pass MAX_MAGNITUDE before computing it (an integer
    power is exact, so its cost grows with the result's digits)."""
    if base == 0 or abs(base) == 1 or isinstance(base, float) and math.isinf(base):
        return
    if exponent * math.log10(abs(base)) > math.log10(MAX_MAGNITUDE):
        raise _Limit(f"the power {_shown(repr(base), 20)}**{_shown(repr(exponent), 20)} "
                         f"is beyond +-{MAX_MAGNITUDE:g}")
