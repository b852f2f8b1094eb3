"""Closed-loop stability margins of linear PTO laws on the linearised plant (python-control).

A linear PTO law u = -K(s) y, with y = [x, v] the PTO's position and velocity (m, m/s or rad,
rad/s) and u the PTO's whole force on its follower (N or N m), closes a negative-feedback loop
around G(s), the plant's transfer from u to y. G is linearised about rest with no Coulomb
friction and the PTO's own scene law zeroed (the controller owns the PTO force, as in
closed-loop simulation; `reactive.base_params`). The loop transfer is L(s) = K(s) G(s)
(SISO) and the closed loop's characteristic equation is 1 + L(s) = 0.

Passive and reactive control, u = -(damping v + stiffness x), have K = [stiffness, damping]:
L(s) = (damping + stiffness / s) G_v(s), with G_v = 1 / Z_i the PTO's intrinsic admittance. In
phasors of exp(+i omega t), L(i omega) = Z_pto / Z_i with Z_pto = damping - i stiffness / omega
(controllers.reactive). Two consequences the tests check by hand:

- a damper on a passive device: Re Z_i >= 0 and damping >= 0 give Re L >= 0, so the Nyquist
  curve never meets the negative real axis: infinite gain margin, phase margin >= 90 deg,
  stable for any damping;
- a spring: L(0) = stiffness / K, K the restoring stiffness the PTO sees (hydrostatics in
  heave). A negative stiffness puts L(0) on the negative real axis: the gain margin is
  K / |stiffness|, and stiffness < -K (L(0) < -1) leaves no net restoring force: unstable.

Margins reported (`Margins`):

- gain margin: the factor on K, nearest 1 in log, that puts L(i omega) on -1 where it crosses
  the negative real axis (> 1: gains may grow that much; < 1: the loop is beyond -1 and the
  gains must shrink by that factor to reach it); inf when there is no such crossing;
- phase margin (deg, unsigned): the least phase change, lag or lead, that puts L(i omega) on
  -1 where |L| = 1; inf when |L| never reaches 1. Unsigned because reactive control near
  complex-conjugate matching has |L(i omega_wave)| = 1 at an angle -2 arg Z_i, close to
  +-180 deg on either side, and the textbook sign (lag only) then reads "negative" for a
  stable loop. python-control's signed figure at the same crossing, remainder(arg L, 360 deg)
  - 180 deg (control.stability_margins: negative when the loop lags past -180 deg), is
  reported beside it as phase_margin_signed_deg; its absolute value is phase_margin_deg. The
  gain margin and its choice among crossings (nearest 1 in log, L(0) included) are
  python-control's too, and so is the stability margin;
- stability margin: min over omega >= 0 of |1 + L(i omega)| (omega = 0 and infinity
  included), the distance of the Nyquist curve from -1, 1 / (peak sensitivity);
- the closed-loop poles (reactive.closed_loop_stability for static laws): stable, and the
  pole margin (1/s), minus the largest real part. The poles decide stability; the margins say
  how far from the edge it is.

Saturation (a controller's force_max) is not in these small-signal margins.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import control
import numpy as np
from mbcontrol.errors import ControllerError, UnknownName

@dataclass(frozen=True)
class Margins:
    """Stability margins of one PTO's linear loop L(s) = K(s) G(s), negative feedback.

    gain_margin: factor on K (inf: never crosses the negative real axis); phase_margin_deg:
    unsigned, deg (inf: |L| never reaches 1); stability_margin: min |1 + L(i omega)|;
    frequencies in rad/s (nan where there is none; 0 is a crossing at DC); gain_crossovers_rad_s
    and phase_margins_deg: every |L| = 1 crossing and its margin; stable and pole_margin (1/s)
    from the closed-loop poles; message: a sentence saying all that. A sampled law (period_s
    set) has L(z), z = exp(i omega period_s), and pole_margin = -ln(spectral radius) /
    period_s, the equivalent continuous decay rate (controllers.sampled).
    """
    pto: str
    law: str
    gain_margin: float
    phase_crossover_rad_s: float
    phase_margin_deg: float
    gain_crossover_rad_s: float
    stability_margin: float
    stability_margin_rad_s: float
    gain_crossovers_rad_s: tuple
    phase_margins_deg: tuple
    stable: bool
    pole_margin: float
    message: str
    loop: object = field(default=None, repr=False, compare=False)   # L(s) or L(z)
    period_s: float | None = None   # the controller's sample period (s); None: continuous
    phase_margin_signed_deg: float = math.inf   # python-control's sign (module docstring)

    def to_dict(self) -> dict:
        """JSON-ready: no L(s); inf and nan become None."""
        out = {}
        for key in ("pto", "law", "gain_margin", "phase_crossover_rad_s", "phase_margin_deg",
                    "gain_crossover_rad_s", "stability_margin", "stability_margin_rad_s",
                    "gain_crossovers_rad_s", "phase_margins_deg", "stable", "pole_margin",
                    "message", "period_s", "phase_margin_signed_deg"):
            value = getattr(self, key)
            out[key] = [_finite(v) for v in value] if isinstance(value, tuple) else _finite(value)
        return out


def _finite(value):
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def plant_loop(plant, *, pto: str | None = None, params=None) -> control.StateSpace:
    """G(s): the linearised plant from the PTO force u (N or N m) to [position, velocity].

    About rest, no Coulomb friction, the PTO's own scene law zeroed, other PTOs as `params`
    sets them (default: free), as reactive.closed_loop_stability sees it.
    """
    from mbcontrol.analysis import linearize

    from .impedance import base_params
    name = pto or plant.scene.ptos[0].name
    base = base_params(plant, name, params)
    return linearize(plant, params=base, inputs=[f"u__{name}"],
                     outputs=[f"{name}__position", f"{name}__velocity"])


def _gains(law, pto: str):
    """(label, K): K a 1x2 static gain [stiffness, damping] or an LTI system, u = -K y."""
    if isinstance(law, (control.StateSpace, control.TransferFunction)):
        if law.ninputs != 2 or law.noutputs != 1:
            raise ControllerError(f"margins: an LTI law K(s) maps [x, v] (2 inputs) to the PTO "
                                  f"force (1 output); got {law.ninputs} inputs, {law.noutputs} "
                                  f"outputs")
        return "lti", law
    if isinstance(law, dict):
        from . import linear_law_named
        label, settings = linear_law_named(law), law
    else:
        label = getattr(law, "name", type(law).__name__)
        if getattr(law, "kind", None) != "linear":
            raise ControllerError(f"margins: {label!r} is not a linear law (passive, reactive, a "
                                  f"dict of damping and stiffness, or an LTI K(s)); switching and "
                                  f"predictive controllers have no loop transfer")
        settings = {"damping": law.damping, "stiffness": getattr(law, "stiffness", 0.0)}

    def one(value):                # a number for all PTOs, or a dict by PTO name
        return float(value.get(pto, 0.0) if isinstance(value, dict) else value)

    return label, (one(settings.get("damping", 0.0)), one(settings.get("stiffness", 0.0)))


def loop_margins(plant, law, *, pto: str | None = None, params=None,
                 period: float | None = None, others: dict | None = None) -> Margins:
    """Gain, phase and stability margins and closed-loop poles of a linear PTO law.

    law: a Passive or Reactive controller, a dict {"damping": N s/m, "stiffness": N/m} (or
    N m s/rad, N m/rad), or an LTI K(s) from [x, v] to the force, u = -K(s) [x, v] (negative
    feedback). pto: which PTO closes the loop (default the first); params: plant parameter
    overrides, e.g. the other PTOs' damping and stiffness when their loops are closed too (the
    default leaves them free). Never raises on an unstable loop: it says so in `stable` and
    `message`.

    period (s; default the law's own `period`): a sampled law, its command held over each
    period as simulate holds it. Then every PTO's loop is closed, jointly and in discrete
    time (controllers.sampled): the other PTOs with the law's gains for them,
    or others = {pto: (damping, stiffness)}; static laws only. Without a period, `others`
    closes the other PTOs continuously (as their scene damping and stiffness).
    """
    from .impedance import closed_loop_stability
    name = pto or plant.scene.ptos[0].name
    period = period if period is not None else getattr(law, "period", None)
    if period:
        return _sampled_margins(plant, law, float(period), name, params, others)
    if others:                  # a continuous law on the other PTOs is their scene law
        params = {**{f"{p}__{key}": float(v) for p, (c, k) in others.items()
                     for key, v in (("damping", c), ("stiffness", k))}, **(params or {})}
    G = plant_loop(plant, pto=name, params=params)
    label, K = _gains(law, name)
    if label == "lti":
        L = control.series(G, control.ss(K))
        poles = control.feedback(G, control.ss(K), sign=-1).poles()
        pole_margin = -float(np.max(poles.real))
        stable = pole_margin > 0
    else:
        damping, stiffness = K
        Kg = np.array([[stiffness, damping]])
        L = control.ss(G.A, G.B, Kg @ G.C, Kg @ G.D)
        stable, pole_margin = closed_loop_stability(plant, damping, stiffness, pto=name,
                                                    params=params)
    gm, w180, pms, wcs, sm, wsm = _margins(L)
    k = int(np.argmin(pms)) if pms else None
    pm = pms[k] if pms else math.inf
    wc = wcs[k] if pms else math.nan
    message = _message(name, label, stable, pole_margin, gm, w180, pm, wc, sm, L)
    return Margins(name, label, gm, w180, pm, wc, sm, wsm, tuple(wcs), tuple(pms),
                   bool(stable), float(pole_margin), message, L,
                   phase_margin_signed_deg=_signed(L, wc, pm))


def pto_gains(plant, law, others: dict | None = None) -> dict:
    """{pto: (damping, stiffness)} for every PTO (scene order), as a passive or reactive law
    (a controller or a dict of damping and stiffness, each a number or a dict by PTO) applies
    them in simulation; others = {pto: (damping, stiffness)} overrides."""
    names = [p.name for p in plant.scene.ptos]
    gains = {}
    for n in names:
        label, K = _gains(law, n)
        if label == "lti":
            raise ControllerError("margins: a sampled loop takes a static law (damping, stiffness); "
                                  "an LTI K(s) has no hold model here")
        gains[n] = K
    unknown = set(others or {}) - set(names)
    if unknown:
        raise UnknownName(f"{plant.name}: gains for unknown PTO(s) {sorted(unknown)}")
    gains.update({n: tuple(map(float, v)) for n, v in (others or {}).items()})
    return gains


def _sampled_margins(plant, law, period, name, params, others) -> Margins:
    """loop_margins of a sampled law: stable and pole_margin (-ln(rho) / period, 1/s) from
    every PTO's loop closed jointly (controllers.sampled.sampled_closed_loop), the margins
    from PTO `name`'s L(z) with the other loops closed in discrete time."""
    from .sampled import discrete_loop, loop_response_margins, sampled_closed_loop
    gains = pto_gains(plant, law, others)
    joint = sampled_closed_loop(plant, gains, period, params=params)
    L = discrete_loop(plant, gains, period, name, params=params)
    gm, w180, pms, wcs, sm, wsm = loop_response_margins(L)
    k = int(np.argmin(pms)) if pms else None
    pm, wc = (pms[k], wcs[k]) if pms else (math.inf, math.nan)
    label = _gains(law, name)[0]
    text = _message(name, label, joint.stable, joint.decay_rate, gm, w180, pm, wc, sm, L)
    message = (f"sampled at {period:g} s (zero-order hold), every PTO's loop closed "
               f"(spectral radius {joint.spectral_radius:.6g}): {text}")
    return Margins(name, label, gm, w180, pm, wc, sm, wsm, tuple(wcs), tuple(pms),
                   bool(joint.stable), float(joint.decay_rate), message, L, period,
                   _signed(L, wc, pm))


def _signed(L, wc: float, pm: float) -> float:
    """python-control's signed phase margin (deg) at the crossing wc (rad/s): arg(-L), i.e.
    remainder(arg L, 360) - 180; inf where |L| never reaches 1."""
    if not math.isfinite(pm):
        return math.inf
    point = np.exp(1j * wc * float(L.dt)) if L.isdtime(strict=True) else 1j * wc
    value = complex(np.asarray(L(point)).ravel()[0])
    return float(np.remainder(np.degrees(np.angle(value)), 360.0) - 180.0)


def _margins(L):
    """(gm, w_gm, [pm], [w_c], sm, w_sm) of a continuous SISO loop, read off its frequency
    response (controllers.sampled.loop_response_margins). python-control's polynomial method
    (control.stability_margins) reports crossings that are not there on high-order loops
    (wavestar, hinged_barge, flap_pair: |L| = 1 at frequencies where a direct evaluation of
    L(i omega) stays below 0.46) and overflows on raft3's."""
    from .sampled import loop_response_margins
    if not L.nstates:                           # a static gain: its value is the response
        value = float(np.asarray(L.D).ravel()[0])
        gm = 1 / abs(value) if value < 0 else math.inf
        return gm, (0.0 if value < 0 else math.nan), [], [], abs(1 + value), 0.0
    return loop_response_margins(L)


def _dc(L):
    """L at zero frequency (s = 0, or z = 1 when sampled); None where a pole sits there."""
    try:
        with np.errstate(divide="ignore", invalid="ignore"):
            dc = complex(np.asarray(L(1.0 if L.isdtime(strict=True) else 0j)).ravel()[0])
    except (ZeroDivisionError, np.linalg.LinAlgError):
        return None
    return dc if np.isfinite(dc) else None


def _message(pto, label, stable, pole_margin, gm, w_gm, pm, wc, sm, L) -> str:
    gain = ("inf (never crosses the negative real axis)" if math.isinf(gm)
            else f"{gm:.4g} at {w_gm:.4g} rad/s")
    phase = ("inf (|L| < 1 throughout)" if math.isinf(pm) else
             f"{pm:.3g} deg at {wc:.4g} rad/s (python-control's signed figure "
             f"{_signed(L, wc, pm):+.3g} deg)")
    text = (f"PTO {pto!r}, {label} law: gain margin {gain}; phase margin {phase}; "
            f"min |1 + L| = {sm:.3g}")
    if stable:
        return (f"stable closed loop (slowest pole decays at {pole_margin:.3g} 1/s). " + text)
    hint = ""
    dc = _dc(L)
    if dc is not None and dc.real < -1 and abs(dc.imag) < 1e-9 * abs(dc):
        hint = (f" L(0) = {dc.real:.4g} < -1: the PTO's negative stiffness outweighs the "
                f"restoring stiffness it sees, so nothing holds the device at rest.")
    growth = (f"a pole with real part {-pole_margin:.3g} 1/s (grows e-fold in "
              f"{1 / -pole_margin:.3g} s)" if pole_margin < 0 else "a pole on the imaginary axis")
    return f"UNSTABLE closed loop: {growth}.{hint} {text}"
