"""Sampled linear PTO laws checked as sampled: every PTO's loop closed at once, in discrete time.

A controller with a period h is called every h seconds and its command held in between
(zero-order hold; mbcontrol.sim.simulate). On a spring-damper u = -(c v + k x) the hold lags the
command by about h / 2, u(t) ~ -(c v + k x(t - h / 2)) ~ -((c - k h / 2) v + k x): a positive
stiffness removes a damping k h / 2 (a negative one adds |k| h / 2), so a reactive law that
is stable in continuous time can be unstable sampled. And a law on every PTO loads every PTO:
a loop with the others left free is not the loop simulated.

Here the plant is linearised about rest (mbcontrol.analysis.linearize: no Coulomb friction,
every PTO's own scene law zeroed unless `params` sets it, as in closed-loop simulation) from
every PTO force u_p to every PTO position and velocity, discretised exactly with the hold
(mbcontrol.lti.zoh) and closed with u_k = -G y_k, the command computed from the
outputs sampled at t_k and applied over [t_k, t_k + h) (no further delay: simulate's). The
loop is stable when the spectral radius rho < 1; -ln(rho) / h is its equivalent continuous
decay rate (1/s).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from mbcontrol.errors import ControllerError, UnknownName
from mbcontrol.lti import zoh
from mbcontrol.plant import controlled_params
from mbcontrol.sim import closed_loop_map, sampled_verdict

if TYPE_CHECKING:       # python-control costs 2.5 s to import: only where it is used
    import control

# a loop gain this small relative to the loop's peak is a zero of L, not a crossing of the
# negative real axis (velocity feedback has L(0) = 0, which round-off puts at -1e-16)
_ZERO_GAIN = 1e-9


@dataclass(frozen=True)
class SampledLoop:
    """The joint closed loop of every PTO under u_p = -(damping_p v_p + stiffness_p x_p).

    period_s: the hold (s; None: continuous); stable; spectral_radius (nan when continuous);
    decay_rate: -ln(rho) / period, or minus the largest real part of the continuous poles
    (1/s; < 0: unstable); poles: z (sampled) or s (1/s, continuous); unstable_poles: those
    beyond the unit circle (right half-plane); gains: {pto: (damping, stiffness)}; message.
    """
    period_s: float | None
    stable: bool
    spectral_radius: float
    decay_rate: float
    poles: np.ndarray = field(repr=False)
    unstable_poles: np.ndarray
    gains: dict
    message: str

    def to_dict(self) -> dict:
        """JSON-ready (complex poles as [re, im]; the full pole list left out)."""
        rho = self.spectral_radius
        return {"period_s": self.period_s, "stable": bool(self.stable),
                "spectral_radius": None if np.isnan(rho) else float(rho),
                "decay_rate_1_s": float(self.decay_rate),
                "unstable_poles": [[float(p.real), float(p.imag)] for p in self.unstable_poles],
                "gains": {k: list(map(float, v)) for k, v in self.gains.items()},
                "message": self.message}


def joint_plant(plant, *, params=None) -> control.StateSpace:
    """The plant linearised about rest from every PTO force (N or N m; inputs u__<pto>) to
    every PTO's position and velocity (outputs <pto>__position, <pto>__velocity, PTO by PTO),
    with no Coulomb friction and the PTOs' scene laws zeroed unless `params` sets them."""
    from mbcontrol.analysis import linearize
    base = controlled_params(plant, params, linear=True)
    names = [p.name for p in plant.scene.ptos]
    return linearize(plant, params=base, inputs=[f"u__{n}" for n in names],
                     outputs=[f"{n}__{s}" for n in names for s in ("position", "velocity")])


def _complete(plant, gains: dict) -> dict:
    """{pto: (damping, stiffness)} for every PTO in scene order, a PTO left out free."""
    names = [p.name for p in plant.scene.ptos]
    unknown = set(gains) - set(names)
    if unknown:
        raise UnknownName(f"{plant.name}: gains for unknown PTO(s) {sorted(unknown)}; PTOs are "
                          f"{', '.join(names)}")
    return {n: tuple(map(float, gains.get(n, (0.0, 0.0)))) for n in names}


def gain_matrix(gains: dict, names) -> np.ndarray:
    """G with u = -G y, y = [x_1, v_1, x_2, v_2, ...]: block-diagonal [stiffness, damping]."""
    G = np.zeros((len(names), 2 * len(names)))
    for i, n in enumerate(names):
        damping, stiffness = gains[n]
        G[i, 2 * i:2 * i + 2] = stiffness, damping
    return G


def sampled_closed_loop(plant, gains, period: float | None, *, params=None) -> SampledLoop:
    """Stability of every PTO's loop closed at once with its command held over `period` s.

    gains: {pto: (damping N s/m or N m s/rad, stiffness N/m or N m/rad)}, a PTO left out
    free (controllers.margins.pto_gains reads them off a passive or reactive law). period
    None: the continuous joint loop, the poles of A - B G C. params: plant parameter
    overrides. Never raises on an unstable loop: `stable` and `message` say so.
    """
    gains = _complete(plant, gains)
    sys = joint_plant(plant, params=params)
    names = [p.name for p in plant.scene.ptos]
    G = gain_matrix(gains, names)
    A, B, C, D = (np.asarray(M) for M in (sys.A, sys.B, sys.C, sys.D))
    if period is None:
        poles = np.linalg.eigvals(A - B @ np.linalg.solve(np.eye(len(names)) + G @ D, G @ C))
        rate = -float(np.max(poles.real))
        bad = poles[poles.real > 0]
        state = "stable" if rate > 0 else "UNSTABLE"
        return SampledLoop(None, rate > 0, float("nan"), rate, poles, bad, gains,
                           f"the joint closed loop of PTOs {', '.join(names)} in continuous "
                           f"time is {state}: slowest pole at {-rate:.3g} 1/s (real part)")
    z = np.linalg.eigvals(closed_loop_map(A, B, C, D, -G, float(period)))
    # strict, as the continuous pole margin: a design check forgives no mode at the edge
    v = sampled_verdict(z, float(period), strict=True,
                        what=f"the joint closed loop of PTOs {', '.join(names)}")
    return SampledLoop(float(period), v["stable"], v["spectral_radius"], v["decay_rate_1_s"],
                       z, z[np.abs(z) >= 1], gains, v["message"])


def discrete_loop(plant, gains: dict, period: float, pto: str, *, params=None):
    """L(z) = G_p C_p (zI - Phi_o)^-1 Gamma_p, PTO `pto`'s sampled loop transfer (SISO,
    control.StateSpace with dt = period) with the other PTOs' loops closed in discrete time,
    Phi_o = Phi - Gamma_o G_o C_o. Negative feedback: u_p = -G_p y_p closes 1 + L(z) = 0.
    G_p = [stiffness, damping]; gains as sampled_closed_loop."""
    import control
    gains = _complete(plant, gains)
    names = list(gains)
    sys = joint_plant(plant, params=params)
    if np.any(np.asarray(sys.D)):
        raise ControllerError(f"{plant.name}: PTO positions and velocities should not depend on the "
                              f"force directly (D != 0)")
    Phi, Gamma = zoh(sys.A, sys.B, float(period))
    G, C = gain_matrix(gains, names), np.asarray(sys.C)
    i = names.index(pto)
    rest = [j for j in range(len(names)) if j != i]
    Phi_o = Phi - Gamma[:, rest] @ G[rest] @ C
    return control.ss(Phi_o, Gamma[:, i:i + 1], G[i:i + 1] @ C, np.zeros((1, 1)), float(period))


def loop_response_margins(L):
    """(gm, w_gm, [pm], [w_c], sm, w_sm) of a SISO loop L(z) sampled at L.dt, or L(s) when
    continuous (definitions as margins._margins; rad/s, up to Nyquist pi / dt when sampled),
    read off its frequency response rather than python-control's polynomial method, which
    misses the crossings of lightly damped, high-order loops (flap_pair: 80 states) or
    overflows (raft3). The response, from L's modes, is evaluated on a log grid plus +-20
    half-widths around every mode's frequency, and each crossing is refined with brentq on L
    itself."""
    h = float(L.dt) if L.isdtime(strict=True) else 0.0
    lam, V = np.linalg.eig(np.asarray(L.A))
    left, right = np.asarray(L.C) @ V, np.linalg.solve(V, np.asarray(L.B))
    residue, d = (left.ravel() * right.ravel()), float(np.asarray(L.D).ravel()[0])

    def response(w):
        w = np.atleast_1d(np.asarray(w, float))
        z = np.exp(1j * w * h) if h else 1j * w
        return (residue[None, :] / (z[:, None] - lam[None, :])).sum(axis=1) + d

    if h:
        nyquist = np.pi / h
        s = np.log(lam[np.abs(lam) > 0]) / h
    else:             # continuous: 100 times past the fastest mode stands for infinity
        s = lam
        scale = np.abs(lam[np.abs(lam) > 0]) if np.any(np.abs(lam) > 0) else np.array([1.0])
        nyquist = 100 * float(scale.max())
    grid = [np.logspace(np.log10(nyquist) - 5, np.log10(nyquist), 20000)]
    for pole in s[(s.imag > 0) & (s.imag < nyquist)]:
        width = max(abs(pole.real), 1e-6 * nyquist)
        grid.append(pole.imag + width * np.linspace(-20, 20, 401))
    w = np.unique(np.clip(np.concatenate(grid), 0.0, nyquist))
    H = response(w)
    peak = float(np.max(np.abs(H)))

    def crossings(f):                    # refined roots of f(w) between grid neighbours
        values = f(H)
        idx = np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0)
        return [brentq(lambda x: float(f(response(x))[0]), w[i], w[i + 1]) for i in idx]

    gm, w_gm = np.inf, np.nan
    axis = [(x, complex(response(x)[0])) for x in crossings(lambda H: H.imag)]
    with np.errstate(divide="ignore", invalid="ignore"):     # real at both ends (s: 0, inf)
        axis += ([(x, complex(response(x)[0])) for x in (0.0, nyquist)] if h
                 else [(0.0, complex(response(0.0)[0])), (np.inf, complex(d))])
    axis = [(x, v) for x, v in axis
            if np.isfinite(v) and v.real < 0 and abs(v) > _ZERO_GAIN * peak]
    if axis:
        x, v = min(axis, key=lambda item: abs(np.log(1 / abs(item[1]))))
        gm, w_gm = 1 / abs(v), x
    wcs = crossings(lambda H: np.abs(H) - 1)
    pms = [float(abs(np.degrees(np.angle(-complex(response(x)[0]))))) for x in wcs]
    j = int(np.argmin(np.abs(1 + H)))
    best = minimize_scalar(lambda x: float(np.abs(1 + response(x)[0])), method="bounded",
                           bounds=(w[max(j - 1, 0)], w[min(j + 1, w.size - 1)]))
    sm, w_sm = min((float(np.abs(1 + H[j])), float(w[j])), (float(best.fun), float(best.x)))
    return float(gm), float(w_gm), pms, [float(x) for x in wcs], sm, w_sm


# A damper held over a period must keep at least this share of the decay rate it has in
# continuous time: rm3's sea-tuned warm-up damper (41 MN s/m at Tp 12.58 s) held over an MPC's
# 0.2 s is unstable (the float and plate lock and ring), which diverged 17 of 32 PacWave seas.
HELD_DECAY_SHARE = 0.5
DECAY_ROUND_OFF = 1e-9   # 1/s: decay rates this close count as equal (rho = 1 +- 1e-15)


def held_dampers(plant, damping: dict, period: float, *, params=None) -> tuple[dict, float]:
    """Dampers {pto: N s/m} scaled by the largest common factor f <= 1 whose joint loop, held
    over `period` s, is stable and keeps HELD_DECAY_SHARE of the continuous loop's decay rate
    (1/s) at the same dampers. Returns (dampers, f); f = 1 when they are kept as they are, f = 0
    (no damper) when not even a millionth of them is acceptable.
    The plant is linearised and discretised once; each trial is one eigenvalue problem."""
    names = [p.name for p in plant.scene.ptos]
    sys = joint_plant(plant, params=params)
    A, B, C = (np.asarray(M) for M in (sys.A, sys.B, sys.C))
    Phi, Gamma = zoh(A, B, float(period))

    def acceptable(f):
        G = gain_matrix({n: (f * damping.get(n, 0.0), 0.0) for n in names}, names)
        continuous = -float(np.max(np.linalg.eigvals(A - B @ G @ C).real))
        rho = float(np.max(np.abs(np.linalg.eigvals(Phi - Gamma @ G @ C))))
        held = -np.log(rho) / period if rho > 0 else np.inf
        # a mode no damper moves (a free drift: rate 0 both ways) passes at round-off
        return held >= HELD_DECAY_SHARE * continuous - DECAY_ROUND_OFF

    if acceptable(1.0):
        return dict(damping), 1.0
    bad, good = 1.0, 0.5
    while not acceptable(good):              # down by halves to an acceptable damper
        bad, good = good, good / 2
        if good < 1e-6:                      # the plant alone fails the test: no damper
            return {n: 0.0 for n in names}, 0.0
    for _ in range(12):                      # then to 1/4096 of the bracket in ln f
        mid = np.sqrt(bad * good)
        bad, good = (bad, mid) if acceptable(mid) else (mid, good)
    return {n: good * damping.get(n, 0.0) for n in names}, good
