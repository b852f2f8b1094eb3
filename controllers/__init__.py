"""PTO controllers. Each implements the Controller protocol of `controllers.base`.

`make(name, **settings)` builds one by name (as the CLI's --controller NAME --set k=v does).
REGISTRY maps each name to its class, and the class states what callers need to know about
the law (its kind, tuned settings, preview, exportability, tune(), law(): the law protocol of
`controllers.law`). Callers ask the class, never the name: this module and the command line's
choices are the only places that name laws. `register(name, cls)` adds a law.
Each law's tuner lives beside it (`optimal_damping` with passive, `reactive_tuning` with
reactive, `optimal_latch_time` and `optimal_declutch` with latching, `joint_tuning` for
several PTOs at once); the loop checks (`loop_margins`, `loop_robustness`) and the PTO limits
they respect are here too. Tuning by name, bounding, simulating and scoring is a study:
`mbcontrol.studies.design`.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

from mbcontrol.errors import UnknownName
from mbcontrol.lazy import face

if TYPE_CHECKING:
    from .base import Controller

# name -> (module, its name there): loaded on first use, so that the command line can list
# the laws (REGISTRY's names) without importing python-control, CasADi and the hydrodynamics
_WHERE = {
    "Controller": ("base", "Controller"), "Law": ("law", "Law"),
    "PredictiveLaw": ("law", "PredictiveLaw"), "Tuning": ("law", "Tuning"),
    "electrical_optimum": ("impedance", "electrical_optimum"),
    "joint_tuning": ("joint", "joint_tuning"), "other_laws": ("joint", "other_laws"),
    "Declutching": ("latching", "Declutching"), "Latching": ("latching", "Latching"),
    "mean_power": ("latching", "mean_power"), "optimal_declutch": ("latching", "optimal_declutch"),
    "optimal_latch_time": ("latching", "optimal_latch_time"),
    "command_limit": ("limits", "command_limit"), "linear_range": ("limits", "linear_range"),
    "loop_margins": ("margins", "loop_margins"), "loop_bode": ("loop_plots", "loop_bode"),
    "loop_nyquist": ("loop_plots", "loop_nyquist"), "loop_marks": ("loop_plots", "loop_marks"),
    "pto_gains": ("margins", "pto_gains"),
    "Mpc": ("mpc", "Mpc"), "Nmpc": ("nmpc", "Nmpc"),
    "Passive": ("passive", "Passive"), "optimal_damping": ("passive", "optimal_damping"),
    "Reactive": ("reactive", "Reactive"), "reactive_tuning": ("reactive", "reactive_tuning"),
    "loop_robustness": ("robustness", "robustness"),
    "share_explained": ("robustness", "share_explained"),
    "OutsideEnvelope": ("tuning", "OutsideEnvelope"),
    "LimitsUnreachable": ("tuning", "LimitsUnreachable"),
}


__getattr__, __dir__ = face(__name__, globals(), _WHERE)


class _Registry(Mapping):
    """Law name -> its class. A built-in class is imported when first asked for, so that
    listing the names imports nothing; a registered class is held as given."""

    def __init__(self, classes: dict):
        self._classes = classes        # name -> the class's name in this face, or the class

    def __getitem__(self, name):
        if name not in self._classes:
            raise KeyError(name)
        found = self._classes[name]
        return __getattr__(found) if isinstance(found, str) else found

    def __iter__(self):
        return iter(self._classes)

    def __len__(self):
        return len(self._classes)


REGISTRY = _Registry({"passive": "Passive", "reactive": "Reactive", "latching": "Latching",
                      "declutching": "Declutching", "mpc": "Mpc", "nmpc": "Nmpc"})
BUILT_IN = tuple(REGISTRY)
# the law design falls back to in a sea its tuned law cannot serve: a damper, tuned within
# the PTO's limits or saturated at its force limit (studies.design.fallback)
DAMPER = "passive"


def register(name: str, cls) -> None:
    """Add the law `cls` under `name`, so that make(name, ...), design, sweeps and the command
    line's listings know it. cls states the law protocol (controllers.law; subclass
    controllers.Law) and its `name` is `name`. UnknownName if it does not, or if `name` is
    taken."""
    from .law import check_law
    if name in REGISTRY:
        raise UnknownName(f"register({name!r}): the name is taken by {REGISTRY[name]!r}; "
                          f"unregister it first")
    check_law(name, cls)
    REGISTRY._classes[name] = cls


def linear_law_named(gains: dict) -> str:
    """The registered linear law whose tuned settings are the gains given (a dict with damping
    and perhaps stiffness): "passive" for a damper, "reactive" with a spring; "linear" when
    none is registered."""
    given = {"damping", "stiffness"} if "stiffness" in gains else {"damping"}
    for name in REGISTRY:
        cls = REGISTRY[name]
        if cls.kind == "linear" and set(cls.tuned) == given:
            return name
    return "linear"


def unregister(name: str) -> None:
    """Remove a law added by register() (the built-in laws stay)."""
    if name in BUILT_IN:
        raise UnknownName(f"unregister({name!r}): a built-in law stays registered")
    if name not in REGISTRY:
        raise UnknownName(f"unregister({name!r}): no such law; registered: {', '.join(REGISTRY)}")
    del REGISTRY._classes[name]


def make(name: str, **settings) -> Controller:
    """A controller by registry name with keyword settings, e.g. make('passive', damping=2)."""
    if name not in REGISTRY:
        raise UnknownName(f"unknown controller {name!r}; expected one of {', '.join(REGISTRY)}")
    import inspect
    accepted = inspect.signature(REGISTRY[name]).parameters
    unknown = [k for k in settings if k not in accepted]
    if unknown:
        raise UnknownName(f"controller {name!r} has no setting {', '.join(map(repr, unknown))}; "
                          f"its settings are {', '.join(accepted)}")
    try:
        return REGISTRY[name](**settings)
    except TypeError as exc:
        raise UnknownName(f"controller {name!r}: {exc}; its settings are "
                          f"{', '.join(accepted)}") from None


# Laws whose power comes from their damping alone: with none (their default, so that a law is
# never tuned by accident) they absorb nothing. A bare `--controller reactive` used to report
# 0.0 W in all 32 PacWave seas, all "valid", with no word said.
DAMPED_LAWS = ("passive", "reactive", "latching", "declutching")


def absorbs_nothing(name: str | None, settings: dict | None, varied=()) -> str | None:
    """Why controller `name` with `settings` absorbs no power, or None. The CLI's simulate
    and sweep warn with it (the documented choice: a named controller runs as given, its
    defaults included, and says so; `design` tunes it for a sea)."""
    if name not in DAMPED_LAWS or "damping" in varied:
        return None
    damping = (settings or {}).get("damping", 0.0)
    values = damping.values() if isinstance(damping, dict) else [damping]
    if any(float(v) != 0.0 for v in values):
        return None
    return (f"controller '{name}' with damping 0 absorbs no power (its defaults: no damping"
            f"{', no stiffness' if name == 'reactive' else ''}): give it settings (--set "
            f"damping=... ), or tune it for a sea with `mbcontrol design MODEL --controller "
            f"{name}`")
