"""The energy audit of a run: no more mechanical energy than the waves and the PTOs put in.

A faithful solution of a passive plant cannot gain more energy than the work done on it; an
unstable step, or an unstable closed loop, gains it geometrically. `energy_audit` raises
SimulationError at the first sample past the margin, with the time, the step and a remedy.
"""
from __future__ import annotations

import numpy as np

from .. import defaults
from ..errors import SimulationError


# ENERGY_MARGIN, the default "sim.energy_margin": a run may not end up with more than twice the energy put in


def energy_budget(plant, t, Y):
    """(E - E_0, W_in) per sample (J): the mechanical energy gained, and the work the waves and
    the PTOs put in, W_in = int (P_exc + sum max(0, -P_pto)) dt (trapezoid), and MoorDyn's
    lines (their power into the bodies, either sign: the lines' energy is not in E).

    Radiation (passive, starting at rest), friction, drag and mooring damping only remove
    energy, so a faithful solution has E - E_0 <= W_in (up to its integration error).
    None when the plant has a catenary mooring (its energy is not in the plant's audit).
    """
    col = {name: i for i, name in enumerate(plant.outputs)}
    if "energy" not in col or any(m.kind == "catenary" for m in plant.scene.moorings):
        return None        # a catenary's elastic and gravity energy is not in the audit
    power_in = Y[:, col["excitation_power"]].copy()
    if "mooring_power" in col:          # MoorDyn's lines: they store and return energy
        power_in += Y[:, col["mooring_power"]]
    for pto in plant.scene.ptos:
        power_in += np.maximum(0.0, -Y[:, col[f"{pto.name}__power"]])
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power_in[1:] + power_in[:-1])
                                             * np.diff(t))])
    return Y[:, col["energy"]] - Y[0, col["energy"]], work


def energy_audit(plant, t, Y, method: str, dt: float, why=None) -> None:
    """Raise SimulationError at the first sample whose energy gain exceeds ENERGY_MARGIN times
    the work put in so far (plus a floor: 5 % of the record's input, half the initial
    energy), or whose outputs are not finite: the signature of an unstable step or of an
    unstable closed loop. why: the closed-loop diagnosis (sim.diagnose.explainer; None: the
    step is blamed); the error's `t_fail` attribute is the time, s.
    """
    bad = np.flatnonzero(~np.isfinite(Y).all(axis=1))
    budget = energy_budget(plant, t, Y)
    if budget is not None:
        gain, work = budget
        energy0 = abs(Y[0, plant.outputs.index("energy")])
        work_so_far = np.maximum.accumulate(np.maximum(work, 0.0))
        # the floor forgives what a faithful solution shows: kinematic O(q^3) mismatches
        # between loads and potentials early in the ramp (0.1 % of the record's work on
        # wavestar), a mooring table extrapolated beyond its envelope (not quite
        # conservative), integration error on a free decay. An unstable step grows energy
        # geometrically, by orders of magnitude, and outgrows the floor within a few steps.
        allowed = defaults.get("sim.energy_margin") * work_so_far + 0.05 * work_so_far[-1] + 0.5 * energy0 \
            + 1e-12
        with np.errstate(invalid="ignore"):
            bad = np.union1d(bad, np.flatnonzero(gain > allowed))
    if bad.size == 0:
        return
    i = int(bad[0])
    detail = "non-finite outputs" if not np.isfinite(Y[i]).all() else (
        f"mechanical energy grew by {gain[i]:.4g} J while the waves and PTOs had put in "
        f"{work[i]:.4g} J")
    head = (f"{plant.name}: simulation diverged at t = {t[i]:.4g} s (step {i}, dt = {dt} s, "
            f"method {method!r}): {detail}")
    cause = why(float(t[i])) if why is not None else None
    if cause:
        raise diverged(f"{head}: {cause}", float(t[i]))
    raise diverged(
        f"{head}. Remedy: a smaller dt (try {dt / 4:g} s), "
        f"method='exp-rk4' when fast radiation poles limit the step, method='cvodes' for "
        f"stiff loads (end stops, friction, latching), or `mbcontrol bench {plant.name} "
        f"--stability` for each method's largest stable step", float(t[i]))


def diverged(message: str, t_fail: float) -> SimulationError:
    """A SimulationError carrying the time of the divergence (s) as `t_fail`."""
    error = SimulationError(message)
    error.t_fail = t_fail
    return error
