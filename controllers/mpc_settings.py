"""The MPC's settings: what its user chooses, frozen, with units and defaults (controllers.mpc).

`MpcSettings` is one of the MPC's three parts (do-mpc's settings / setup / data split, and
Pinocchio's Model apart from its Data): the settings (this module, frozen), the setup built
from a plant and the settings (`controllers.mpc_setup.MpcSetup`, fixed once built) and the
run data (`MpcRun`, one per run). A setting given as a dict by PTO name is copied into a
`FrozenDict`, a list into a tuple: two MPCs made from the same arguments share nothing that
either could change.
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, fields

from mbcontrol.errors import ControllerError

FORECASTS = ("known", "ar", "model", "none")
ESTIMATORS = ("kalman", "state")
SOLVERS = ("qpoases", "cvxpy")
OBJECTIVES = ("auto", "electrical", "mechanical")
ORACLE_LABEL = "non-causal upper bound (true future wave)"


class FrozenDict(dict):
    """A dict that refuses changes (a per-PTO setting: {PTO name: value}); a dict still, for
    the code that reads per-PTO settings (limits.per_pto_values)."""

    def _refuse(self, *args, **kwargs):
        raise TypeError("a frozen setting cannot be changed; make a new controller")

    __setitem__ = __delitem__ = clear = pop = popitem = setdefault = update = _refuse
    __ior__ = _refuse

    def __reduce__(self):                   # copy, deepcopy and pickle rebuild it whole
        return (FrozenDict, (dict(self),))

    def __hash__(self):
        return hash(tuple(sorted(self.items())))


def _frozen(value):
    """A private, unchangeable copy of a dict or list setting; other values as given."""
    if isinstance(value, dict):
        return FrozenDict(value)
    if isinstance(value, list):
        return tuple(value)
    return value


@dataclass(frozen=True)
class MpcSettings:
    """Every setting of the linear MPC, frozen (see controllers.mpc for what they do).

    horizon_s, dt_s: prediction horizon and control period, s (dt_s a multiple of the
    simulation step). force_max (N or N m), stroke_max (m or rad), rate_max (N/s or N m/s):
    limits, a number or a dict by PTO name; None: the scene PTO's (rate: unlimited; a stroke
    the scene leaves unlimited: a soft one in the linear model's range). wave: the sea (the
    Kalman wave model's frequencies and the warm-up damper; the forecast only with "known").
    forecast: "ar" (default, causal), "model", "none" or "known" (the oracle, labelled a
    bound). estimator: "kalman" or "state" (the plant's state: an oracle). solver: "qpoases"
    or "cvxpy". order: reduce the control plant to this many states, None: full.
    force_penalty: r relative to the energy Hessian's largest eigenvalue (dimensionless).
    stroke_penalty: slack weights (scaled units). soft_stroke: stroke limit soft (exact L1
    penalty) or hard. measured: plant output names the Kalman filter reads (None: every
    joint coordinate and rate). ar_order: AR model order. measurement_noise: sensor noise
    relative to each output's peak response (Kalman). efficiency: PTO efficiency (0, 1], a
    number or a dict by PTO name, None: the scene's. warm_up_s: passive damping until this
    time, s (None: WARM_UP_PERIODS peak periods with the AR forecast, 0 otherwise).
    objective: "auto", "electrical" or "mechanical". envelope: keep the linear model's range.
    blocks: move blocking, the force held over blocks of steps (controllers.mpc_blocks): None
    (one force per step), a count of blocks (a default layout, short blocks first) or the
    block lengths in steps, summing to horizon_s / dt_s.
    """
    horizon_s: float = 10.0
    dt_s: float = 0.2
    force_max: float | dict | None = None
    stroke_max: float | dict | None = None
    rate_max: float | dict | None = None
    _: KW_ONLY
    wave: object = None
    forecast: str | None = None
    estimator: str = "kalman"
    solver: str = "qpoases"
    order: int | None = None
    force_penalty: float = 1e-3
    stroke_penalty: float = 100.0
    soft_stroke: bool = True
    measured: tuple | None = None
    ar_order: int = 8
    measurement_noise: float = 1e-3
    efficiency: float | dict | None = None
    warm_up_s: float | None = None
    objective: str = "auto"
    envelope: bool = True
    blocks: int | tuple | None = None

    def __post_init__(self):
        forecast = self.forecast or "ar"    # causal by default; the oracle only when asked
        _choice("forecast", forecast, FORECASTS)
        _choice("estimator", self.estimator, ESTIMATORS)
        _choice("solver", self.solver, SOLVERS)
        _choice("objective", self.objective, OBJECTIVES)
        if forecast == "known" and self.wave is None:
            raise ControllerError("mpc: forecast 'known' needs the wave (wave=...)")
        if self.warm_up_s is not None and not self.warm_up_s >= 0:
            raise ControllerError(f"mpc: warm_up_s must be >= 0 s, got {self.warm_up_s}")
        if self.horizon_s < self.dt_s or self.dt_s <= 0:
            raise ControllerError(f"mpc: expected 0 < dt_s <= horizon_s, got dt_s={self.dt_s}, "
                                  f"horizon_s={self.horizon_s}")
        resolved = {"forecast": forecast, "horizon_s": float(self.horizon_s),
                    "dt_s": float(self.dt_s), "envelope": bool(self.envelope)}
        resolved.update({f.name: _frozen(getattr(self, f.name)) for f in fields(self)
                         if f.name not in resolved})
        for name, value in resolved.items():
            object.__setattr__(self, name, value)

    @property
    def uses_state(self) -> bool:
        """Reads the plant's whole state (estimator "state"): an oracle."""
        return self.estimator == "state"

    @property
    def oracle(self) -> bool:
        return self.forecast == "known" or self.uses_state

    def label(self) -> str:
        """How causal the run is, for JSON, Datasets and figure legends."""
        if self.forecast == "known":
            return ORACLE_LABEL
        causal = {"ar": "causal (AR forecast of the Kalman excitation estimate)",
                  "model": "causal (Kalman wave-model forecast)",
                  "none": "causal (no forecast)"}[self.forecast]
        return causal + ("; full-state oracle" if self.uses_state else "")


SETTING_NAMES = tuple(f.name for f in fields(MpcSettings))


def _choice(what, value, allowed):
    if value not in allowed:
        raise ControllerError(f"mpc: {what} must be one of {', '.join(allowed)}, got {value!r}")
