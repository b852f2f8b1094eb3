"""The Controller protocol: everything `simulate` and the exporters may use of a PTO controller,
declared here, where the simulator that calls it lives (mbcontrol.controllers implements it).

A controller is bound to a plant by `reset(plant)` (it looks up the signals it measures by
name), then called as `controller(t, y) -> u` every `period` seconds with the plant's output
vector y; u (one force or torque per PTO, N or N m) is held until the next call (zero-order
hold). In closed loop u is the PTO's whole force: the scene's PTO law is set aside. A
controller whose law is a static CasADi expression of y may also return it from
`casadi_law(plant)`; with period equal to the simulation step it then runs inside compiled
code.

Optional members (a controller without one behaves as its entry in OPTIONAL says), read only
through the functions below:
- `uses_state = True`: called as `controller(t, y, x)` with the plant's whole state x as
  well: full-state feedback, an oracle for studies (no real device measures radiation
  states), which its describe() must say;
- `estimation_report(t, W) -> dict`: an estimator's accuracy against the true excitation W,
  kept in the run record;
- `casadi_law_parametric(plant) -> (law(y, theta), theta)`: the law with its gains as
  parameters, so one compiled function serves every gain;
- `kind` ("linear", "switching", "predictive"; controllers.law), `exportable` (bool) and
  `export_refusal` (why not, a sentence): what the exporters learn of a registered law.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Controller(Protocol):
    name: str
    period: float | None   # s, zero-order-hold period; None: every simulation step

    def reset(self, plant) -> None: ...

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray: ...

    def casadi_law(self, plant): ...

    def describe(self) -> dict: ...


# the optional members and what their absence means
OPTIONAL = {"uses_state": False, "estimation_report": None, "casadi_law_parametric": None,
            "kind": None, "exportable": False, "export_refusal": None}


def name_of(controller) -> str:
    """The controller's name, or its class's."""
    return getattr(controller, "name", None) or type(controller).__name__


def period_of(controller) -> float | None:
    """The controller's hold period (s), None for every simulation step (or no controller)."""
    return getattr(controller, "period", None) if controller is not None else None


def uses_state(controller) -> bool:
    """Does the controller read the plant's whole state (an oracle)?"""
    return bool(getattr(controller, "uses_state", OPTIONAL["uses_state"]))


def estimation_report(controller):
    """The controller's estimation_report method, or None."""
    return getattr(controller, "estimation_report", OPTIONAL["estimation_report"])


def parametric_law(controller):
    """The controller's casadi_law_parametric method, or None."""
    return getattr(controller, "casadi_law_parametric", OPTIONAL["casadi_law_parametric"])


def law_kind(controller) -> str | None:
    """The registered law's kind ("linear", "switching", "predictive"), None if it has none."""
    return getattr(controller, "kind", OPTIONAL["kind"])


def exportable(controller) -> bool:
    """Does the law say it can be exported as C?"""
    return bool(getattr(controller, "exportable", OPTIONAL["exportable"]))


def export_refusal(controller) -> str | None:
    """Why the law cannot be exported, in its own words (None: it does not say)."""
    return getattr(controller, "export_refusal", OPTIONAL["export_refusal"])
