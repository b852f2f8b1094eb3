"""Short-crested seas in a sweep: the wave a sea with a direction and a spread runs in, and the
expected power of a linear law there from the frequency-domain solution.

A spread sea's realisation gives each component one direction (waves.Spreading); its mean
power over a repeat period is the sum over those components. The expected power over all
realisations is the spreading-weighted integral over directions of the per-direction power
spectra (components in different directions have independent phases, so their powers add):
P = sum_i sum_k W_ik 1/2 c a_i^2 |V(omega_i, theta_k)|^2, with W_ik the share of
D(theta | omega_i) in direction theta_k's bin. The response V is linear in the excitation,
which is interpolated between the hydro data's headings by fixed weights (hydro.data.headings:
heading_matrix), so V is computed at the data's headings only and interpolated the same way:
exact, not a further approximation. Powers in W, angles in rad.
"""
from __future__ import annotations

import math

import numpy as np
from ... import defaults

# QUADRATURE_STEP, the default "sweep.direction_step": rad: direction bins of the expected power


def spread_sector(headings, spread: float) -> float:
    """Half-width (rad) of the directions a sea of spread sigma (rad) keeps about its mean:
    the whole circle (pi) where the hydro data's headings (rad) cover it, else 3 sigma (at
    most pi); the share of D cut off is recorded in the wave's settings."""
    from ...hydro import covers_circle
    from ...hydro import SECTOR_SIGMAS
    if covers_circle(headings):
        return math.pi
    return min(math.pi, SECTOR_SIGMAS * spread)


def sea_spreading(plant, sea, direction: float):
    """The waves.Spreading of a short-crested sea (sea.spread > 0) about `direction` (rad),
    or None for a long-crested one."""
    from ...waves import Spreading
    if not sea.spread_given:
        return None
    headings = plant.hydro.data["wave_direction"].values
    return Spreading(sea.spreading, direction, sea.spread, spread_sector(headings, sea.spread))


def spread_power(plant, wave, velocities, damping) -> float:
    """The expected mean power (W) of linear dampers `damping` (N s/m or N m s/rad, one per
    PTO) in the spread sea `wave` (a realisation's frequencies and amplitudes, its settings'
    spreading): velocities(direction) gives (n_omega, n_pto) velocities per unit amplitude
    for one direction (rad) per frequency."""
    from ...hydro import heading_matrix
    from ...waves import spreading_from_settings
    spreading = spreading_from_settings(wave.settings)
    omega = np.asarray(wave.omega, float)
    omega_p = 2 * math.pi / wave.settings["tp"]
    n = max(2, math.ceil(2 * spreading.sector / defaults.get("sweep.direction_step")))
    theta = spreading.mean - spreading.sector + (np.arange(n) + 0.5) * 2 * spreading.sector / n
    W = spreading.bin_weights(theta, omega, omega_p)                  # (n_omega, n)
    headings = plant.hydro.data["wave_direction"].values
    M = heading_matrix(headings, theta, plant.hydro.source)             # (n, n_headings)
    used = np.flatnonzero(np.any(M != 0, axis=0))
    at = np.stack([velocities(np.full(omega.size, float(headings[j]))) for j in used])
    a2 = np.asarray(wave.amplitude, float) ** 2
    c = np.asarray(damping, float)
    total = 0.0
    for k in range(n):
        V = np.einsum("h,hip->ip", M[k, used], at)                     # (n_omega, n_pto)
        total += float(np.sum(W[:, k, None] * 0.5 * c[None, :] * a2[:, None] * np.abs(V) ** 2))
    return total
