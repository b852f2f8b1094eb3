"""Passive control: each PTO a linear damper, u = -damping * v (absorbed power c v^2 >= 0).

PTO limits. The command is saturated to +-force_max (N or N m; default: the scene PTO's
force_max, inf: no limit), in the Python path and in the compiled CasADi law alike
(`force_limits`, `saturate`, `casadi_saturate`, shared with reactive and latching). A
saturated damper still absorbs power but no longer bounds the stroke: the stroke limit is met
by tuning, `optimal_damping(..., force_max=, stroke_max=)`, which keeps the predicted force and
stroke peaks of the linear frequency-domain solution within the limits (the peak statistic is
documented in `controllers.impedance.fd_statistics`); the WECCCOMP tests verify it by simulation.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
from mbcontrol.errors import ControllerError

from .base import per_pto, signal_indices
from .impedance import base_params, default_bounds
from .law import Law
from .limits import casadi_saturate, force_limits, limits_report, linear_law_parametric, saturate
from .tuning import constrained_tuning, electrical_winding


class Passive(Law):
    """A linear damper on every PTO: u = sat(-damping * v), the PTO's whole force.

    damping: N s/m (or N m s/rad) per PTO, one number for all, or a dict by PTO name. In
    closed loop the controller owns the PTO force (the scene's PTO law is set aside).
    force_max: N (or N m), the saturation of the command, as `force_limits` reads it (None:
    the scene PTO's force_max; inf: none).
    """
    name = "passive"
    kind, tuned, exportable = "linear", ("damping",), True     # the law protocol (controllers.law)
    run_state = "none: the gains and limits bound by reset(plant); no memory between calls"
    units = {"damping": "N s/m (or N m s/rad)", "period": "s", "force_max": "N (or N m)"}

    @classmethod
    def tune(cls, plant, wave, pto=None, **options):
        """The damping of `optimal_damping` (below) for `wave`, within the PTO's limits, the
        linear model's envelope and its rated power (options: Law.tune's); several PTOs
        tuned jointly (controllers.joint)."""
        from .law import pto_of
        from .law_tuning import tune_linear
        return tune_linear(cls, optimal_damping, plant, wave, pto_of(plant, pto),
                           **options)

    def __init__(self, damping=0.0, period: float | None = None, force_max=None):
        self.damping = damping
        self.period = period          # s; None: every simulation step
        self.force_max = force_max
        self._gains = None
        self._limits = None
        self._law = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        self._gains = per_pto(plant, self.damping, "passive damping")
        if np.any(self._gains < 0):
            raise ControllerError(f"passive damping must be >= 0, got {self._gains}")
        self._limits = force_limits(plant, self.force_max)
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        self._position = signal_indices(plant, [f"{n}__position" for n in names])
        self._law = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        return saturate(-self._gains * np.asarray(y)[self._velocity], self._limits)

    @property
    def damping_per_pto(self) -> np.ndarray:
        """N s/m (or N m s/rad) per PTO, scene order, after reset()."""
        return self._gains.copy()

    @property
    def saturation(self) -> np.ndarray:
        """The command's limit per PTO in N or N m, inf where there is none, after reset()."""
        return self._limits.copy()

    def casadi_law(self, plant):
        if self._law is None:
            y = ca.SX.sym("y", len(plant.outputs))
            u = casadi_saturate(-ca.DM(self._gains) * y[self._velocity], self._limits)
            self._law = ca.Function("passive_law", [y], [u])
        return self._law

    def casadi_law_parametric(self, plant):
        """(law (y, gains) -> u, the gains): the reactive law's form with zero stiffness, its
        gains as parameters, so compiled code serves every damping and the reactive law too
        (sim.simulate embeds this one)."""
        law = linear_law_parametric(plant, self._velocity, self._position, self._limits)
        return law, np.concatenate([self._gains, np.zeros(len(self._gains))])

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "period_s": self.period,
                "saturation": "command clipped to +-force_max per PTO (null: none)",
                "force_max": limits_report(self._limits)}


def optimal_damping(plant, wave, *, pto: str | None = None, params=None, bounds=None,
                    force_max: float | None = None, stroke_max: float | None = None,
                    exceedance: float = 0.01, objective: str = "auto",
                    envelope: bool = False,
                    rated_power: float | None = None) -> tuple[float, float]:
    """PTO damping that maximises the mean absorbed power in `wave`: (damping, power W).

    Evaluated on the frequency-domain solution built straight from the BEM data (linear
    theory: Coulomb friction is left out, as linear theory cannot hold it), with the PTO's
    force -damping * v alone, as in closed loop. For a regular wave or an irregular sea (sum
    over its components). bounds: search interval, N s/m or N m s/rad; default: 1e-3 to 1e3
    times the PTO's intrinsic impedance |Z_i| at the wave's most energetic component (the
    regular-wave optimum is |Z_i| itself), so the search fits a tank model and a 10 m buoy.

    Limits (keyword-only; None: unconstrained, the search above): force_max (N or N m) and
    stroke_max (m or rad) bound the predicted peaks of the PTO force and position in `wave`,
    as `controllers.impedance.fd_statistics` predicts them (a regular wave: its amplitudes; a
    sea: the Rice level the record exceeds with probability <~ `exceedance`). The search is
    then a log grid over `bounds`, refined by Brent's method inside the feasible set or by
    bisection to its edge. A damper lowers the stroke and raises the force, so limits that
    no damping meets raise ValueError. (A damper only absorbs, so with an efficiency alone its
    electrical power is the efficiency times this mechanical power: the same optimum.)

    objective: "auto" (the default) maximises the electrical power of a PTO with a
    drivetrain (the mechanical power less the winding loss R |F|^2 / (gear kt')^2 / 2, whose
    optimum is a lighter damper), else the mechanical power; "mechanical" or "electrical"
    force one (tuning.electrical_winding). The power returned is the mechanical one.

    envelope: keep the predicted significant relative heave, roll and pitch within the linear
    model's range (analysis.envelope; tuning.constrained_tuning, which raises OutsideEnvelope
    with the closest damper when no damping can). rated_power (W): the predicted mean power
    at most that (a damper detuned in seas that would give more).
    """
    winding = electrical_winding(plant, pto, objective)
    if (force_max is not None or stroke_max is not None or winding is not None or envelope
            or rated_power is not None):
        c, _, power = constrained_tuning(plant, wave, pto=pto, params=params, passive=True,
                                         bounds=bounds, force_max=force_max,
                                         stroke_max=stroke_max, exceedance=exceedance,
                                         winding=winding, envelope=envelope,
                                         rated_power=rated_power)
        return c, power
    from scipy.optimize import minimize_scalar

    from mbcontrol.analysis import frequency_domain_response
    name = pto or plant.scene.ptos[0].name
    base = base_params(plant, name, params)
    parallel = base[f"{name}__damping"]       # a damper params sets beside the controller

    def power(damping: float) -> float:       # the controller's own: its force times velocity
        v = frequency_domain_response(plant, wave.omega, direction=wave.direction,
                                      params={**base, f"{name}__damping": parallel + damping},
                                      outputs=[f"{name}__velocity"])[:, 0]
        return float(np.sum(0.5 * damping * np.abs(v * wave.amplitude) ** 2))

    if bounds is None:
        bounds = default_bounds(plant, wave, name, base)
    result = minimize_scalar(lambda z: -power(np.exp(z)), method="bounded",
                             bounds=np.log(bounds), options={"xatol": 1e-4})
    return float(np.exp(result.x)), -float(result.fun)


