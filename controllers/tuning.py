"""Tuning within limits: the best damper (or damper and spring) whose predicted force and
stroke peaks stay within the PTO limits, searched on the frequency-domain statistics."""
from __future__ import annotations

import numpy as np

from mbcontrol import defaults
from mbcontrol.analysis import envelope_response
from mbcontrol.errors import ControllerError

from .impedance import (base_params, default_bounds, fd_statistics, hull_impedance,
                        intrinsic_impedance, margin_function)


class OutsideEnvelope(ControllerError):
    """No setting keeps the device inside its envelope in this sea. fallback: (damping,
    stiffness, predicted power W) of the damper that comes closest; ratio: its largest
    predicted significant motion over the limit."""

    def __init__(self, message: str, *, fallback: tuple, ratio: float):
        super().__init__(message)
        self.fallback, self.ratio = fallback, ratio


class LimitsUnreachable(ControllerError):
    """No damper holds the PTO's force and stroke limits together in this sea: a light one
    lets the stroke pass its limit, a heavy one the force (studies.design.fallback then
    tries a force-saturated damper)."""


def constrained_tuning(plant, wave, *, pto: str | None = None, params=None,
                       passive: bool = False, bounds=None, force_max: float | None = None,
                       stroke_max: float | None = None, efficiency: float | None = None,
                       exceedance: float = 0.01, min_margin: float = 1e-3,
                       winding: float | None = None, envelope: bool = False,
                       rated_power: float | None = None,
                       min_stability: float | None = None,
                       force_on: str | None = None) -> tuple[float, float, float]:
    """(damping, stiffness, predicted mean power W) maximising the predicted mean power
    (electrical with `efficiency` or a drivetrain's `winding` coefficient, else mechanical;
    impedance.fd_statistics) subject to fd_statistics' force and stroke
    peaks <= force_max (N) and stroke_max (m) (None: no limit) and, for a spring, a stable
    closed loop with margin >= min_margin (1/s), and with `envelope` every quantity of the
    linear model's range (analysis.envelope: relative heave against the mean draft, roll and
    pitch against 30 deg) within "envelope.share" of its limit, as predicted for this sea, and
    with `rated_power` (W) the predicted mean power (the objective's: electrical or
    mechanical) at most that: in a sea that would give more, the law detunes to it. With
    `min_stability` (controllers.robustness.STABILITY_FLOOR) the loop's least distance from
    -1, min |1 + L(i omega)| with L = Z_pto / Z_i over the hydro data's band and at rest, is at
    least that (0.52 gives a gain margin of 2.08 and a phase margin of 30.1 deg at the least).
    force_on: which force force_max limits (None: the scene PTO's force_max_on; with a
    drivetrain "hull" is the force on the hull, the machine's less gear^2 (J a + b v + K x)).

    passive: stiffness 0, a 1-D search: a log grid of 400 dampings over `bounds` (default
    impedance.default_bounds), then Brent's method between the best feasible point's neighbours
    if both are feasible, else bisection towards the infeasible one (the optimum is on the
    edge of the feasible set). Spring and damper: a grid of 81 log dampings over `bounds` by
    161 stiffnesses over +-2 k_s (k_s the matching stiffness at the most energetic component,
    at least the median |omega Z_i|), the best stable feasible point and the constrained
    passive optimum as starts of a Nelder-Mead search in (log c, k / k_s) that scores any
    infeasible or unstable pair as infinitely bad, so the result is never below the passive
    one in prediction. ValueError if no damping meets the force and stroke limits;
    OutsideEnvelope (a ValueError) if none also keeps the device inside its envelope: it
    carries the damper that comes closest (`fallback`, `ratio`), for a caller that flags the
    sea rather than stops.
    """
    name = pto or plant.scene.ptos[0].name
    Z, F = intrinsic_impedance(plant, wave.omega, pto=name, params=params,
                               direction=wave.direction)
    f_max = np.inf if force_max is None else float(force_max)
    s_max = np.inf if stroke_max is None else float(stroke_max)
    if not (f_max > 0 and s_max > 0):
        raise ControllerError(f"limits must be > 0, got force_max={force_max}, stroke_max={stroke_max}")
    key = "power_W" if efficiency is None and winding is None else "electrical_W"
    hull = hull_impedance(plant, name, wave.omega, force_on)

    env = None
    if envelope:
        env = envelope_response(plant, wave, name, params=base_params(plant, name, params))
    w = np.asarray(wave.omega, float)
    robust = None if min_stability is None else _loop_distance(plant, name, params, wave)

    def evaluate(c, k):
        st = fd_statistics(Z, F, wave, c, k, efficiency=efficiency, exceedance=exceedance,
                           winding=winding, hull=hull)
        feasible = (st["force_peak"] <= f_max) & (st["stroke_peak"] <= s_max)
        if rated_power is not None:
            feasible = feasible & (st[key] <= rated_power)
        if robust is not None:
            st["stability"] = robust(c, k)
            feasible = feasible & (st["stability"] >= min_stability)
        if env is not None:           # the PTO force phasors, exp(-i omega t) for the envelope
            cc, kk = np.asarray(c, float)[..., None], np.asarray(k, float)[..., None]
            force = -(cc - 1j * kk / w) * F * wave.amplitude / (Z + cc - 1j * kk / w)
            st["envelope_ratio"] = env.ratio(np.conj(force))
            feasible = feasible & (st["envelope_ratio"] <= defaults.get("envelope.share"))
        return st[key], feasible, st

    if bounds is None:
        bounds = default_bounds(plant, wave, name, base_params(plant, name, params))
    x = np.linspace(np.log(bounds[0]), np.log(bounds[1]), 400)
    objective, feasible, st = evaluate(np.exp(x), 0.0)
    if not feasible.any():
        _no_feasible_damper(plant, x, st, bounds=bounds, env=env, Z=Z, F=F, wave=wave,
                            f_max=f_max, s_max=s_max, rated_power=rated_power, key=key)
    best_x = _best_on_grid(evaluate, x, objective, feasible)
    c_passive = float(np.exp(best_x))
    if passive:
        return c_passive, 0.0, float(evaluate(c_passive, 0.0)[2]["power_W"])
    c, k = _best_spring_damper(plant, name, params, evaluate, bounds=bounds, best_x=best_x,
                               Z=Z, F=F, wave=wave, min_margin=min_margin)
    return c, k, float(evaluate(c, k)[2]["power_W"])


def _no_feasible_damper(plant, x, st, *, bounds, env, Z, F, wave, f_max, s_max, rated_power,
                        key):
    """Raise why no damper on the log grid `x` is feasible: OutsideEnvelope, with the closest
    damper, when the limits can be met but the envelope cannot; else ControllerError."""
    if env is not None:
        limited = (st["force_peak"] <= f_max) & (st["stroke_peak"] <= s_max)
        if rated_power is not None:
            limited = limited & (st[key] <= rated_power)
        if limited.any():            # the limits can be met, the envelope cannot
            j = int(np.argmin(np.where(limited, st["envelope_ratio"], np.inf)))
            c = float(np.exp(x[j]))
            worst = env.report(np.conj(-c * F * wave.amplitude / (Z + c)))
            raise OutsideEnvelope(
                f"{plant.name}: no damping keeps the device inside its linear model's range "
                f"in this sea: the closest ({c:.4g}) reaches "
                + ", ".join(f"{r['name']} {r['significant']:.3g} ({100 * r['share']:.0f} % of "
                            f"{r['limit']:.3g}, {r['source']})" for r in worst),
                fallback=(c, 0.0, float(st["power_W"][j])),
                ratio=float(st["envelope_ratio"][j]))
    # a light damper keeps the force low but lets the stroke grow, a heavy one the reverse:
    # say both ends of the trade, where each limit alone is met, not two unrelated minima
    within_force = st["force_peak"] <= f_max
    within_stroke = st["stroke_peak"] <= s_max
    parts = []
    if within_force.any():
        j = int(np.flatnonzero(within_force)[-1])
        parts.append(f"the heaviest damper within force_max ({np.exp(x[j]):.4g} N s/m) lets "
                     f"the stroke peak reach {st['stroke_peak'][j]:.4g} (stroke_max {s_max:.4g})")
    if within_stroke.any():
        j = int(np.flatnonzero(within_stroke)[0])
        parts.append(f"the lightest within stroke_max ({np.exp(x[j]):.4g} N s/m) needs a force "
                     f"peak of {st['force_peak'][j]:.4g} (force_max {f_max:.4g})")
    raise LimitsUnreachable(
        f"{plant.name}: no damping in {bounds[0]:.4g}..{bounds[1]:.4g} keeps both predicted "
        f"peaks within the limits in this sea: " + ("; ".join(parts) or
                                                     "neither limit can be met alone"))


def _best_on_grid(evaluate, x, objective, feasible) -> float:
    """The best feasible log damping, refined: Brent's method between its neighbours when both
    are feasible, else bisection towards the infeasible one (the optimum is on the edge)."""
    from scipy.optimize import minimize_scalar
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
    return best_x


def _best_spring_damper(plant, name, params, evaluate, *, bounds, best_x, Z, F, wave,
                        min_margin) -> tuple[float, float]:
    """(damping, stiffness): a damping-stiffness grid's best stable feasible point and the
    passive optimum (log damping `best_x`) start a Nelder-Mead search in (log c, k / k_s)."""
    w = np.asarray(wave.omega, float)
    margin = margin_function(plant, name, params)
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

    best = multistart(cost, starts, xatol=1e-5, fatol_rel=1e-9, fatol_abs=1e-12, maxiter=600)
    c, k = float(np.exp(best.x[0])), float(best.x[1] * k_scale)
    if not np.isfinite(best.fun):
        raise ControllerError(f"{plant.name}: no stable spring-damper meets the limits")
    return c, k


def _loop_distance(plant, name: str, params, wave, n: int = 300):
    """(damping, stiffness) -> min |1 + L(i omega)| of u = -(c v + k x) (broadcast), L =
    Z_pto / Z_i from the BEM data on a log grid over the hydro band and the sea's own
    frequencies, and at rest, L(0) = k / K with K the stiffness the PTO sees."""
    omega = plant.hydro.omega
    grid = np.union1d(np.geomspace(float(omega[0]), float(omega[-1]), n),
                      np.asarray(wave.omega, float))
    # Z_i does not depend on the direction: the mean one serves a spread sea's grid too
    Z, _ = intrinsic_impedance(plant, grid, pto=name, params=params,
                               direction=wave.mean_direction)
    # Re(i omega Z_i) = K - omega^2 m at low frequency: K from the two lowest frequencies
    r0, r1 = (float((1j * w * z).real) for w, z in zip(grid[:2], Z[:2]))
    K = (r0 * grid[1] ** 2 - r1 * grid[0] ** 2) / (grid[1] ** 2 - grid[0] ** 2)

    def distance(c, k):
        c, k = np.asarray(c, float)[..., None], np.asarray(k, float)[..., None]
        L = (c - 1j * k / grid) / Z
        least = np.min(np.abs(1 + L), axis=-1)
        if K > 0:                                   # at rest the spring alone: L(0) = k / K
            least = np.minimum(least, np.abs(1 + k[..., 0] / K))
        return least
    return distance


def electrical_winding(plant, pto: str | None, objective: str) -> float | None:
    """The tuners' objective: "auto" (electrical power when the PTO has a drivetrain, else
    mechanical), "electrical" or "mechanical". Returns the drivetrain's winding coefficient for
    an electrical objective (analysis.electrical.winding_coefficient), None for a mechanical
    one."""
    from mbcontrol.analysis import winding_coefficient
    if objective not in ("auto", "electrical", "mechanical"):
        raise ControllerError(f"objective {objective!r}: expected auto, electrical or mechanical")
    name = pto or plant.scene.ptos[0].name
    winding = None if objective == "mechanical" else winding_coefficient(plant, name)
    if objective == "electrical" and winding is None:
        raise ControllerError(f"objective 'electrical': PTO {name!r} has no [pto.drivetrain] "
                              f"(give one, or an efficiency to the reactive tuner)")
    return winding


def multistart(cost, starts, *, xatol, fatol_rel, fatol_abs, maxiter):
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
