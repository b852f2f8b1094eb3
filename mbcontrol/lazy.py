"""Package faces that load what they export on first use (PEP 562): `mbcontrol`,
`mbcontrol.sim` and `mbcontrol.controllers` name their exports here rather than importing every module, so that
a quick answer of the command line (`--help`, `models`) imports no simulator, CasADi, xarray
or python-control (tests/features/cli/test_startup.py)."""
from __future__ import annotations

from importlib import import_module


def face(package: str, namespace: dict, where: dict, listed=None):
    """(__getattr__, __dir__) for `package` (its globals `namespace`): `where` maps each name
    to (its module in the package, its name there, or None for the module itself); a name is
    imported when first asked for, then kept in the namespace. listed: the names `dir()` shows
    (a curated face: `mbcontrol`'s); None: the namespace's and `where`'s."""
    def __getattr__(name):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attr = where[name]
        value = import_module(f"{package}.{module}")
        value = value if attr is None else getattr(value, attr)
        namespace[name] = value
        return value

    def __dir__():
        return sorted(listed) if listed is not None else sorted(set(namespace) | set(where))
    return __getattr__, __dir__
