"""The plant's linear mechanics at rest, read off its exact Jacobians, and the device a
radiation fit is judged by (:mod:`mbcontrol.hydro.response_error`).

With M_tot = M + P A∞ Pᵀ, the linearised s' row is -M_tot⁻¹ (K q + B s) + radiation, so the
generalised stiffness K = -M_tot ds'/dq and damping B = -M_tot ds'/ds: hydrostatics and gravity
with their lever arms, PTO, friction (slope at rest) and moorings, exactly as the plant has them.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..hydro import HydroModel, RadiationModel
from ..hydro.response_error import Device
from .jacobians import jacobians
from .process import assemble_plant, dof_selector


@dataclass(frozen=True)
class MechanicalMatrices:
    """Linear generalised matrices at rest (n_s x n_s), and P0 restricted to hydro DOFs."""
    mass: np.ndarray           # P0 M_RB P0^T
    added_mass_inf: np.ndarray  # P0 A_inf P0^T
    stiffness: np.ndarray      # hydrostatic + PTO + mooring stiffness
    damping: np.ndarray        # PTO + friction (slope at rest) + mooring damping
    P_hydro: np.ndarray        # (n_s, n_h): generalised force of a body-DOF wrench
    output_q: np.ndarray       # (n_y, n_q): output sensitivity to q
    output_s: np.ndarray       # (n_y, n_s): output sensitivity to s


def mechanical_matrices(plant, params=None) -> MechanicalMatrices:
    """Read the non-radiation linear terms off the plant's exact Jacobians at rest.

    With M_tot = M + A_inf, the linearised s' row is -M_tot^{-1} (K q + B s) + radiation, so
    K = -M_tot ds'/dq and B = -M_tot ds'/ds (the fitted radiation enters through chi, and its
    feed-through D_r is removed).
    """
    p = plant.params(**params) if isinstance(params, dict) else (
        plant.p0 if params is None else np.asarray(params, float))
    tree, n = plant.topology.tree, plant.topology.tree.n_s
    q = ca.SX.sym("q", tree.n_q)
    P0 = np.asarray(ca.Function("P", [q], [tree.P(q)])(np.zeros(tree.n_q)))
    select = dof_selector(plant.topology, list(plant.hydro.dofs)) if plant.hydro else \
        np.zeros((0, P0.shape[1]))
    P_h = P0 @ select.T
    M = np.asarray(ca.Function("M", [q], [tree.mass_matrix(q)])(np.zeros(tree.n_q)))
    A_inf = P_h @ plant.hydro.added_mass_inf @ P_h.T if plant.hydro else np.zeros_like(M)
    x0 = plant.x0()
    A, _, _, C, _, _ = (np.asarray(J) for J in jacobians(plant)(
        x0, np.zeros(len(plant.inputs)), np.zeros(len(plant.disturbances)), p))
    rows = slice(tree.n_q, tree.n_q + n)
    K = -(M + A_inf) @ A[rows, :tree.n_q]
    B = -(M + A_inf) @ A[rows, tree.n_q:tree.n_q + n]
    if plant.hydro:
        B -= P_h @ plant.hydro.radiation_matrices()[3] @ P_h.T
    return MechanicalMatrices(M, A_inf, K, B, P_h, C[:, :tree.n_q],
                              C[:, tree.n_q:tree.n_q + n])


def linear_params(plant, ptos, params=None) -> dict:
    """Parameter overrides for linear theory seen from `ptos`: their own damping and
    stiffness zero (the decision force is the PTO's whole force), Coulomb friction removed
    (its smoothed slope at rest is not linear physics); `params` (dict or full vector) kept
    for everything else."""
    if params is not None and not isinstance(params, dict):
        params = dict(zip(plant.parameters, np.asarray(params, float)))
    out = dict(params or {})
    for friction in plant.scene.frictions:
        out[f"{friction.name}__coulomb"] = 0.0
    for name in ptos:
        out[f"{name}__damping"] = 0.0
        out[f"{name}__stiffness"] = 0.0
    return out


def device_around(scene, source: str, data, dofs) -> Device:
    """The device a radiation fit of ``data`` on ``dofs`` sits in: the scene's plant without
    radiation states, linear at rest, seen from its PTOs (their own damping and stiffness zero,
    Coulomb friction removed: `linear_params`), with its joints' stiffness and its drivetrains,
    and the data's excitation at every heading."""
    n = len(dofs)
    none = RadiationModel(A=np.zeros((0, 0)), B=np.zeros((0, n)), C=np.zeros((n, 0)), D=np.zeros((n, n)),
                          dofs=tuple(dofs), order=0, fit_error=0.0, entry_errors=np.zeros((n, n)))
    plant = assemble_plant(scene, HydroModel(tuple(dofs), data, none, source), radiation=False)
    mech = mechanical_matrices(plant, linear_params(plant, [pto.name for pto in scene.ptos]))
    excitation = data["excitation_force"].sel(influenced_dof=list(dofs)).transpose(
        "wave_direction", "omega", "influenced_dof").values
    return Device(tuple(plant.topology.tree.coordinate_names), tuple(dofs), mech.mass + mech.added_mass_inf,
                  mech.damping, mech.stiffness, mech.P_hydro, excitation, data["omega"].values,
                  data["wave_direction"].values, scene.hydro.response_band)
