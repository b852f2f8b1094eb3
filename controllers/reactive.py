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

from .base import per_pto, signal_indices
from .passive import casadi_saturate, force_limits, limits_report, saturate


class Reactive:
    """Damper and spring on every PTO: u = sat(-(damping * v + stiffness * x)), the PTO's force.

    damping: N s/m (or N m s/rad), >= 0; stiffness: N/m (or N m/rad), any sign. Each one
    number for all PTOs or a dict by PTO name. x and v are the PTO's position and velocity
    (from rest). force_max: N (or N m), the saturation of the command (None: the scene PTO's
    force_max; inf: none; see controllers.passive.force_limits). The law is static, so with
    period None it runs inside compiled code, saturation included. A saturated spring-damper
    does not bound the stroke: tune with reactive_tuning(..., force_max=, stroke_max=).
    """
    name = "reactive"

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
            raise ValueError(f"reactive damping must be >= 0, got {self._c}")
        self._limits = force_limits(plant, self.force_max)
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        self._position = signal_indices(plant, [f"{n}__position" for n in names])
        self._law = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        y = np.asarray(y)
        return saturate(-(self._c * y[self._velocity] + self._k * y[self._position]),
                        self._limits)

    def casadi_law(self, plant):
        if self._law is None:
            y = ca.SX.sym("y", len(plant.outputs))
            u = -(ca.DM(self._c) * y[self._velocity] + ca.DM(self._k) * y[self._position])
            self._law = ca.Function("reactive_law", [y], [casadi_saturate(u, self._limits)])
        return self._law

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "stiffness": self.stiffness,
                "period_s": self.period,
                "saturation": "command clipped to +-force_max per PTO (null: none)",
                "force_max": limits_report(self._limits)}


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
    margin = _margin_function(plant, pto or plant.scene.ptos[0].name, params)(damping, stiffness)
    return margin > 0, margin


def _margin_function(plant, name: str, params=None):
    """(damping, stiffness) -> stability margin (1/s), from one linearisation."""
    import control

    from mbcontrol.linearize import linearize
    base = _base_params(plant, name, params)
    base[f"{name}__damping"] = 0.0
    sys = linearize(plant, params=base, inputs=[f"u__{name}"],
                    outputs=[f"{name}__position", f"{name}__velocity"])

    def margin(damping: float, stiffness: float) -> float:
        gain = np.array([[float(stiffness), float(damping)]])     # u = -gain @ [x, v]
        return -float(np.max(control.feedback(sys, gain, sign=-1).poles().real))
    return margin


def fd_statistics(Z, F, wave, damping, stiffness, *, efficiency: float | None = None,
                  exceedance: float = 0.01) -> dict:
    """Linear-theory statistics of u = -(damping v + stiffness x) in `wave` (exp(+i omega t)).

    Z, F: intrinsic_impedance at wave.omega. damping (N s/m) and stiffness (N/m) broadcast
    (arrays give arrays). Per component j the PTO velocity is V_j = F_j a_j / (Z_j + c - i k /
    omega_j), its position X_j = V_j / (i omega_j), its force U_j = -(c V_j + k X_j). Keys:

    - power_W: mean absorbed power sum c |V_j|^2 / 2 (W);
    - electrical_W: mean electrical power with `efficiency` eta, eta P when absorbing and P /
      eta when the PTO drives the body (as metrics.electrical_power); None: power_W. A regular
      wave's P(t) = A + B cos(2 omega t) is split exactly; in a sea P = -u v with u and v jointly
      Gaussian, E|P| = s_u s_v (2 / pi)(sqrt(1 - r^2) + r asin r) (r their correlation);
    - stroke_peak (m), force_peak (N): a regular wave's amplitudes |X a|, |U a|; in a sea the
      level b that the record of length T (the wave's repeat period 2 pi / d_omega) crosses,
      upwards or downwards, with expected count `exceedance` by Rice's formula,
      2 (T / T_z) exp(-b^2 / 2 s^2) = exceedance, b = s sqrt(2 ln(2 T / (T_z exceedance))):
      a peak factor b / s of 4.5 for 150 zero-crossing periods and the default 1 % (T_z =
      2 pi s / s', the mean zero-crossing period from the spectral moments). The chance that
      the record's largest value exceeds b is at most about `exceedance`: Rice counts
      crossings, and they come in clusters (tests/test_limits.py measures 2-3 % of random-phase
      records at exceedance 10 %);
    - stroke_std, force_std: standard deviations (m, N).
    """
    w, a = np.asarray(wave.omega, float), np.asarray(wave.amplitude, float)
    c = np.asarray(damping, float)[..., None]
    k = np.asarray(stiffness, float)[..., None]
    V = F * a / (Z + c - 1j * k / w)
    X = V / (1j * w)
    U = -(c * V + k * X)
    power = np.sum(0.5 * c * np.abs(V) ** 2, axis=-1)
    var = {name: 0.5 * np.sum(np.abs(z) ** 2, axis=-1) for name, z in
           (("x", X), ("v", V), ("u", U), ("du", w * U))}
    s_x, s_v, s_u = (np.sqrt(var[n]) for n in ("x", "v", "u"))
    if w.size == 1:
        stroke, force = np.sqrt(2) * s_x, np.sqrt(2) * s_u           # amplitudes
        half = s_u * s_v                                             # B = |U| |V| / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            theta = np.arccos(np.clip(np.where(half > 0, -power / half, -1.0), -1, 1))
        positive = (power * theta + half * np.sin(theta)) / np.pi   # E[max(P, 0)]
    else:
        record = 2 * np.pi / (wave.d_omega or np.min(np.diff(np.sort(w))))

        def peak(s, s_rate):
            crossings = record * s_rate / (np.pi * np.maximum(s, 1e-300))   # 2 T / T_z
            return s * np.sqrt(2 * np.log(np.maximum(crossings / exceedance, 1.0)))
        stroke, force = peak(s_x, s_v), peak(s_u, np.sqrt(var["du"]))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.clip(np.where(s_u * s_v > 0, -power / (s_u * s_v), 0.0), -1, 1)
        mean_abs = s_u * s_v * (2 / np.pi) * (np.sqrt(1 - r ** 2) + r * np.arcsin(r))
        positive = 0.5 * (power + mean_abs)
    if efficiency is None:
        electrical = power
    else:
        electrical = efficiency * positive + (power - positive) / efficiency
    return {"power_W": power, "electrical_W": electrical, "stroke_peak": stroke,
            "force_peak": force, "stroke_std": s_x, "force_std": s_u}


def reactive_tuning(plant, wave, pto: str | None = None, *, params=None,
                    min_margin: float = 1e-3, force_max: float | None = None,
                    stroke_max: float | None = None, efficiency: float | None = None,
                    exceedance: float = 0.01) -> tuple[float, float, float]:
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
    search is constrained_tuning's; the power returned is still the mechanical one.
    """
    if force_max is not None or stroke_max is not None or efficiency is not None:
        return constrained_tuning(plant, wave, pto=pto, params=params, force_max=force_max,
                                  stroke_max=stroke_max, efficiency=efficiency,
                                  exceedance=exceedance, min_margin=min_margin)

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

        best = _multistart(cost, ([np.log(c0), k0 / k_scale], [np.log(np.median(np.abs(Z))), 0.0]),
                           xatol=1e-4, fatol_rel=1e-6, fatol_abs=1e-9, maxiter=400)
        c, k = float(np.exp(best.x[0])), float(best.x[1] * k_scale)
    stable, margin = closed_loop_stability(plant, c, k, pto=name, params=params)
    if not stable:
        raise ValueError(f"{plant.name}: reactive tuning (damping {c:.4g}, stiffness {k:.4g}) "
                         f"gives an unstable closed loop (margin {margin:.3g} 1/s)")
    return c, k, power(c, k)


def constrained_tuning(plant, wave, *, pto: str | None = None, params=None,
                       passive: bool = False, bounds=None, force_max: float | None = None,
                       stroke_max: float | None = None, efficiency: float | None = None,
                       exceedance: float = 0.01,
                       min_margin: float = 1e-3) -> tuple[float, float, float]:
    """(damping, stiffness, predicted mean power W) maximising the predicted mean power
    (electrical with `efficiency`, else mechanical) subject to fd_statistics' force and stroke
    peaks <= force_max (N) and stroke_max (m) (None: no limit) and, for a spring, a stable
    closed loop with margin >= min_margin (1/s).

    passive: stiffness 0, a 1-D search: a log grid of 400 dampings over `bounds` (default
    passive.default_bounds), then Brent's method between the best feasible point's neighbours
    if both are feasible, else bisection towards the infeasible one (the optimum is on the
    edge of the feasible set). Spring and damper: a grid of 81 log dampings over `bounds` by
    161 stiffnesses over +-2 k_s (k_s the matching stiffness at the most energetic component,
    at least the median |omega Z_i|), the best stable feasible point and the constrained
    passive optimum as starts of a Nelder-Mead search in (log c, k / k_s) that scores any
    infeasible or unstable pair as infinitely bad, so the result is never below the passive
    one in prediction. ValueError if no damping meets the limits.
    """
    from scipy.optimize import minimize_scalar

    from .passive import default_bounds
    name = pto or plant.scene.ptos[0].name
    Z, F = intrinsic_impedance(plant, wave.omega, pto=name, params=params,
                               direction=wave.direction)
    f_max = np.inf if force_max is None else float(force_max)
    s_max = np.inf if stroke_max is None else float(stroke_max)
    if not (f_max > 0 and s_max > 0):
        raise ValueError(f"limits must be > 0, got force_max={force_max}, stroke_max={stroke_max}")
    key = "power_W" if efficiency is None else "electrical_W"

    def evaluate(c, k):
        st = fd_statistics(Z, F, wave, c, k, efficiency=efficiency, exceedance=exceedance)
        feasible = (st["force_peak"] <= f_max) & (st["stroke_peak"] <= s_max)
        return st[key], feasible, st

    if bounds is None:
        base = _base_params(plant, name, params)
        base[f"{name}__damping"] = 0.0
        bounds = default_bounds(plant, wave, name, base)
    x = np.linspace(np.log(bounds[0]), np.log(bounds[1]), 400)
    objective, feasible, st = evaluate(np.exp(x), 0.0)
    if not feasible.any():
        raise ValueError(
            f"{plant.name}: no damping in {bounds[0]:.4g}..{bounds[1]:.4g} keeps the predicted "
            f"peaks within force_max {f_max:.4g} and stroke_max {s_max:.4g} (least force peak "
            f"{st['force_peak'].min():.4g}, least stroke peak {st['stroke_peak'].min():.4g})")
    j = int(np.argmax(np.where(feasible, objective, -np.inf)))
    best_x = x[j]
    inside = 0 < j < x.size - 1
    if inside and feasible[j - 1] and feasible[j + 1]:
        res = minimize_scalar(lambda z: -evaluate(np.exp(z), 0.0)[0], method="bounded",
                              bounds=(x[j - 1], x[j + 1]), options={"xatol": 1e-6})
        if evaluate(np.exp(res.x), 0.0)[1] and -res.fun >= objective[j]:
            best_x = float(res.x)
    else:
        edge = [n for n in (j - 1, j + 1) if 0 <= n < x.size and not feasible[n]]
        if edge:
            lo, hi = x[j], x[edge[0]]
            for _ in range(50):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if evaluate(np.exp(mid), 0.0)[1] else (lo, mid)
            if evaluate(np.exp(lo), 0.0)[0] >= objective[j]:
                best_x = lo
    c_passive = float(np.exp(best_x))
    if passive:
        return c_passive, 0.0, float(evaluate(c_passive, 0.0)[2]["power_W"])

    margin = _margin_function(plant, name, params)
    w = np.asarray(wave.omega, float)
    j = int(np.argmax(np.abs(F * wave.amplitude)))
    k_scale = max(abs(float(w[j] * Z[j].imag)), float(np.median(np.abs(w * Z))))
    log_c = np.linspace(np.log(bounds[0]), np.log(bounds[1]), 81)
    k_grid = np.linspace(-2, 2, 161) * k_scale
    grid = np.empty((log_c.size, k_grid.size))
    for i, lc in enumerate(log_c):
        value, ok, _ = evaluate(np.exp(lc), k_grid)
        grid[i] = np.where(ok, value, -np.inf)
    starts = [np.array([best_x, 0.0])]
    for flat in np.argsort(grid, axis=None)[::-1][:400]:     # best first, until a stable one
        i, m = np.unravel_index(flat, grid.shape)
        if not np.isfinite(grid[i, m]):
            break
        if margin(np.exp(log_c[i]), k_grid[m]) >= min_margin:
            starts.insert(0, np.array([log_c[i], k_grid[m] / k_scale]))
            break

    def cost(z):
        c, k = np.exp(z[0]), z[1] * k_scale
        value, ok, _ = evaluate(c, k)
        return -float(value) if ok and margin(c, k) >= min_margin else np.inf

    best = _multistart(cost, starts, xatol=1e-5, fatol_rel=1e-9, fatol_abs=1e-12, maxiter=600)
    c, k = float(np.exp(best.x[0])), float(best.x[1] * k_scale)
    if not np.isfinite(best.fun):
        raise ValueError(f"{plant.name}: no stable spring-damper meets the limits")
    return c, k, float(evaluate(c, k)[2]["power_W"])


def _multistart(cost, starts, *, xatol, fatol_rel, fatol_abs, maxiter):
    """The best Nelder-Mead result over the starts in (log damping, scaled stiffness); the
    function tolerance is relative to the cost at each start."""
    from scipy.optimize import minimize
    best = None
    for start in starts:
        res = minimize(cost, start, method="Nelder-Mead",
                       options={"xatol": xatol, "fatol": fatol_rel * abs(cost(start)) + fatol_abs,
                                "maxiter": maxiter})
        if best is None or res.fun < best.fun:
            best = res
    return best
