"""The control-plant model a model-based controller (MPC, Kalman filter) predicts with.

The process plant is linearised about rest with the controller owning the PTO force (the
scene's PTO damping and stiffness zeroed, Coulomb friction left out), optionally reduced by
balanced truncation, and discretised with a zero-order hold at the controller's period.

The wave excitation w (one force per hydro DOF) reaches the linear model only through
B_w, whose rank is at most the number of generalised coordinates (forces on the bodies act
through the joints). It is therefore carried as a generalised disturbance d = S w of rank r
(B_w = B_d S, from the SVD of B_w): a one-DOF device has one, however many hydro DOFs its
floats have. The Kalman filter estimates d, and the forecasts are made in d.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mbcontrol.errors import ControllerError
from mbcontrol.lti import frequency_response, zoh
from mbcontrol.plant import controlled_params

from .base import signal_indices


@dataclass
class ControlPlant:
    """Discrete linear model z+ = Ad z + Bu u + Bd d, with z the (reduced) state deviation.

    Units: u in N or N m per PTO, d in the units of S w (N-like), dt in s. Rows: `Cp`, `Cv`
    the PTOs' positions and velocities; `Cm` the measured outputs (deviations from rest).
    `S` maps the plant's excitation w to d; `T` maps the plant's state to z (identity without
    reduction); `A`, `Bu_c`, `Bd_c` are the continuous-time matrices (for the Kalman filter's
    augmented wave model).
    """
    dt: float
    A: np.ndarray
    Bu_c: np.ndarray
    Bd_c: np.ndarray
    Ad: np.ndarray
    Bu: np.ndarray
    Bd: np.ndarray
    Cp: np.ndarray
    Cv: np.ndarray
    Cm: np.ndarray
    S: np.ndarray
    T: np.ndarray
    ptos: list
    measured: list
    y_rest: np.ndarray            # measured outputs at rest
    y_index: list                 # indices of the measured outputs in plant.outputs
    Ce: np.ndarray | None = None  # rows of `extra_outputs` (deviations from rest), or None

    @property
    def nz(self) -> int:
        return self.Ad.shape[0]

    @property
    def nd(self) -> int:
        return self.Bd.shape[1]


def controller_params(plant, params=None) -> dict:
    """The plant as a controller sees it (mbcontrol.plant.ownership): every PTO's scene law
    off unless `params` sets it (the controller owns the force), no Coulomb friction (a
    linear model cannot hold it)."""
    return controlled_params(plant, params, linear=True)


def default_measurements(plant) -> list[str]:
    """Every joint coordinate and its rate: what encoders on the joints give."""
    coords = list(plant.topology.tree.coordinate_names)
    return coords + [f"{c}__vel" for c in coords]


def build_control_plant(plant, dt: float, *, ptos=None, measured=None, order=None,
                        params=None, extra_outputs=None) -> ControlPlant:
    """Linearise, reduce (order: states kept, None = all) and discretise `plant` at dt s.
    extra_outputs: plant outputs the controller predicts besides the PTOs' (rows `Ce`, e.g.
    a body's heave for its envelope); they may not depend directly on the inputs."""
    from mbcontrol.analysis import balanced_truncation, linearize

    ptos = list(ptos or [p.name for p in plant.scene.ptos])
    measured = list(measured or default_measurements(plant))
    signal_indices(plant, measured)
    base = controller_params(plant, params)
    extra = list(extra_outputs or [])
    outputs = ([f"{n}__position" for n in ptos] + [f"{n}__velocity" for n in ptos] + measured
               + extra)
    sys = linearize(plant, params=base, inputs=[f"u__{n}" for n in ptos] + list(plant.disturbances),
                    outputs=outputs)
    nu, k = len(ptos), len(ptos)
    T = np.eye(plant.nx)
    if order is not None and order < plant.nx:
        red = balanced_truncation(sys, order)
        sys, T = red.system, red.T
    A, B, C = (np.asarray(M, float) for M in (sys.A, sys.B, sys.C))
    if extra and np.any(np.asarray(sys.D)[-len(extra):] != 0):
        raise ControllerError(f"{plant.name}: outputs {extra} depend directly on the inputs; the "
                              f"control plant predicts only outputs of its state")
    Ce = C[C.shape[0] - len(extra):] if extra else None
    C = C[:C.shape[0] - len(extra)]
    if np.any(np.asarray(sys.D)[:, :nu] != 0):
        raise ControllerError(f"{plant.name}: the PTO force feeds through to a position or velocity; "
                              f"the control-plant model expects a strictly proper plant")
    Bu_c, Bw = B[:, :nu], B[:, nu:]
    Bd_c, S = _disturbance_basis(Bw)
    Ad, Bud = zoh(A, np.hstack([Bu_c, Bd_c]), dt)
    x_rest = plant.x0()
    y_rest = np.asarray(plant.h(x_rest, np.zeros(len(plant.inputs)),
                                np.zeros(len(plant.disturbances)), plant.params(**base))).ravel()
    y_index = signal_indices(plant, measured)
    return ControlPlant(dt=dt, A=A, Bu_c=Bu_c, Bd_c=Bd_c, Ad=Ad, Bu=Bud[:, :nu],
                        Bd=Bud[:, nu:], Cp=C[:k], Cv=C[k:2 * k], Cm=C[2 * k:], S=S, T=T,
                        ptos=ptos, measured=measured, y_rest=y_rest[y_index], y_index=y_index,
                        Ce=Ce)


def _disturbance_basis(Bw: np.ndarray, rtol: float = 1e-9):
    """(B_d, S) with B_w = B_d S and B_d of full column rank r."""
    if Bw.shape[1] == 0:
        return np.zeros((Bw.shape[0], 0)), np.zeros((0, 0))
    U, s, Vt = np.linalg.svd(Bw, full_matrices=False)
    r = int(np.sum(s > rtol * s[0])) if s.size and s[0] > 0 else 0
    return U[:, :r], s[:r, None] * Vt[:r]


def pto_admittance(cp, omega) -> np.ndarray:
    """|force -> velocity| of each PTO at omega (rad/s): (n_omega, n_pto), m/s per N (or
    rad/s per N m), from the control plant's continuous model."""
    G = frequency_response(cp.A, cp.Bu_c, cp.Cv, None, omega)
    return np.abs(np.diagonal(G, axis1=0, axis2=1))


def pto_impedance(cp, omega: float) -> np.ndarray:
    """|Z_i| per PTO at omega (rad/s): 1 / |force -> velocity| (N s/m or N m s/rad)."""
    return 1.0 / pto_admittance(cp, omega)[0]


def device_frequency(cp, band: tuple[float, float], n: int = 400) -> float:
    """The device's own resonance as its PTOs see it (rad/s): where the force-to-velocity
    response peaks within `band` (the hydro data's frequencies), the largest over the PTOs.
    Not the least-damped pole of A: on five of six catalogue models that is a pole of the
    radiation fit (sphere 8.40 rad/s against its heave resonance 1.44)."""
    omega = np.geomspace(max(band[0], 1e-3), band[1], n)
    response = pto_admittance(cp, omega).max(axis=1)
    return float(omega[int(np.argmax(response))])


def hydro_band(plant) -> tuple[float, float]:
    """The frequencies the device's hydro data cover (rad/s); 0.1-10 rad/s without data."""
    if plant.hydro is None:
        return (0.1, 10.0)
    return (float(plant.hydro.omega[0]), float(plant.hydro.omega[-1]))
