"""The constrained power figure a design reports, and whether it is a bound on what it is
compared with.

A bound over every T-periodic PTO force (T the wave's repeat period) must let the force hold
every multiple of 2 pi / T, not only the sea's own frequencies: a saturating controller's force
fills the gaps between them and holds their harmonics, and with the sea's grid alone an MPC
beats the figure (the sphere in Hs 3.5 m, Tp 9.67 s, a 300 s sea, 2 MN, 4 m: 547.5 kW on the
sea's 115 frequencies, 563.9 kW on all 570 up to the data's 12 rad/s). The grid stops at the
hydro data's band (no physics beyond it), so the figure bounds forces inside that band; a
force's content above it is worth little (+0.7 % from 6 to 12 rad/s on that sea).

The figure is a mean over a whole repeat period in periodic steady state. A regular wave's
metrics (the last 10 periods) are such a mean, and so are a sea's when `design` scores its
last whole repeat period (its default: two periods simulated). A window after the ramp is not:
it can hold more energetic waves than the period (that sphere sea: the complex-conjugate
optimum's mean is 12 % above the period's over t >= ramp, 6.4 % over t >= 48 s). Compared
with such a window the figure is a "reference", with the window's complex-conjugate share so
a reader can see how far a window mean may stray.
"""
from __future__ import annotations

import math

import numpy as np

# Above this many force frequencies the dense interior-point solve is not run unless asked
# (full=True): it costs ~n^3 / 3 a step (bounds.PseudoSpectralProblem, solver "IPM"): 570
# frequencies (the sphere's 300 s sea to 12 rad/s) 9 s, 1146 (a 600 s sea) ~1-2 min. Beyond
# it the band is cut to this many and the figure is a reference, not a bound.
MAX_FORCE_COMPONENTS = 600


def _grid_size(period, lowest, omega_max) -> int:
    step = 2 * np.pi / period
    return max(0, math.floor(omega_max / step * (1 + 1e-9)) - math.ceil(lowest / step) + 1)


def window_share(conjugate, start: float, end: float) -> float:
    """The complex-conjugate optimum's mean absorbed power over [start, end] s of the
    realisation over its mean over the repeat period (1: no bias)."""
    from .ports import MultiportBound, window_mean_power
    single = MultiportBound(conjugate.power, conjugate.power_by_component,
                            np.asarray(conjugate.thevenin.omega, float),
                            conjugate.force[:, None], conjugate.velocity[:, None],
                            (conjugate.thevenin.pto,))
    return window_mean_power(single, start, end) / conjugate.power


def constrained_figure(plant, wave, pto, force_max: float, stroke_max: float, *,
                       params=None, harmonics: int = 1, full: bool = False,
                       conjugate=None, whole_period: bool = False,
                       oversample: float | None = None) -> dict:
    """The constrained figure (W) and what it is, as the keys of design's bound:

    constrained_W: the pseudo-spectral optimum (its dual certificate where the solver gives
    one), None on failure with constrained_reason; constrained_kind: "bound" or "reference";
    constrained_kind_reason: why; constrained_omega_max_rad_s, constrained_components: the
    force's grid (top frequency, rad/s; number); constrained_solve_time_s (s);
    constrained_points: the collocation times the limits hold at;
    constrained_max_force_dense, constrained_max_position_dense (N or N m, m or rad) and
    constrained_force_overshoot_pct, constrained_position_overshoot_pct: the optimal force and
    its position between the collocation points (analysis.dense; a figure whose force breaks
    a limit there is higher than the dense grid's, so still a bound); for a sea also
    window_s ([ramp, repeat period], s) and window_share (the complex-conjugate optimum's
    mean over that window over its period mean). harmonics: a regular wave's force grid
    (the design's choice); a sea's grid is every multiple of 2 pi / T in the hydro data's band,
    cut to MAX_FORCE_COMPONENTS unless full. conjugate: the complex_conjugate_bound, if known.
    whole_period: a sea's metrics are a mean over a whole repeat period (design's default),
    so the figure bounds them; else they are a window's and it is a reference. oversample:
    collocation density (default analysis.dense.OVERSAMPLE).
    """
    from ..waves import repeat_period
    from .bounds import PseudoSpectralProblem, complex_conjugate_bound
    out: dict = {"constrained_W": None, "constrained_reason": None}
    period, _ = repeat_period(wave)
    top, lowest = float(plant.hydro.omega[-1]), float(plant.hydro.omega[0])
    sea = wave.omega.size > 1
    reasons = []
    if sea:
        n = _grid_size(period, lowest, top)
        omega_max = top
        if n > MAX_FORCE_COMPONENTS and not full:
            step = 2 * np.pi / period
            omega_max = (math.ceil(lowest / step) + MAX_FORCE_COMPONENTS - 1) * step
            reasons.append(f"the force's band is cut to {omega_max:.3g} rad/s "
                           f"({MAX_FORCE_COMPONENTS} frequencies, not the {n} up to the data's "
                           f"{top:.3g} rad/s: a full grid takes minutes, ask with "
                           f"bounds='full'), so a saturating force may beat it")
        grid = {"omega_max": omega_max}
    else:
        grid = {"harmonics": harmonics}
        omega_max = harmonics * float(wave.omega[0])
        if omega_max + float(wave.omega[0]) <= top:
            reasons.append(f"the force's harmonics stop at {harmonics} ({omega_max:.3g} rad/s), "
                           f"below the data's {top:.3g} rad/s")
    try:
        if oversample is not None:
            grid["oversample"] = oversample
        problem = PseudoSpectralProblem(plant, wave, pto=pto, params=params, **grid)
        result = problem.solve(force_max, stroke_max, "IPM")
    except Exception as exc:        # a solver failure is reported, not raised: # noqa: BLE001
        out["constrained_reason"] = f"pseudo-spectral solve failed: {exc}"
        return out
    out.update(constrained_omega_max_rad_s=float(problem.omega[-1]),
               constrained_components=int(problem.omega.size),
               constrained_solve_time_s=result.solve_time,
               constrained_points=int(problem.time.size),
               constrained_max_force_dense=result.max_force_dense,
               constrained_max_position_dense=result.max_position_dense,
               constrained_force_overshoot_pct=result.force_overshoot_pct,
               constrained_position_overshoot_pct=result.position_overshoot_pct)
    if not math.isfinite(result.mean_power):
        out["constrained_reason"] = f"no optimum under the limits (solver status {result.status})"
        return out
    # the dual's value: an upper bound on the QP whatever the solver's last digits
    certified = result.certified_power
    out["constrained_W"] = certified if math.isfinite(certified) else result.mean_power
    if sea and not whole_period:
        cc = conjugate or complex_conjugate_bound(plant, wave, pto, params)
        start = float(wave.ramp_time or 0.0)
        share = window_share(cc, start, period)
        out.update(window_s=[start, period], window_share=share)
        reasons.append(
            f"it is a mean over the whole {period:.4g} s repeat period, the metrics over the "
            f"window after the ramp and any controller warm-up: over t >= {start:.4g} s this "
            f"sea's complex-conjugate optimum absorbs {100 * share:.1f} % of its period mean")
    kind = "reference" if reasons else "bound"
    out["constrained_kind"] = kind
    out["constrained_kind_reason"] = (
        "; ".join(reasons) if reasons else
        f"a bound on the mean over whole periods (the metrics' window) of any periodic force "
        f"within the limits and the hydro data's band (to {problem.omega[-1]:.3g} rad/s), "
        f"linear theory")
    return out
