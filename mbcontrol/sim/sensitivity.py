"""Exact parameter sensitivities of a plant's outputs, through the compiled integrator.

`sensitivity_plant(plant, names, outputs)` is the plant augmented with the forward
sensitivity equations S' = (df/dx) S + df/dp, S = dx/dp (nx by len(names), S(0) = 0, as the
rest state does not depend on p), and outputs dy/dp = (dh/dx) S + dh/dp, all from CasADi's
exact Jacobians. Stepped by the same explicit Runge-Kutta method, the augmented system gives
the exact derivative of the discrete simulation (for explicit RK methods, integrating the
variational equations with the same tableau equals differentiating the steps), so Gauss-Newton
sees the gradient of what it fits, not of a finite-difference guess. It runs through
`simulate_batch` like any plant: one compiled library, all runs of a group in one call.
"""
from __future__ import annotations

import dataclasses

import casadi as ca

from ..errors import UnknownName


def sensitivity_name(output: str, parameter: str) -> str:
    """The output name of d(output)/d(parameter)."""
    return f"d_{output}__d_{parameter}"


def sensitivity_plant(plant, names, outputs):
    """`plant` with states [x, vec(dx/dp)] and outputs [y, d(outputs)/d(names)].

    names: parameters of the plant to differentiate by; outputs: the plant outputs whose
    derivatives are wanted, named `sensitivity_name(output, parameter)`.
    """
    unknown = [n for n in names if n not in plant.parameters]
    missing = [o for o in outputs if o not in plant.outputs]
    if unknown or missing:
        raise UnknownName(f"{plant.name}: sensitivities of {missing or outputs} by {unknown or names}: "
                          f"{'unknown parameter(s) ' + str(unknown) if unknown else ''}"
                          f"{' unknown output(s) ' + str(missing) if missing else ''}")
    n_par = len(names)
    x, S = ca.SX.sym("x", plant.nx), ca.SX.sym("S", plant.nx, n_par)
    u, w = ca.SX.sym("u", len(plant.inputs)), ca.SX.sym("w", len(plant.disturbances))
    p = ca.SX.sym("p", len(plant.p0))
    select = ca.DM.zeros(len(plant.p0), n_par)          # p -> the differentiated parameters
    for j, name in enumerate(names):
        select[plant.parameters.index(name), j] = 1.0
    f, h = plant.f(x, u, w, p), plant.h(x, u, w, p)
    S_dot = ca.mtimes(ca.jacobian(f, x), S) + ca.mtimes(ca.jacobian(f, p), select)
    chosen = ca.vertcat(*[h[plant.outputs.index(o)] for o in outputs])
    dy = ca.mtimes(ca.jacobian(chosen, x), S) + ca.mtimes(ca.jacobian(chosen, p), select)
    xa = ca.vertcat(x, ca.vec(S))
    f_aug = ca.Function("f", [xa, u, w, p], [ca.vertcat(f, ca.vec(S_dot))],
                        ["x", "u", "w", "p"], ["xdot"])
    h_aug = ca.Function("h", [xa, u, w, p], [ca.vertcat(h, ca.vec(dy))],
                        ["x", "u", "w", "p"], ["y"])
    # ca.vec stacks columns: parameter-major, as the names below
    states = plant.states + tuple(f"d_{s}__d_{n}" for n in names for s in plant.states)
    outs = plant.outputs + tuple(sensitivity_name(o, n) for n in names for o in outputs)
    notes = {**plant.notes, "sensitivities": {"parameters": list(names), "outputs": list(outputs)}}
    return dataclasses.replace(plant, states=states, outputs=outs, f=f_aug, h=h_aug, notes=notes,
                               parts=None, held=None)
