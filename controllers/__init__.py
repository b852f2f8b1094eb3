"""PTO controllers. Each implements the Controller protocol of `controllers.base`.

`make(name, **settings)` builds one by name (as the CLI's --controller NAME --set k=v does).
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
    "Controller": ("base", "Controller"), "electrical_optimum": ("impedance", "electrical_optimum"),
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
    """Law name -> its class, each class imported when first asked for (its names are free)."""

    def __init__(self, classes: dict):
        self._classes = classes

    def __getitem__(self, name):
        if name not in self._classes:
            raise KeyError(name)
        return __getattr__(self._classes[name])

    def __iter__(self):
        return iter(self._classes)

    def __len__(self):
        return len(self._classes)


REGISTRY = _Registry({"passive": "Passive", "reactive": "Reactive", "latching": "Latching",
                      "declutching": "Declutching", "mpc": "Mpc", "nmpc": "Nmpc"})


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
