"""The NMPC's settings: what its user chooses, frozen, with units and defaults
(controllers.nmpc).

`NmpcSettings` is one of the NMPC's three parts, as the linear MPC's (controllers.mpc_settings):
the settings (this module, frozen), the setup built from a plant and the settings
(`controllers.nmpc_setup.NmpcSetup`: the limits, scales and the compiled IPOPT problem,
fixed once built) and the run data (`NmpcRun`, one per run). `params` and `ipopt` are copied
into `FrozenDict`s: two NMPCs made from the same arguments share nothing either could change.
"""
from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, fields

from mbcontrol.errors import ControllerError

from .mpc_settings import FrozenDict


@dataclass(frozen=True)
class NmpcSettings:
    """Every setting of the NMPC, frozen (see controllers.nmpc.Nmpc for what they do).

    wave: the sea it forecasts (required); horizon_s, dt_s (s); substeps: RK4 steps per dt_s;
    force_max (N or N m), stroke_max (m or rad), rate_max (N/s or N m/s); force_penalty
    (W/N^2); stroke_penalty; pto; model (the prediction plant); params (its overrides);
    max_iter, tol, max_cpu_time (s), ipopt: IPOPT's settings."""
    wave: object
    _: KW_ONLY
    horizon_s: float = 10.0
    dt_s: float = 0.25
    substeps: int = 2
    force_max: float | None = None
    stroke_max: float | None = None
    rate_max: float | None = None
    force_penalty: float | None = None
    stroke_penalty: float = 10.0
    pto: str | None = None
    model: object = None
    params: dict | None = None
    max_iter: int = 200
    tol: float = 1e-6
    max_cpu_time: float | None = None
    ipopt: dict | None = None

    def __post_init__(self):
        if self.wave is None:
            raise ControllerError("Nmpc needs the wave it forecasts (wave=...)")
        horizon_s, dt_s, n = self.horizon_s, self.dt_s, self.n
        if n < 1 or abs(n * dt_s - horizon_s) > 1e-9 * horizon_s:
            raise ControllerError(f"horizon_s ({horizon_s}) must be a whole number >= 1 of "
                                  f"dt_s ({dt_s})")
        if self.substeps < 1 or self.stroke_penalty <= 0 or (self.force_penalty is not None
                                                             and self.force_penalty < 0):
            raise ControllerError("expected substeps >= 1, stroke_penalty > 0, force_penalty >= 0")
        if self.rate_max is not None and self.rate_max <= 0:
            raise ControllerError(f"rate_max must be > 0 (N/s) or None, got {self.rate_max}")
        object.__setattr__(self, "params", FrozenDict(self.params or {}))
        object.__setattr__(self, "ipopt", FrozenDict(self.ipopt or {}))

    @property
    def n(self) -> int:
        """Horizon steps: horizon_s / dt_s (0 for a dt_s <= 0)."""
        return round(self.horizon_s / self.dt_s) if self.dt_s > 0 else 0


SETTING_NAMES = tuple(f.name for f in fields(NmpcSettings) if f.name != "_")
