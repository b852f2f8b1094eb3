"""Reactive control: each PTO a damper and a spring, u = -(damping * v + stiffness * x).

A PI law on velocity (x is the integral of v). With the stiffness negative it cancels part of
the device's restoring force, tuning it to the wave; the PTO then returns energy to the body
over part of each cycle (reactive power), and absorbs more on average. Tuning:

- `intrinsic_impedance`: the impedance Z_i(omega) the PTO sees and the equivalent excitation,
  read off the frequency-domain (FD) solution built straight from the BEM data;
- `reactive_tuning`: complex-conjugate control (impedance matching) for a regular wave, or the
  best stable (damping, stiffness) pair for a sea state;
- `closed_loop_stability`: poles of the linearised closed loop (python-control), to reject a
  tuning before it is simulated.

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

from .base import per_pto, signal_indices


class Reactive:
    """Damper and spring on every PTO: u = -(damping * v + stiffness * x), the PTO's force.

    damping: N s/m (or N m s/rad), >= 0; stiffness: N/m (or N m/rad), any sign. Each one
    number for all PTOs or a dict by PTO name. x and v are the PTO's position and velocity
    (from rest). The law is static, so with period None it runs inside compiled code.
    """
    name = "reactive"

    def __init__(self, damping=0.0, stiffness=0.0, period: float | None = None):
        self.damping = damping
        self.stiffness = stiffness
        self.period = period          # s; None: every simulation step
        self._law = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        self._c = per_pto(plant, self.damping, "reactive damping")
        self._k = per_pto(plant, self.stiffness, "reactive stiffness")
        if np.any(self._c < 0):
            raise ValueError(f"reactive damping must be >= 0, got {self._c}")
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        self._position = signal_indices(plant, [f"{n}__position" for n in names])
        self._law = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        y = np.asarray(y)
        return -(self._c * y[self._velocity] + self._k * y[self._position])

    def casadi_law(self, plant):
        if self._law is None:
            y = ca.SX.sym("y", len(plant.outputs))
            u = -(ca.DM(self._c) * y[self._velocity] + ca.DM(self._k) * y[self._position])
            self._law = ca.Function("reactive_law", [y], [u])
        return self._law

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "stiffness": self.stiffness,
                "period_s": self.period}


def _base_params(plant, pto: str, params=None) -> dict:
    """Parameters of the plant as a controller sees it: no Coulomb friction (linear theory
    cannot hold it) and every PTO's own law zeroed (in closed loop the controller owns it)."""
    base = dict(params or {})
    for friction in plant.scene.frictions:
        base.setdefault(f"{friction.name}__coulomb", 0.0)
    for other in plant.scene.ptos:
        if other.name != pto:
            base.setdefault(f"{other.name}__damping", 0.0)
            base.setdefault(f"{other.name}__stiffness", 0.0)
    base.setdefault(f"{pto}__stiffness", 0.0)
    return base


def intrinsic_impedance(plant, omega, *, pto: str | None = None, params=None,
                        direction: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(Z_i, F_eq) at each omega (rad/s), exp(+i omega t): the PTO's Thevenin equivalent.

    Z_i (N s/m or N m s/rad): the impedance the PTO sees (everything but the PTO: inertia,
    added mass, radiation damping, restoring, the other PTOs as set by params); F_eq (N per m
    of wave amplitude): the force that drives it, so that with a PTO impedance Z_pto the PTO
    velocity is F_eq / (Z_i + Z_pto). Read off two FD solutions (mbcontrol.analysis) with
    different PTO damping c: V(c) = F_eq / (Z_i + c) is exact for a linear model, for any
    number of bodies.
    """
    from mbcontrol.analysis import frequency_domain_response
    name = pto or plant.scene.ptos[0].name
    omega = np.atleast_1d(np.asarray(omega, float))
    base = _base_params(plant, name, params)

    def velocity(c: float) -> np.ndarray:
        return frequency_domain_response(plant, omega, direction=direction,
                                         params={**base, f"{name}__damping": c},
                                         outputs=[f"{name}__velocity"])[:, 0]

    v0 = velocity(0.0)
    # first pass with a unit damper (exact, but poorly conditioned if |Z_i| >> 1), then
    # again with a damper of the size of Z_i, which keeps V0 - Vc well away from round-off
    Z = None
    for c in (1.0, None):
        c = c if c is not None else float(np.median(np.abs(Z)))
        vc = velocity(c)
        Z = c * vc / (v0 - vc)
    return Z, v0 * Z


def complex_conjugate_power(plant, wave, *, pto: str | None = None, params=None) -> float:
    """The upper bound of mean absorbed power in `wave` (W): sum |F_eq a|^2 / (8 Re Z_i)."""
    Z, F = intrinsic_impedance(plant, wave.omega, pto=pto, params=params,
                               direction=wave.direction)
    return float(np.sum(np.abs(F * wave.amplitude) ** 2 / (8 * Z.real)))


def closed_loop_stability(plant, damping: float, stiffness: float, *, pto: str | None = None,
                          params=None) -> tuple[bool, float]:
    """Is the linearised plant stable under u = -(damping v + stiffness x)? (stable, margin).

    margin (1/s): minus the largest real part of the closed-loop poles (python-control); > 0
    when stable, the decay rate of the slowest mode. Linearised about rest, with no Coulomb
    friction and the PTO's own law zeroed, as in closed-loop simulation.
    """
    import control

    from mbcontrol.linearize import linearize
    name = pto or plant.scene.ptos[0].name
    base = _base_params(plant, name, params)
    base[f"{name}__damping"] = 0.0
    sys = linearize(plant, params=base, inputs=[f"u__{name}"],
                    outputs=[f"{name}__position", f"{name}__velocity"])
    gain = np.array([[float(stiffness), float(damping)]])     # u = -gain @ [x, v]
    poles = control.feedback(sys, gain, sign=-1).poles()
    margin = -float(np.max(poles.real))
    return margin > 0, margin


def reactive_tuning(plant, wave, pto: str | None = None, *, params=None,
                    min_margin: float = 1e-3) -> tuple[float, float, float]:
    """(damping N s/m, stiffness N/m, predicted mean power W) for `wave`, linear theory.

    Regular wave: complex-conjugate control at its frequency (damping = Re Z_i, stiffness =
    omega Im Z_i), predicted power |F a|^2 / (8 Re Z_i). Sea state: the pair maximising the
    FD mean power sum_j c |V_j a_j|^2 / 2, V_j = F_eq / (Z_i + c - i k / omega_j), among those
    whose linear closed loop is stable with a margin >= min_margin (1/s). Either way the
    result is checked for closed-loop stability (ValueError if unstable).
    """
    from scipy.optimize import minimize

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

        best = None
        for start in ([np.log(c0), k0 / k_scale], [np.log(np.median(np.abs(Z))), 0.0]):
            res = minimize(cost, start, method="Nelder-Mead",
                           options={"xatol": 1e-4, "fatol": 1e-6 * abs(cost(start)) + 1e-9,
                                    "maxiter": 400})
            if best is None or res.fun < best.fun:
                best = res
        c, k = float(np.exp(best.x[0])), float(best.x[1] * k_scale)
    stable, margin = closed_loop_stability(plant, c, k, pto=name, params=params)
    if not stable:
        raise ValueError(f"{plant.name}: reactive tuning (damping {c:.4g}, stiffness {k:.4g}) "
                         f"gives an unstable closed loop (margin {margin:.3g} 1/s)")
    return c, k, power(c, k)
