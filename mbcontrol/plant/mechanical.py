"""The plant's linear mechanics at rest, read off its exact Jacobians: what the frequency-domain
solution, the PTO ports and the device a radiation fit is judged by
(:func:`mbcontrol.plant.process.device_around`) are made of.

With M_tot = M + P A∞ Pᵀ, the linearised s' row is -M_tot⁻¹ (K q + B s) + radiation, so the
generalised stiffness K = -M_tot ds'/dq and damping B = -M_tot ds'/ds: hydrostatics and gravity
with their lever arms, PTO, friction (slope at rest) and moorings, exactly as the plant has them.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..multibody import Topology
from ..scene import DOF_NAMES
from .jacobians import jacobians


def dof_selector(topo: Topology, dofs: list[str]) -> np.ndarray:
    """Rows pick hydro DOFs out of the 6N body-twist vector."""
    select = np.zeros((len(dofs), 6 * len(topo.bodies)))
    for row, dof in enumerate(dofs):
        body, name = dof.split("__")
        select[row, 6 * topo.body_index(body) + DOF_NAMES.index(name)] = 1.0
    return select


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
