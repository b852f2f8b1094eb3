"""PTO controllers. Each implements the Controller protocol of `controllers.base`.

`make(name, **settings)` builds one by name (as the CLI's --controller NAME --set k=v does).
"""
from __future__ import annotations

from .base import Controller
from .latching import Declutching, Latching
from .mpc import Mpc
from .nmpc import Nmpc
from .passive import Passive
from .reactive import Reactive

REGISTRY = {"passive": Passive, "reactive": Reactive, "latching": Latching,
            "declutching": Declutching, "mpc": Mpc, "nmpc": Nmpc}


def make(name: str, **settings) -> Controller:
    """A controller by registry name with keyword settings, e.g. make('passive', damping=2)."""
    if name not in REGISTRY:
        raise KeyError(f"unknown controller {name!r}; expected one of {', '.join(REGISTRY)}")
    import inspect
    accepted = inspect.signature(REGISTRY[name]).parameters
    unknown = [k for k in settings if k not in accepted]
    if unknown:
        raise KeyError(f"controller {name!r} has no setting {', '.join(map(repr, unknown))}; "
                       f"its settings are {', '.join(accepted)}")
    try:
        return REGISTRY[name](**settings)
    except TypeError as exc:
        raise KeyError(f"controller {name!r}: {exc}; its settings are "
                       f"{', '.join(accepted)}") from None
