"""Electrical power bounds of a PTO with a drivetrain (scene [pto.drivetrain]).

The winding loss of a machine whose current is I = F / (gear kt') is R F^2 / (gear kt')^2: in
the pseudo-spectral problem (analysis.bounds.PseudoSpectralProblem) it is one more term of the
same diagonal quadratic, so the electrical optimum under force and stroke limits is the same
convex QP with a heavier diagonal. Without limits it equals the closed form of
controllers.impedance.electrical_optimum (tests/features/controllers/test_electrical.py checks both).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .bounds import PseudoSpectralBound, PseudoSpectralProblem, _pto_name


@dataclass
class ElectricalBound:
    electrical_W: float          # mean electrical power delivered at the optimum, W
    mechanical_W: float          # the mean absorbed (machine) power there, W
    winding_loss_W: float        # the mean winding loss there, W
    mechanical: PseudoSpectralBound   # the optimum's force, velocity, position, status ...


def winding_coefficient(plant, pto: str) -> float | None:
    """R / (gear kt')^2, W per N^2 (or per (N m)^2) of PTO force: the mean winding loss is
    this times the mean square force. None for a PTO without a drivetrain."""
    drive = next(p for p in plant.scene.ptos if p.name == pto).drivetrain
    return None if drive is None else drive.winding_resistance / drive.force_per_current ** 2


def electrical_bound(plant, wave, *, pto: str | None = None, force_max: float = np.inf,
                     stroke_max: float = np.inf, params=None, omega_max: float | None = None,
                     force_on: str | None = None, solver: str = "CLARABEL",
                     **solver_options) -> ElectricalBound:
    """The most mean electrical power (W) a PTO with a drivetrain can deliver in a periodic
    `wave` with |F| <= force_max and |x| <= stroke_max, non-causal (the force's Fourier
    coefficients optimised as pseudo_spectral_bound does; omega_max: let the force hold every
    multiple of 2 pi / T up to it, as WecOptTool's frequency grid does).

    force_on: which force force_max limits (None: the scene PTO's force_max_on): "machine"
    (the PTO force, the machine's), or "hull" ("wec" too: what the whole drivetrain puts on
    the joint, the machine's force less the reflected inertia, friction and shaft-spring
    forces gear^2 (J a + b v + K x): WecOptTool's PTO force; the result's force series and
    max_force are then that force)."""
    name = _pto_name(plant, pto)
    winding = winding_coefficient(plant, name)
    if winding is None:
        raise InputError(f"PTO {name!r} has no [pto.drivetrain]: no electrical bound")
    problem = PseudoSpectralProblem(plant, wave, pto=name, params=params, omega_max=omega_max,
                                    force_on=force_on)
    problem.rho = problem.rho + winding          # mean loss winding x sum(c_k^2 + s_k^2) / 2
    result = problem.solve(force_max, stroke_max, solver, **solver_options)
    loss = float(winding * 0.5 * np.sum(np.abs(result.force_coefficients) ** 2))
    return ElectricalBound(result.mean_power - loss, result.mean_power, loss, result)

