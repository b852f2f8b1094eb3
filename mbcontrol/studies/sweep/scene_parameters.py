"""The annual energy's parameter term from the scene's own `[[uncertainty]]` tables
(`mbcontrol.scene.uncertainty`): masses, drag coefficients and PTO efficiencies, none of them
a plant parameter, each with its standard uncertainty.

Per sea, each number's relative power sensitivity d ln P / d theta from linear theory (BEM
data, the sea's linear law; `spectral.expected_power`) by central differences, the plant
rebuilt with the number moved (the hydro data kept, no radiation fit: the frequency-domain
solution needs none; a rebuild costs ~20 ms):
- a body's mass moves its inertia (the static imbalance it leaves shifts rest, which linear
  theory's power does not see);
- a linear drag coefficient b moves the damping straight;
- a quadratic drag coefficient c (F = -c v|v|) enters by statistical linearisation (Borgman
  1967): b_eq = sqrt(8 / pi) sigma_v c for a Gaussian velocity of rms sigma_v, so
  d ln P / d c = sqrt(8 / pi) sigma_v d ln P / d b, sigma_v the DOF's rms velocity in the sea
  by linear theory (first order, at the model without the quadratic drag);
- a PTO's efficiency eta moves only the electrical power P_e = eta P+ - P- / eta (P+ and P-
  the time means of the absorbed and the returned parts, from each sea's mean power and mean
  |power|): d P_e / d eta = P+ + P- / eta^2, per sea, from the simulated records.
The relative sensitivities multiply the simulated power (as `spectral.parameter_gradient`).
Gradients in W per SI unit of each number.
"""
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from .spectral import STEP, expected_power

BORGMAN = math.sqrt(8.0 / math.pi)


def moved_plant(plant, item, value: float):
    """The plant with one scene number (an `Uncertain`, not an efficiency) set to `value`."""
    from ...plant import build_plant
    scene = plant.scene
    if item.kind == "mass":
        bodies = tuple(dataclasses.replace(b, mass=value) if b.name == item.owner else b
                       for b in scene.bodies)
        scene = dataclasses.replace(scene, bodies=bodies)
    else:                                       # a drag's linear coefficient on one DOF
        drags = tuple(dataclasses.replace(d, linear={**d.linear, item.dof: value})
                      if d.name == item.owner else d for d in scene.drags)
        scene = dataclasses.replace(scene, drags=drags)
    with warnings.catch_warnings():     # a moved mass leaves rest off balance: not a finding
        warnings.simplefilter("ignore")
        return build_plant(scene, plant.hydro, radiation=False)


def _rms_velocity(plant, wave, gains, params, item) -> float:
    """The drag's DOF's rms velocity in the sea (linear theory, BEM data; m/s or rad/s)."""
    from ...analysis import frequency_domain_response, law_params
    body = next(d.body for d in plant.scene.drags if d.name == item.owner)
    X = frequency_domain_response(plant, wave.omega, direction=wave.direction,
                                  params=law_params(plant, gains, params),
                                  outputs=[f"{body}__{item.dof}"])[:, 0]
    a = np.asarray(wave.amplitude, float)
    return float(np.sqrt(np.sum(0.5 * a ** 2 * np.abs(1j * wave.omega * X) ** 2)))


def _plants(plant, item, gains_scale: float):
    """(plants at theta + h and theta - h, h) for a mass or a drag coefficient."""
    if item.kind == "mass":
        x = item.nominal
        h = STEP * abs(x)
    else:           # a drag coefficient may be 0: step on the law's damping scale
        x = item.nominal if item.kind == "drag_linear" else _linear_nominal(plant, item)
        h = STEP * max(abs(x), gains_scale)
    return (moved_plant(plant, item, x + h), moved_plant(plant, item, x - h)), h


def _linear_nominal(plant, item) -> float:
    drag = next(d for d in plant.scene.drags if d.name == item.owner)
    return float(drag.linear.get(item.dof, 0.0))


def relative_gradients(plant, waves, laws, items, *, params, skip) -> np.ndarray:
    """(n_sea, n_item): d ln P / d theta per sea (1 / SI unit) of the absorbed power by linear
    theory; efficiencies 0 (they do not move it); rows of `skip` seas (capped, idle) 0."""
    out = np.zeros((len(waves), len(items)))
    scale = max((abs(c) for g in laws if g for c, _ in g.values()), default=1.0) or 1.0
    for j, item in enumerate(items):
        if item.kind == "efficiency":
            continue
        (up, down), h = _plants(plant, item, scale)
        for k, (wave, gains) in enumerate(zip(waves, laws)):
            if skip[k]:
                continue
            base = expected_power(plant, wave, gains, params=params)
            if base == 0.0:
                continue
            slope = (expected_power(up, wave, gains, params=params)
                     - expected_power(down, wave, gains, params=params)) / (2 * h) / base
            if item.kind == "drag_quadratic":
                slope *= BORGMAN * _rms_velocity(plant, wave, gains, params, item)
            out[k, j] = slope
    return out


def efficiency_gradients(items, mean_W, mean_abs_W, eta) -> np.ndarray:
    """(n_sea, n_item): d P_e / d eta (W per unit) of each efficiency item from each sea's
    per-PTO mean power and mean |power| (dicts pto -> (n_sea,) arrays, W) and the PTO's
    efficiency eta; other items 0."""
    n = len(next(iter(mean_W.values()))) if mean_W else 0
    out = np.zeros((n, len(items)))
    for j, item in enumerate(items):
        if item.kind != "efficiency":
            continue
        p, a = np.asarray(mean_W[item.owner], float), np.asarray(mean_abs_W[item.owner], float)
        plus, minus = 0.5 * (a + p), 0.5 * (a - p)     # absorbed and returned, time means
        out[:, j] = np.nan_to_num(plus + minus / eta[item.owner] ** 2)
    return out
