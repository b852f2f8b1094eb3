"""Reactive control: each PTO a damper and a spring, u = -(damping * v + stiffness * x).

A PI law on velocity (x is the integral of v). With the stiffness negative it cancels part of
the device's restoring force, tuning it to the wave; the PTO then returns energy to the body
over part of each cycle (reactive power), and absorbs more on average. Tuning:

- `intrinsic_impedance`: the impedance Z_i(omega) the PTO sees and the equivalent excitation,
  read off the frequency-domain (FD) solution built straight from the BEM data;
- `reactive_tuning`: complex-conjugate control (impedance matching) for a regular wave, or the
  best stable (damping, stiffness) pair for a sea state;
- `closed_loop_stability`: poles of the linearised closed loop (python-control), to reject a
  tuning before it is simulated;
- `fd_statistics` and `constrained_tuning` (reactive_tuning's force_max / stroke_max /
  efficiency keywords): predicted mean mechanical and electrical power and force and stroke
  peaks of a (damping, stiffness) pair, and the best pair within the PTO's limits.

PTO limits: the command is saturated to +-force_max (the scene PTO's by default), compiled law
included. Saturation only clips the force: it does not keep the stroke, and a clipped negative
spring no longer cancels the restoring force, so the limits belong in the tuning.

Phasor convention of this module: exp(+i omega t), as `mbcontrol.analysis` and python-control
(the hydro data's exp(-i omega t) phasors are complex conjugates of these). In it a heaving
body has Z_i = B + i (omega (m + A) - K / omega), velocity V = F / (Z_i + Z_pto), and the law
above is the PTO impedance Z_pto = damping - i stiffness / omega (force -Z_pto V, as x = V/(i
omega)). Matching Z_pto = conj(Z_i) gives damping = Re Z_i, stiffness = omega Im Z_i (for the
heaving body: omega^2 (m + A) - K, negative below resonance) and the mean power
|F a|^2 / (8 Re Z_i), the most any control can absorb from that wave.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
from mbcontrol.errors import ControllerError

from .base import per_pto, signal_indices
from .impedance import closed_loop_stability, intrinsic_impedance
from .law import Law
from .limits import casadi_saturate, force_limits, limits_report, linear_law_parametric, saturate
from .tuning import constrained_tuning, electrical_winding, multistart


class Reactive(Law):
    """Damper and spring on every PTO: u = sat(-(damping * v + stiffness * x)), the PTO's force.

    damping: N s/m (or N m s/rad), >= 0; stiffness: N/m (or N m/rad), any sign. Each one
    number for all PTOs or a dict by PTO name. x and v are the PTO's position and velocity
    (from rest). force_max: N (or N m), the saturation of the command (None: the scene PTO's
    force_max; inf: none; see controllers.limits.force_limits). The law is static, so with
    period None it runs inside compiled code, saturation included. A saturated spring-damper
    does not bound the stroke: tune with reactive_tuning(..., force_max=, stroke_max=).
    """
    name = "reactive"
    # the law protocol (controllers.law); tuned within the robustness floors when robust
    kind, tuned, exportable, floors = "linear", ("damping", "stiffness"), True, True
    run_state = "none: the gains and limits bound by reset(plant); no memory between calls"
    units = {"damping": "N s/m (or N m s/rad)", "stiffness": "N/m (or N m/rad)",
             "period": "s", "force_max": "N (or N m)"}

    @classmethod
    def tune(cls, plant, wave, pto=None, **options):
        """The (damping, stiffness) of `reactive_tuning` (below) for `wave`, within the PTO's
        limits, the linear model's envelope, its rated power and, robust, the robustness
        floors (options: Law.tune's); several PTOs tuned jointly (controllers.joint)."""
        from .law import pto_of
        from .law_tuning import tune_linear
        return tune_linear(cls, reactive_tuning, plant, wave, pto_of(plant, pto),
                           **options)

    def __init__(self, damping=0.0, stiffness=0.0, period: float | None = None,
                 force_max=None):
        self.damping = damping
        self.stiffness = stiffness
        self.period = period          # s; None: every simulation step
        self.force_max = force_max
        self._limits = None
        self._law = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        self._c = per_pto(plant, self.damping, "reactive damping")
        self._k = per_pto(plant, self.stiffness, "reactive stiffness")
        if np.any(self._c < 0):
            raise ControllerError(f"reactive damping must be >= 0, got {self._c}")
        self._limits = force_limits(plant, self.force_max)
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        self._position = signal_indices(plant, [f"{n}__position" for n in names])
        self._law = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        y = np.asarray(y)
        return saturate(-(self._c * y[self._velocity] + self._k * y[self._position]),
                        self._limits)

    @property
    def damping_per_pto(self) -> np.ndarray:
        """N s/m (or N m s/rad) per PTO, scene order, after reset()."""
        return self._c.copy()

    @property
    def stiffness_per_pto(self) -> np.ndarray:
        """N/m (or N m/rad) per PTO, scene order, after reset()."""
        return self._k.copy()

    @property
    def saturation(self) -> np.ndarray:
        """The command's limit per PTO in N or N m, inf where there is none, after reset()."""
        return self._limits.copy()

    def casadi_law(self, plant):
        if self._law is None:
            y = ca.SX.sym("y", len(plant.outputs))
            u = -(ca.DM(self._c) * y[self._velocity] + ca.DM(self._k) * y[self._position])
            self._law = ca.Function("reactive_law", [y], [casadi_saturate(u, self._limits)])
        return self._law

    def casadi_law_parametric(self, plant):
        """(law (y, [damping, stiffness] per PTO) -> u, their values): the same law with its
        gains as parameters, so compiled code serves every pair (sim.simulate embeds it)."""
        law = linear_law_parametric(plant, self._velocity, self._position, self._limits)
        return law, np.concatenate([self._c, self._k])

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "stiffness": self.stiffness,
                "period_s": self.period,
                "saturation": "command clipped to +-force_max per PTO (null: none)",
                "force_max": limits_report(self._limits)}


def reactive_tuning(plant, wave, pto: str | None = None, *, params=None,
                    min_margin: float = 1e-3, force_max: float | None = None,
                    stroke_max: float | None = None, efficiency: float | None = None,
                    exceedance: float = 0.01, objective: str = "auto",
                    envelope: bool = False, rated_power: float | None = None,
                    robust: bool = False) -> tuple[float, float, float]:
    """(damping N s/m, stiffness N/m, predicted mean power W) for `wave`, linear theory.

    Regular wave: complex-conjugate control at its frequency (damping = Re Z_i, stiffness =
    omega Im Z_i), predicted power |F a|^2 / (8 Re Z_i). Sea state: the pair maximising the
    FD mean power sum_j c |V_j a_j|^2 / 2, V_j = F_eq / (Z_i + c - i k / omega_j), among those
    whose linear closed loop is stable with a margin >= min_margin (1/s). Either way the
    result is checked for closed-loop stability (ValueError if unstable).

    Limits and losses (keyword-only; all None: the tuning above, unchanged): force_max (N),
    stroke_max (m) bound the predicted force and stroke peaks of fd_statistics (regular wave:
    amplitudes; sea: the Rice level exceeded with probability <~ `exceedance`), and efficiency
    (0..1) makes the objective the predicted mean electrical power instead (reactive power
    is bought back at 1 / efficiency, which moves the optimum towards a damper). Then the
    search is constrained_tuning's; the power returned is still the mechanical one. A PTO
    with a drivetrain is tuned for electrical power by default (objective "auto"; see
    passive.optimal_damping): the winding loss of the spring's reactive current moves the
    optimum away from the complex conjugate. envelope, rated_power: as
    passive.optimal_damping's. robust: keep the loop min |1 + L| >= robustness.stability_floor()
    (with the default floors, a gain margin of 2.08 and a phase margin of 30.1 deg at the
    least; the floors are the defaults design.gain_margin_min and design.phase_margin_min_deg).
    This primitive's default is the unconstrained optimum; `design` and `export` (studies.design
    .tune) ask for robust=True unless told --aggressive.
    """
    winding = electrical_winding(plant, pto, objective)
    if (force_max is not None or stroke_max is not None or efficiency is not None or winding
            or envelope or rated_power is not None or robust):
        from .robustness import stability_floor
        return constrained_tuning(plant, wave, pto=pto, params=params, force_max=force_max,
                                  stroke_max=stroke_max, efficiency=efficiency,
                                  exceedance=exceedance, min_margin=min_margin,
                                  winding=winding, envelope=envelope,
                                  rated_power=rated_power,
                                  min_stability=stability_floor() if robust else None)

    name = pto or plant.scene.ptos[0].name
    w, a = np.asarray(wave.omega, float), np.asarray(wave.amplitude, float)
    Z, F = intrinsic_impedance(plant, w, pto=name, params=params, direction=wave.direction)

    def power(c: float, k: float) -> float:
        v = F * a / (Z + c - 1j * k / w)
        return float(np.sum(0.5 * c * np.abs(v) ** 2))

    if w.size == 1:
        c, k = float(Z[0].real), float(w[0] * Z[0].imag)
    else:
        # start from matching at the energy-weighted mean frequency, then maximise in
        # (log c, k / k_scale); an unstable pair scores zero so the search stays stable
        weight = np.abs(F * a) ** 2
        j = int(np.argmin(np.abs(w - np.sum(weight * w) / np.sum(weight))))
        c0, k0 = float(Z[j].real), float(w[j] * Z[j].imag)
        k_scale = max(abs(k0), float(np.median(np.abs(w * Z))))

        def cost(z):
            c, k = np.exp(z[0]), z[1] * k_scale
            stable, margin = closed_loop_stability(plant, c, k, pto=name, params=params)
            return -power(c, k) if stable and margin >= min_margin else 0.0

        best = multistart(cost, ([np.log(c0), k0 / k_scale], [np.log(np.median(np.abs(Z))), 0.0]),
                           xatol=1e-4, fatol_rel=1e-6, fatol_abs=1e-9, maxiter=400)
        c, k = float(np.exp(best.x[0])), float(best.x[1] * k_scale)
    stable, margin = closed_loop_stability(plant, c, k, pto=name, params=params)
    if not stable:
        raise ControllerError(f"{plant.name}: reactive tuning (damping {c:.4g}, stiffness {k:.4g}) "
                              f"gives an unstable closed loop (margin {margin:.3g} 1/s)")
    return c, k, power(c, k)


