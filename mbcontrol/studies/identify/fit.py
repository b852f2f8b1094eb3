"""Fitting an `Identification`: Nelder-Mead (the seed's simplex search) or Gauss-Newton with
exact sensitivities (a bounded trust-region Levenberg-Marquardt, scipy's least_squares
"trf"), multi-start, and the uncertainty of the result.

Uncertainty (at the optimum, from the Gauss-Newton Hessian J^T J of the residuals in the
physical parameters, scaled by the residual variance s^2 = |r|^2 / (m - n)): covariance
s^2 (J^T J)^-1, standard errors, correlations. A parameter the optimum leaves at one of its
bounds (within AT_BOUND of the span, in the fitted variable) is reported there, with no sigma:
its Jacobian column describes a move the bound blocks, and the interval would be one-sided.
The others' covariance is that of the reduced problem (the bounded ones held), with m - n_free
degrees of freedom.

Residuals correlated in time (the peaks and timeseries costs: consecutive residuals of one run
and channel, `Identification.time_blocks`) make (J^T J)^-1 s^2 far too narrow: the samples are
not independent. There the covariance is the sandwich (J^T J)^-1 J^T Σ J (J^T J)^-1 with Σ the
AR(1) covariance γ0 ρ^|i-j| within each block (ρ the pooled lag-1 autocorrelation of the
residuals, floored at 0, γ0 = s^2), i.e. Newey-West with the AR(1) kernel; the result's
`uncertainty_method` states it, with ρ and the effective sample count m (1-ρ)/(1+ρ). Checked on
AR(1) measurement noise: 95 % intervals hold the truth in about 95 % of seeds (tests). Model
error that repeats every period is not AR(1): its intervals stay optimistic.

Parameters the data cannot separate are named in a warning: a pair with |correlation| >
CORRELATION_LIMIT, or the direction of the smallest singular value of the column-scaled
Jacobian when its condition number passes CONDITION_LIMIT.
"""
from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ... import defaults
from ...console import progress_bar
from ...errors import InputError

METHODS = ("gauss-newton", "nelder-mead")
# CORRELATION_LIMIT: the default "identify.correlation_limit" (mbcontrol.defaults)
# CONDITION_LIMIT: the default "identify.condition_limit" (mbcontrol.defaults)
AT_BOUND = 1e-6          # share of a parameter's span (in theta) that counts as on the bound


class IdentifiabilityWarning(UserWarning):
    """The data cannot separate some of the fitted parameters."""


@dataclass
class FitResult:
    """What a fit found: values (parameter -> value), std (standard errors, same units),
    correlation (n x n), cost before and after (1/2 |r|^2), the residuals, simulations run,
    wall time (s), the method and a list of warnings."""
    method: str
    names: list
    initial: dict
    values: dict
    std: dict
    correlation: np.ndarray
    cost_initial: float
    cost: float
    residuals: np.ndarray = field(repr=False)
    simulations: int = 0
    evaluations: int = 0
    wall_time_s: float = 0.0
    starts: int = 1
    warnings: list = field(default_factory=list)
    condition_number: float = float("nan")
    at_bound: dict = field(default_factory=dict)     # name -> "lower" or "upper"
    uncertainty_method: str = "independent residuals"


def fit(problem, method: str | None = None, *, starts: int = 1, seed: int = 0,
        max_evaluations: int | None = None, tol: float = 1e-8, progress: bool = False,
        theta0=None) -> FitResult:
    """Fit `problem` (an Identification) by `method`; starts > 1 adds random starts inside
    the bounds (uniform in theta) and keeps the best. Returns a FitResult with uncertainty.
    method left out: the default "identify.method" ("gauss-newton"; mbcontrol.defaults)."""
    method = defaults.resolve("identify.method", method)
    from scipy.optimize import least_squares, minimize
    if method not in METHODS:
        raise InputError(f"method {method!r}: expected one of {', '.join(METHODS)}")
    lo, hi = problem.bounds()
    rng = np.random.default_rng(seed)
    first = problem.theta0() if theta0 is None else np.asarray(theta0, float)
    points = [first] + [lo + (hi - lo) * rng.uniform(size=lo.size) for _ in range(starts - 1)]
    sims0, t0 = problem.simulations, time.perf_counter()
    bar = _bar(progress, method)
    cost_initial = problem.cost_value(first)
    best, evaluations = None, 0
    # (r, J) of Gauss-Newton's latest point (least_squares asks for r, then J at the same
    # point) and of its lowest-cost one: trf accepts every step that lowers the cost, so that
    # is where it stops, and its (r, J) is needed again below for the uncertainty
    # (time_blocks, which residuals() sets, depend only on the runs and the cost)
    evaluated, lowest = {}, [math.inf, None]
    for start in points:
        if method == "gauss-newton":
            def both(theta):
                key = tuple(theta)
                if key not in evaluated:
                    evaluated[key] = problem.residuals(theta, jacobian=True)
                    value = 0.5 * float(evaluated[key][0] @ evaluated[key][0])
                    if value < lowest[0]:
                        lowest[:] = value, key
                    for old in [k for k in evaluated if k not in (key, lowest[1])]:
                        del evaluated[old]
                    _tick(bar, value)
                return evaluated[key]

            res = least_squares(lambda th: both(th)[0], start, jac=lambda th: both(th)[1],
                                bounds=(lo, hi), method="trf", x_scale="jac", ftol=tol,
                                xtol=tol, gtol=tol, max_nfev=max_evaluations or 100)
            theta, value, evaluations = res.x, float(res.cost), evaluations + res.nfev
        else:
            span = np.where(hi > lo, hi - lo, 1.0)

            def cost(z):                      # the simplex lives on [0, 1] per parameter
                value = problem.cost_value(lo + span * np.clip(z, 0.0, 1.0))
                _tick(bar, value)
                return value

            z0 = (start - lo) / span
            res = minimize(cost, z0, method="Nelder-Mead", bounds=[(0.0, 1.0)] * lo.size,
                           options={"xatol": 1e-4, "fatol": tol * max(cost_initial, 1e-300),
                                    "maxfev": max_evaluations or 200 * lo.size,
                                    "adaptive": lo.size > 3})
            theta, value, evaluations = lo + span * res.x, float(res.fun), evaluations + res.nfev
        if best is None or value < best[1]:
            best = (theta, value)
    if bar is not None:
        bar.close()
    theta, value = best
    key = tuple(theta)
    r, J = evaluated[key] if key in evaluated else problem.residuals(theta, jacobian=True)
    span = np.where(hi > lo, hi - lo, 1.0)
    bound = {p.name: side for p, t, l, h, w in zip(problem.fit, theta, lo, hi, span)
             for side, gap in (("lower", t - l), ("upper", h - t)) if gap <= AT_BOUND * w}
    result = FitResult(method=method, names=[p.name for p in problem.fit],
                       initial={p.name: p.initial for p in problem.fit},
                       values=problem.values(theta), std={}, correlation=np.eye(len(theta)),
                       cost_initial=cost_initial, cost=0.5 * float(r @ r), residuals=r,
                       evaluations=evaluations, starts=len(points), at_bound=bound)
    uncertainty(problem, theta, r, J, result)
    result.simulations = problem.simulations - sims0
    result.wall_time_s = time.perf_counter() - t0
    return result


def uncertainty(problem, theta, r, J, result: FitResult) -> None:
    """Standard errors and correlations from s^2 (J_p^T J_p)^-1, J_p = dr/dp (physical), over
    the parameters not at a bound (result.at_bound: those get NaN and a warning)."""
    names = result.names
    free = np.array([name not in result.at_bound for name in names], bool)
    std, corr = np.full(len(names), math.nan), np.eye(len(names))
    messages = []
    if free.any():
        params = [p for p, f in zip(problem.fit, free) if f]
        std[free], corr[np.ix_(free, free)], result.condition_number, messages, method = \
            _covariance(params, theta[free], r, J[:, free], getattr(problem, "time_blocks", None))
        result.uncertainty_method = method
    messages += [f"{name} is at its {result.at_bound[name]} bound: reported there, without "
                 f"sigma (the data push it past the bound; widen it if the physics allows)"
                 for name in names if name in result.at_bound]
    result.std = dict(zip(names, map(float, std)))
    result.correlation = corr
    for text in messages:
        warnings.warn(text, IdentifiabilityWarning, stacklevel=3)
    result.warnings = messages


def _ar1(r, blocks):
    """Pooled lag-1 autocorrelation of r within consecutive blocks (sizes), floored at 0."""
    num = den = 0.0
    i = 0
    for n in blocks:
        seg = r[i:i + n]
        num += float(seg[1:] @ seg[:-1])
        den += float(seg @ seg)
        i += n
    return max(0.0, num / den) if den > 0 else 0.0


def _ar1_times(G, rho, blocks):
    """T G with T_ij = rho^|i-j| within each block (0 across): a forward and a backward
    first-order filter, T G = F + B - G, in O(m n)."""
    from scipy.signal import lfilter
    out = np.empty_like(G)
    i = 0
    for n in blocks:
        seg = G[i:i + n]
        forward = lfilter([1.0], [1.0, -rho], seg, axis=0)
        backward = lfilter([1.0], [1.0, -rho], seg[::-1], axis=0)[::-1]
        out[i:i + n] = forward + backward - seg
        i += n
    return out


def _covariance(params, theta, r, J, blocks=None):
    """(std, correlation, condition number, warnings, method) of `params` at theta; blocks:
    sizes of the residuals' time-correlated runs (module notes), None or all 1: independent."""
    names = [p.name for p in params]
    dp = np.array([p.from_theta(t) if p.log else 1.0 for p, t in zip(params, theta)])
    Jp = J / dp[None, :]
    m, n = Jp.shape
    dof = max(m - n, 1)
    s2 = float(r @ r) / dof
    scale = np.where(np.linalg.norm(Jp, axis=0) > 0, np.linalg.norm(Jp, axis=0), 1.0)
    Js = Jp / scale
    sv = np.linalg.svd(Js, compute_uv=False)
    condition = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    bread = np.linalg.pinv(Js.T @ Js)
    method = "independent residuals"
    rho = _ar1(r, blocks) if blocks and max(blocks) > 2 else 0.0
    if rho > 0:
        bread = bread @ (Js.T @ _ar1_times(Js, rho, blocks)) @ bread
        method = (f"AR(1) sandwich: residual lag-1 correlation {rho:.3f} within each run and "
                  f"channel, about {m * (1 - rho) / (1 + rho):.0f} independent samples of {m}")
    cov = s2 * bread / np.outer(scale, scale)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    unseen = np.linalg.norm(Jp, axis=0) == 0
    std[unseen] = np.nan
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = np.nan_to_num(cov / np.outer(std, std))
    messages = [f"{names[k]} has no effect on the data (e.g. its joint is blocked in every "
                f"run): its value is the initial one and its sigma undefined"
                for k in np.flatnonzero(unseen)]
    for i in range(n):
        for j in range(i + 1, n):
            if abs(corr[i, j]) > defaults.get("identify.correlation_limit"):
                messages.append(f"{names[i]} and {names[j]} are correlated "
                                f"{corr[i, j]:+.3f}: the data cannot separate them")
    if condition > defaults.get("identify.condition_limit") and not unseen.any():
        _, _, Vt = np.linalg.svd(Js)
        weak = Vt[-1]
        lead = [names[k] for k in np.argsort(-np.abs(weak)) if abs(weak[k]) > 0.3]
        messages.append(f"ill-conditioned (condition number {condition:.3g}): "
                        f"the combination of {', '.join(lead)} is barely seen by the data")
    if m <= n:
        messages.append(f"{m} residuals for {n} parameters: no degrees of freedom left for "
                        f"the residual variance")
    return std, corr, condition, messages, method


def _bar(progress: bool, method: str):
    if not progress:
        return None
    return progress_bar(desc=f"identify ({method})", unit="eval", leave=False)


def _tick(bar, cost: float) -> None:
    if bar is not None:
        bar.update(1)
        bar.set_postfix(cost=f"{cost:.4g}")
