"""The law protocol: what a registered controller class says about itself, so that design,
sweeps, the checks and the command line ask the class instead of comparing its name.

A law is a class that implements the Controller protocol (mbcontrol.sim.protocol: `name`,
`period`, `reset(plant)`, `__call__(t, y)`, `casadi_law(plant)`, `describe()`) and states,
as class members (`Law` holds the defaults; `controllers.register` checks them):

- `name`: its registry name (make(name, **settings) builds it).
- `kind`, one of KINDS:
  - "linear": a static spring-damper on each PTO's own motion, u = -(damping v + stiffness x),
    clipped to +-force_max. After reset(plant) its gains are `damping_per_pto` (and
    `stiffness_per_pto`, N/m, when it has a spring), N s/m per PTO in scene order. It has a
    loop transfer (controllers.margins) and a linear-theory prediction of its power. Several
    PTOs are tuned jointly (controllers.joint).
  - "switching": it keeps a timer, so it has no loop transfer and no linear theory. It is
    tuned by simulating the plant.
  - "predictive": it optimises over a horizon (horizon_s, dt_s, s). It is not tuned: its
    defaults apply, with a horizon and a slew limit fitted to the wave.
- `tuned`: the settings tune() sets, the contract of make(name, **settings).
- `preview`: its constructor takes the wave (a forecast, or an estimator's wave model). The
  callers pass wave=... beside the settings, and register checks it against the signature.
- `exportable`: `mbcontrol export` can write it as code (mbcontrol.export).
- `floors`: tune(robust=True) holds the robustness floors (controllers.robustness). The other
  laws meet them by construction (a damper on a passive device) or have no loop to check.
- `own_free_limits`: with limits on, a limit the scene leaves free (inf) is not passed, so the
  law's own default applies (the linear MPC: a soft stroke limit within its linear range).
- `run_state`: one line on what an instance keeps between calls after reset(plant).
- `units`: setting -> unit, carried into Settings' field metadata ("unit").
- `Settings`: a frozen dataclass of its settings. Its fields are the constructor's
  parameters, with the same defaults (a field without one must be given) and `units` as
  metadata. It is derived from __init__, so that the constructor stays the one place that
  states a law's settings.
- `tune(plant, wave, pto, *, limits, params, notes, robust, envelope) -> Tuning`: its settings
  for a wave (see Law.tune).
- `law(plant, settings)`: the CasADi Function y -> u that the plant closes its loop with, or
  None for a law with state (it then runs in simulate's Python loop).

Adding a law takes one file with its class (a subclass of Law) and `register(name, cls)`.
"""
from __future__ import annotations

import dataclasses
import inspect
from typing import Any

from mbcontrol.errors import UnknownName

from .law_tuning import Tuning, untuned  # noqa: F401   (Tuning: the protocol's result)

KINDS = ("linear", "switching", "predictive")


class _SettingsOf:
    """The frozen Settings dataclass of the owning class, built from its __init__ on first
    use and cached per class."""

    def __get__(self, obj, owner):
        made = owner.__dict__.get("_settings_class")
        if made is None:
            made = settings_class(owner)
            setattr(owner, "_settings_class", made)
        return made


def settings_class(cls) -> type:
    """A frozen, keyword-only dataclass `<Name>Settings` whose fields are the constructor's
    parameters, with their defaults and the unit from cls.units in each field's metadata."""
    units = getattr(cls, "units", {}) or {}
    fields = []
    for p in inspect.signature(cls).parameters.values():   # its __signature__, if set
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            continue
        meta = {"unit": units.get(p.name)}
        spec = (dataclasses.field(metadata=meta) if p.default is p.empty
                else dataclasses.field(default=p.default, metadata=meta))
        fields.append((p.name, Any, spec))
    return dataclasses.make_dataclass(f"{cls.__name__}Settings", fields, frozen=True,
                                      kw_only=True)


def settings_dict(settings) -> dict:
    """A Settings instance (or a mapping) as keyword arguments (shallow: the wave is kept)."""
    if dataclasses.is_dataclass(settings):
        return {f.name: getattr(settings, f.name) for f in dataclasses.fields(settings)}
    return dict(settings or {})


def pto_of(plant, pto):
    """The scene PTO a tuner works on: a PTO object, a PTO name, or None for the first."""
    ptos = plant.scene.ptos
    if pto is None:
        return ptos[0]
    if not isinstance(pto, str):
        return pto
    for p in ptos:
        if p.name == pto:
            return p
    raise UnknownName(f"{plant.name}: no PTO {pto!r}; PTOs are {', '.join(p.name for p in ptos)}")


class Law:
    """The defaults of the law protocol (see the module docstring). A subclass states at
    least `name`, `kind` and `tuned`, and implements the Controller protocol."""
    name: str = ""
    kind: str = ""
    tuned: tuple[str, ...] = ()
    preview: bool = False
    exportable: bool = False
    floors: bool = False
    own_free_limits: bool = False
    run_state: str = ""
    units: dict = {}
    Settings = _SettingsOf()

    @classmethod
    def tune(cls, plant, wave, pto=None, *, limits: bool = True, params=None,
             notes: list | None = None, robust: bool = True, envelope: bool = True) -> Tuning:
        """The law's settings for `wave` on `pto` (a scene PTO, its name, or None for the
        first). limits: hold the PTO's force and stroke limits (False: none, the law's own
        limits set to inf). params: plant parameter overrides for a tuner that uses a model.
        notes: a list that the tuner appends what the reader should know to. robust: a law
        with floors stays within them. envelope: with limits, also keep the linear model's
        envelope (analysis.envelope).

        This default does not tune: it uses the law's defaults and the PTO's limits, and a
        predictive law gets a horizon and a slew limit fitted to the wave.
        """
        return untuned(cls, plant, wave, pto_of(plant, pto), limits=limits, params=params,
                       notes=[] if notes is None else notes)

    @classmethod
    def law(cls, plant, settings):
        """The CasADi Function y -> u (one force per PTO, N or N m) that `plant` closes its
        loop with under `settings` (a Settings or a dict of them). None for a law with state,
        which runs in simulate's Python loop."""
        controller = cls(**settings_dict(settings))
        controller.reset(plant)
        return controller.casadi_law(plant)


class PredictiveLaw(Law):
    """A law that optimises the PTO force over a receding horizon (Mpc, Nmpc): not tuned
    (Law.tune: its defaults, with a horizon of one wave period in 40 steps and, with a force
    limit, a slew limit fitted to the wave); it takes the wave as its preview."""
    kind, preview = "predictive", True
    tuned = ("horizon_s", "dt_s", "force_max", "stroke_max", "rate_max")
    run_state = ("the estimator's or the solver's state, the command held, the solver's warm "
                 "start and the run's log (solve times, per-step records)")
    units = {"horizon_s": "s", "dt_s": "s", "force_max": "N (or N m)",
             "stroke_max": "m (or rad)", "rate_max": "N/s (or N m/s)", "warm_up_s": "s"}


REQUIRED = ("name", "kind", "tuned", "tune", "law", "reset", "casadi_law", "describe")


def check_law(name: str, cls) -> None:
    """Raise UnknownName, naming what is missing, unless `cls` states the law protocol."""
    called = any("__call__" in vars(k) for k in getattr(cls, "__mro__", ())[:-1])  # not type's
    missing = [m for m in REQUIRED if not hasattr(cls, m)] + ([] if called else ["__call__"])
    if missing:
        raise UnknownName(f"register({name!r}): {cls!r} lacks {', '.join(missing)} of the law "
                          f"protocol (controllers.law; subclass controllers.Law)")
    if cls.name != name:
        raise UnknownName(f"register({name!r}): the class's name is {cls.name!r}; expected "
                          f"{name!r}, the name make() and the records use")
    if cls.kind not in KINDS:
        raise UnknownName(f"register({name!r}): kind {cls.kind!r}; expected one of "
                          f"{', '.join(KINDS)}")
    accepted = inspect.signature(cls).parameters
    unknown = [k for k in cls.tuned if k not in accepted]
    if unknown:
        raise UnknownName(f"register({name!r}): tuned settings {unknown} are not keywords of "
                          f"its constructor ({', '.join(accepted)})")
    if bool(cls.preview) != ("wave" in accepted):
        raise UnknownName(f"register({name!r}): preview is {cls.preview!r} but its constructor "
                          f"{'takes' if 'wave' in accepted else 'does not take'} wave=")
