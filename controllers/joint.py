"""Several PTOs tuned together: each PTO's damper and spring chosen for the total power, with
every other PTO closed by its own tuned law, in linear theory straight from the BEM data.

Why jointly: on a device with several PTOs (an array, a pair of flaps, a raft) each PTO's
power depends on what the others do. Tuning one PTO with the others free, then applying its
law to all, predicts one thing and simulates another (array4: 111 % of a bound that assumed
the others at their scene damping). Here the prediction, the bound, the margins and the
simulation all see the same laws: every PTO p applies u_p = -(c_p v_p + k_p x_p).

Phasors of exp(-i omega t), as `analysis.ports`: with all PTOs' own scene laws zeroed, the PTO
velocities are V = Y F + H A (ports.port_responses). A PTO law is the impedance
Z_p = c_p + i k_p / omega (F_p = -Z_p V_p, since x = i V / omega), so

    V = (I + Y diag(Z)) ^-1 H A,

and PTO p absorbs sum_j c_p |V_pj|^2 / 2 (W). No set of PTO forces absorbs more in total than
the multiport optimum (ports.multiport_bound). In a regular wave that optimum is reached by
PTO laws exactly when each PTO's share of it is absorbed, not supplied (c_p = Re Z_p >= 0 with
Z_p = -F_p / V_p at the optimum): then joint_tuning returns it in closed form.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from mbcontrol.errors import ControllerError

from .impedance import phasor_statistics
from .tuning import multistart

GRID_POINTS = 400            # common-damping grid that finds a feasible start


@dataclass(frozen=True)
class JointTuning:
    """What joint_tuning found: damping, stiffness (dicts by PTO name; N s/m or N m s/rad, N/m
    or N m/rad), predicted_W (mechanical power per PTO, W), total_W (their sum, W),
    statistics (phasor_statistics per PTO: peaks, electrical power), margin (1/s: the joint
    linear closed loop's slowest decay rate), method (how it was found)."""
    damping: dict
    stiffness: dict
    predicted_W: dict
    total_W: float
    statistics: dict = field(repr=False)
    margin: float
    method: str


class PortModel:
    """The device seen from all its PTOs in `wave`: FD responses and the joint linear loop."""

    def __init__(self, plant, wave, params=None):
        from mbcontrol.analysis import linear_params, port_responses

        from .sampled import joint_plant
        self.plant, self.wave = plant, wave
        self.ptos = [p.name for p in plant.scene.ptos]
        self.omega = np.asarray(wave.omega, float)
        self.Y, self.H = port_responses(plant, self.omega, self.ptos, wave.direction, params)
        A = np.asarray(wave.amplitude, float) * np.exp(-1j * np.asarray(wave.phase, float))
        self.h = self.H * A[:, None]                         # (n_omega, n_pto)
        n = len(self.ptos)
        sys = joint_plant(plant, params=linear_params(plant, self.ptos, params))
        if np.any(np.asarray(sys.D) != 0):
            raise ControllerError(f"{plant.name}: a PTO's position or velocity depends directly "
                                  f"on a PTO force")
        self._A, self._B, self._C = (np.asarray(m) for m in (sys.A, sys.B, sys.C))
        self._n = n

    def phasors(self, c, k):
        """(V, X, U): (n_pto, n_omega) PTO velocity, position, force phasors of the laws."""
        c, k = np.asarray(c, float), np.asarray(k, float)
        Z = c[None, :] + 1j * k[None, :] / self.omega[:, None]       # (n_omega, n_pto)
        M = np.eye(self._n)[None] + self.Y * Z[:, None, :]
        V = np.linalg.solve(M, self.h[..., None])[..., 0]
        X = 1j * V / self.omega[:, None]
        return V.T, X.T, (-Z * V).T

    def statistics(self, c, k, efficiency=None, exceedance: float = 0.01) -> list:
        """phasor_statistics per PTO (scene order) under the laws (c, k)."""
        V, X, U = self.phasors(c, k)
        eff = efficiency if efficiency is not None else [None] * self._n
        return [phasor_statistics(V[p], X[p], U[p], float(c[p]), self.wave,
                                  efficiency=eff[p], exceedance=exceedance)
                for p in range(self._n)]

    def margin(self, c, k) -> float:
        """Minus the largest real part of the joint linear closed loop's poles (1/s)."""
        from .sampled import gain_matrix
        K = gain_matrix(dict(zip(self.ptos, zip(c, k))), self.ptos)     # u = -K y
        return -float(np.max(np.linalg.eigvals(self._A - self._B @ K @ self._C).real))


def joint_tuning(plant, wave, *, passive: bool = False, params=None, force_max=None,
                 stroke_max=None, efficiency=None, exceedance: float = 0.01,
                 min_margin: float = 1e-3) -> JointTuning:
    """Per-PTO (damping, stiffness) maximising the total predicted mean power of all PTOs
    (electrical with `efficiency`), each PTO's predicted force and stroke peaks within its
    limits, the joint linear closed loop stable with margin >= min_margin (1/s).

    force_max, stroke_max, efficiency: dicts by PTO name (missing or None: no limit, ideal);
    peaks as impedance.fd_statistics. passive: stiffness 0. Closed form where the multiport
    optimum is a set of PTO laws (module docstring); otherwise a grid of common dampings for a
    feasible start and a Nelder-Mead search over (log c_p, k_p / k_scale) from it and from each
    PTO's own impedance match. ValueError if no common damping meets the limits.
    """
    model = PortModel(plant, wave, params)
    names, n = model.ptos, len(model.ptos)
    f_max = np.array([_get(force_max, p) for p in names])
    s_max = np.array([_get(stroke_max, p) for p in names])
    eff = None if not efficiency else [efficiency.get(p) for p in names]
    key = "power_W" if eff is None else "electrical_W"
    limited = np.isfinite(f_max).any() or np.isfinite(s_max).any()

    def evaluate(c, k):
        stats = model.statistics(c, k, eff, exceedance)
        ok = all(s["force_peak"] <= f_max[p] and s["stroke_peak"] <= s_max[p]
                 for p, s in enumerate(stats))
        return float(sum(s[key] for s in stats)), ok, stats

    w = model.omega
    weight = np.sum(np.abs(model.h) ** 2, axis=1)
    j = int(np.argmax(weight))
    Z_own = 1.0 / np.diagonal(model.Y[j])            # each PTO's impedance, the others free
    if not passive and not limited and eff is None and w.size == 1:
        found = _closed_form(model)
        if found is not None and model.margin(*found) >= min_margin:
            return _result(model, *found, evaluate, "closed form (multiport optimum)")
    scale = float(np.median(np.abs(Z_own)))
    dampings = np.exp(np.linspace(np.log(1e-3 * scale), np.log(1e3 * scale), GRID_POINTS))
    values = [evaluate(np.full(n, cc), np.zeros(n))[:2] for cc in dampings]
    feasible = [v for (v, ok) in values if ok]
    if not feasible:
        raise ControllerError(f"{plant.name}: no common damping in {dampings[0]:.4g}.."
                              f"{dampings[-1]:.4g} keeps every PTO's predicted peaks within its "
                              f"limits")
    best = int(np.argmax([v if ok else -np.inf for (v, ok) in values]))
    c_common = np.full(n, dampings[best])
    c_own = np.maximum(np.abs(Z_own.real), 1e-6 * scale)
    k_own = np.zeros(n) if passive else -w[j] * Z_own.imag     # each PTO's own match
    k_scale = max(float(np.max(np.abs(k_own))), float(np.median(np.abs(w[j] * Z_own))), 1e-12)

    def unpack(z):              # a PTO may end up all but free: keep c inside a sane range
        c = np.exp(np.clip(z[:n], np.log(1e-6 * scale), np.log(1e6 * scale)))
        return c, (np.zeros(n) if passive else z[n:] * k_scale)

    # The margin (an eigenvalue problem of the whole closed loop: 24 ms at raft3's 275 states)
    # is asked only of a point that would beat the best stable point so far (raft3 in a
    # regular wave: 872 calls instead of 2,530, 22 s instead of 61 s, the same optimum). A
    # point not checked is worse than a stable one, so whether it is unstable cannot change
    # which point wins: the best is always a checked, stable one.
    best_stable = [-np.inf]

    def cost(z):
        c, k = unpack(z)
        value, ok, _ = evaluate(c, k)
        if not ok:
            return np.inf
        if not passive and value > best_stable[0]:
            if model.margin(c, k) < min_margin:
                return np.inf
            best_stable[0] = value
        return -value

    starts = [np.log(c_common), np.log(c_own)]
    if not passive:
        starts = [np.concatenate([s, k / k_scale]) for s in starts
                  for k in (np.zeros(n), k_own)]
    best = multistart(cost, starts, xatol=1e-5, fatol_rel=1e-8, fatol_abs=1e-12,
                      maxiter=400 * 2 * n)
    if not np.isfinite(best.fun):
        raise ControllerError(f"{plant.name}: joint tuning found no stable law within the limits")
    c, k = unpack(best.x)
    return _result(model, c, k, evaluate, "search (Nelder-Mead from a common damping and "
                                          "each PTO's own match)")


def _get(limits, name) -> float:
    value = (limits or {}).get(name)
    return np.inf if value is None else float(value)


def _closed_form(model):
    """(c, k) realising the multiport optimum of a regular wave, or None where a PTO would
    have to supply power (c_p < 0)."""
    from mbcontrol.analysis import multiport_bound
    opt = multiport_bound(model.plant, model.wave, responses=(model.Y, model.H))
    F, V = opt.force[0], opt.velocity[0]
    if not np.all(np.isfinite(F)) or np.any(np.abs(V) == 0):
        return None
    Z = -F / V
    if np.any(Z.real <= 0):
        return None
    return Z.real, model.omega[0] * Z.imag


def _result(model, c, k, evaluate, method) -> JointTuning:
    _, _, stats = evaluate(c, k)
    names = model.ptos
    power = {p: float(s["power_W"]) for p, s in zip(names, stats)}
    return JointTuning({p: float(v) for p, v in zip(names, c)},
                       {p: float(v) for p, v in zip(names, k)}, power,
                       float(sum(power.values())), dict(zip(names, stats)),
                       model.margin(c, k), method)


def other_laws(plant, parameters: dict, pto: str) -> dict:
    """Plant parameter overrides closing every PTO but `pto` with its law in `parameters`
    (damping and stiffness: a number for every PTO or a dict by PTO name, missing: 0), as the
    controller applies it in simulation."""
    out = {}
    for key in ("damping", "stiffness"):
        value = parameters.get(key, 0.0)
        for p in plant.scene.ptos:
            if p.name != pto:
                v = value.get(p.name, 0.0) if isinstance(value, dict) else value
                out[f"{p.name}__{key}"] = float(v)
    return out
