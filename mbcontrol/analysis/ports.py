"""The device seen from its PTOs: multiport frequency responses and the multiport
complex-conjugate bound.

Phasors of exp(-i omega t), as `analysis.bounds` (the bound stack's documented exception to
the public exp(+i omega t); `lti.phasor` converts). With every PTO's own damping and stiffness
set to zero (so the PTO forces F are the whole forces the PTOs apply) and Coulomb friction
removed, the PTO velocities are

    V = Y F + H A,

Y (n_pto x n_pto) the admittance from PTO forces to PTO velocities, H (n_pto) the velocities
per unit wave amplitude with the PTOs free, A the complex wave amplitude. The mean power the
PTOs absorb, P = -1/2 Re F^H V, is largest at F = -1/2 Y_h^-1 H A with Y_h = (Y + Y^H) / 2, and
then P = 1/8 (H A)^H Y_h^-1 (H A) (Falnes' optimum for several oscillators; for one PTO it is
|F_e A|^2 / (8 Re Z_i)). No set of PTO forces, causal or not, absorbs more in linear theory.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..plant import linear_params  # noqa: F401 (its public home here too)
from ..errors import InputError


def port_responses(plant, omega, ptos, direction: float = 0.0, params=None):
    """(Y, H): admittance (n_omega, n_pto, n_pto) from PTO forces to PTO velocities (m/s per
    N, or rad/s per N m) and free velocities per unit wave amplitude (n_omega, n_pto) (m/s
    per m), straight from the BEM data at `omega` (rad/s). params: overrides as
    `linear_params`; the PTOs named in `ptos` are freed."""
    return output_responses(plant, omega, ptos, [f"{name}__velocity" for name in ptos],
                            direction, params)


def output_responses(plant, omega, ptos, outputs, direction: float = 0.0, params=None):
    """(G, H) for any plant outputs: G (n_omega, n_out, n_pto) per unit PTO force and H
    (n_omega, n_out) per unit wave amplitude with the PTOs free (exp(-i omega t), straight
    from the BEM data), so that with PTO forces F the outputs are G F + H A. params:
    overrides as `linear_params`; the PTOs named in `ptos` are freed."""
    from ..lti import frequency_chunks
    from .frequency import mechanical_matrices
    from .linearize import jacobians

    if plant.hydro is None:
        raise InputError(f"{plant.name}: no hydrodynamic data, so no wave excitation")
    omega = np.atleast_1d(np.asarray(omega, float))
    if np.any(omega <= 0):
        raise InputError("output_responses: frequencies must be > 0 rad/s")
    p = plant.params(**linear_params(plant, ptos, params))
    mech = mechanical_matrices(plant, p)
    n_q, n_s = plant.n_q, plant.topology.tree.n_s
    _, Bu, _, _, Du, _ = (np.asarray(J) for J in jacobians(plant)(
        plant.x0(), np.zeros(len(plant.inputs)), np.zeros(len(plant.disturbances)), p))
    i_u = [plant.inputs.index(f"u__{name}") for name in ptos]
    i_y = [plant.outputs.index(name) for name in outputs]
    if np.any(Du[np.ix_(i_y, i_u)] != 0):
        raise InputError(f"{plant.name}: an output of {outputs} depends directly on a PTO "
                         f"force")
    # generalised force of unit PTO forces: s' = M_tot^-1 (... + b u), so b = M_tot ds'/du
    b = (mech.mass + mech.added_mass_inf) @ Bu[n_q:n_q + n_s][:, i_u]
    c_q, c_s = mech.output_q[i_y], mech.output_s[i_y]
    hyd, P = plant.hydro, mech.P_hydro
    A_w, B_w = hyd.frequency_domain_matrices(omega)
    F_exc = hyd.excitation_at(omega, direction)
    n = len(ptos)
    Y = np.empty((omega.size, len(i_y), n + 1), complex)
    rhs = np.concatenate([np.broadcast_to(b, (omega.size,) + b.shape),
                          (F_exc @ P.T)[..., None]], axis=2)
    for k in frequency_chunks(omega.size, mech.mass.shape[0]):   # stacked solves
        w = omega[k, None, None]
        Z = (-w**2 * (mech.mass + P @ A_w[k] @ P.T) - 1j * w * (mech.damping + P @ B_w[k] @ P.T)
             + mech.stiffness)
        X = np.linalg.solve(Z, rhs[k])
        Y[k] = c_q @ X + c_s @ (-1j * w * X)    # the outputs' phasors
    return Y[..., :n], Y[..., n]


@dataclass(frozen=True)
class MultiportBound:
    """The multiport complex-conjugate optimum of a wave: power (W, the spectral mean),
    power_by_component (W), and the optimal PTO forces and velocities per component
    (n_omega, n_pto; N or N m, m/s or rad/s) for windowed means (`window_mean_power`)."""
    power: float
    power_by_component: np.ndarray
    omega: np.ndarray
    force: np.ndarray
    velocity: np.ndarray
    ptos: tuple


def multiport_bound(plant, wave, params=None, responses=None) -> MultiportBound:
    """1/8 sum_k (H_k A_k)^H Y_h,k^-1 (H_k A_k) over the wave's components, every PTO free
    (W). responses: (Y, H) at wave.omega when already computed. A PTO that sees no
    dissipation at a frequency (Y_h singular there) makes the bound unbounded: inf."""
    ptos = tuple(p.name for p in plant.scene.ptos)
    Y, H = responses if responses is not None else port_responses(
        plant, wave.omega, ptos, wave.direction, params)
    A = np.asarray(wave.amplitude, float) * np.exp(-1j * np.asarray(wave.phase, float))
    h = H * A[:, None]                                       # (n_omega, n_pto)
    Yh = 0.5 * (Y + np.conj(np.swapaxes(Y, 1, 2)))
    eig = np.linalg.eigvalsh(Yh)                             # (n_omega, n_pto), ascending
    singular = eig[:, 0] <= 1e-12 * np.maximum(eig[:, -1], 1e-300)
    excited = np.any(h != 0, axis=1)
    force = np.zeros_like(h)
    per = np.where(singular & excited, np.inf, 0.0)
    ok = ~singular & excited
    if ok.any():
        solved = np.linalg.solve(Yh[ok], h[ok][..., None])[..., 0]
        force[ok] = -0.5 * solved
        per[ok] = 0.125 * np.real(np.sum(np.conj(h[ok]) * solved, axis=1))
    velocity = np.einsum("kij,kj->ki", Y, force) + h
    return MultiportBound(float(per.sum()), per, np.asarray(wave.omega, float), force,
                          velocity, ptos)


def undamped_note(wave, undamped, pto: str) -> str:
    """What makes a bound infinite, in words: the components of `wave` flagged in `undamped`
    (bool, per component) excite PTO `pto` where the hydro data give it no radiation damping
    (the rule of `multiport_bound`), with their band and share of the wave's variance."""
    omega = np.atleast_1d(np.asarray(wave.omega, float))
    power = np.asarray(wave.amplitude, float) ** 2 * np.ones(omega.size)
    undamped = np.asarray(undamped, bool)
    share = float(power[undamped].sum() / power.sum()) if power.sum() > 0 else 0.0
    return (f"the complex-conjugate bound of this wave is unbounded: {int(undamped.sum())} of "
            f"its {omega.size} components ({omega[undamped].min():.4g}.."
            f"{omega[undamped].max():.4g} rad/s, {share:.2g} of its variance) excite PTO "
            f"{pto!r} where the hydro data give it no radiation damping (BEM data repaired to "
            f"zero, or past the mesh's range); cut the wave's band, or extend the data")


def window_mean_power(bound: MultiportBound, start: float, end: float) -> float:
    """The optimal forces' mean absorbed power over [start, end] s of this realisation (W),
    exactly: the cross terms between components that a finite record does not average out,
    mean over the window of Re[F_j e^-iw_j t] Re[V_k e^-iw_k t] summed in closed form."""
    w, F, V = bound.omega, bound.force, bound.velocity
    if not np.all(np.isfinite(bound.power_by_component)):
        return np.inf
    T = end - start

    def mean_phasor(Omega):                     # mean of exp(-i Omega t) over the window
        out = np.ones_like(Omega, dtype=complex)
        nz = np.abs(Omega) * T > 1e-9
        Om = Omega[nz]
        out[nz] = (np.exp(-1j * Om * end) - np.exp(-1j * Om * start)) / (-1j * Om * T)
        return out

    FV_diff = F @ np.conj(V).T                  # sum over PTOs of F_j conj(V_k)
    FV_sum = F @ V.T                            # sum over PTOs of F_j V_k
    diff = mean_phasor(w[:, None] - w[None, :])
    total = mean_phasor(w[:, None] + w[None, :])
    product = 0.5 * np.real(FV_diff * diff) + 0.5 * np.real(FV_sum * total)
    return float(-product.sum())
