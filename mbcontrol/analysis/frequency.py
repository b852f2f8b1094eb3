"""Frequency-domain analysis: the BEM-direct solution, RAOs and state-space responses.

Convention: phasors of exp(+i omega t), the toolbox's public one (python-control's; see
mbcontrol.lti): x(t) = Re[X e^{+i omega t}]. The BEM excitation, stored per exp(-i omega t), is
converted at the hydro boundary (`HydroModel.excitation_phasor`).

The frequency-domain (FD) solution uses the BEM data at each frequency directly, with no
radiation fit: [-omega^2 (M + A(omega)) + i omega (B(omega) + B_mech) + K] X = F. It is the
reference the time-domain simulation and the fitted state-space model are checked against.
"""
from __future__ import annotations

import numpy as np

from ..lti import frequency_chunks, frequency_response, phasor, state_response
from ..plant import MechanicalMatrices, mechanical_matrices  # noqa: F401 (their public home here too)
from ..errors import InputError


def frequency_domain_response(plant, omega, *, direction: float = 0.0, params=None,
                              outputs=None) -> np.ndarray:
    """Complex response per unit wave amplitude (n_omega, n_outputs), exp(+i omega t).

    Straight from the BEM data (no radiation fit): A(omega), B(omega) and the excitation are
    interpolated linearly on the BEM grid. direction (rad): one, or one per omega (a spread
    sea's components; `HydroModel.excitation_at`). outputs: names (default all plant outputs).
    """
    omega = np.atleast_1d(np.asarray(omega, float))
    mech = mechanical_matrices(plant, params)
    hyd = plant.hydro
    A_w, B_w = hyd.frequency_domain_matrices(omega)
    F = hyd.excitation_phasor(omega, direction)
    idx = [plant.outputs.index(o) for o in (outputs or plant.outputs)]
    rhs = (F @ mech.P_hydro.T)[..., None]
    X = np.concatenate([np.linalg.solve(_impedance(mech, omega[k], A_w[k], B_w[k]), rhs[k])
                        for k in frequency_chunks(omega.size, mech.mass.shape[0])])[..., 0]
    return _outputs(mech, omega, X, idx)


def _impedance(mech, omega, A_w, B_w) -> np.ndarray:
    """Z(omega) = -omega^2 (M + P A P^T) + i omega (B_mech + P B P^T) + K, (n_omega, n, n),
    to be solved as a stack (a Python loop of small solves cost a sweep's uncertainty budget
    8 s over 92 seas)."""
    P = mech.P_hydro
    w = omega[:, None, None]
    return (-w**2 * (mech.mass + P @ A_w @ P.T) + 1j * w * (mech.damping + P @ B_w @ P.T)
            + mech.stiffness)


def _outputs(mech, omega, X, idx) -> np.ndarray:
    """The outputs `idx` of the joint responses X (n_omega, n_q[, k]) at each omega."""
    iw = 1j * omega.reshape((-1,) + (1,) * (X.ndim - 1))
    return (np.einsum("oq,wq...->wo...", mech.output_q, X)
            + np.einsum("oq,wq...->wo...", mech.output_s, iw * X))[:, idx]


def excitation_transfer(plant, omega, *, params=None, outputs=None, sys=None) -> np.ndarray:
    """(n_outputs, n_hydro_dof, n_omega), python-control's axis order (mbcontrol.lti): the
    outputs' response to a unit excitation force on each hydro DOF (exp(+i omega t)); times
    the excitation phasor F (`HydroModel.excitation_phasor`) it is `frequency_domain_response`
    (BEM data straight) or, given the linearised `sys`, `statespace_response`. For many wave
    directions at once: one solve per frequency."""
    omega = np.atleast_1d(np.asarray(omega, float))
    if sys is not None:
        w_idx = [sys.input_labels.index(f"w__{d}") for d in plant.hydro.dofs]
        y_idx = [sys.output_labels.index(o) for o in (outputs or sys.output_labels)]
        A, B, C, D = (np.asarray(M) for M in (sys.A, sys.B, sys.C, sys.D))
        return frequency_response(A, B[:, w_idx], C[y_idx], D[np.ix_(y_idx, w_idx)], omega)
    mech = mechanical_matrices(plant, params)
    A_w, B_w = plant.hydro.frequency_domain_matrices(omega)
    idx = [plant.outputs.index(o) for o in (outputs or plant.outputs)]
    X = np.concatenate([np.linalg.solve(_impedance(mech, omega[k], A_w[k], B_w[k]), mech.P_hydro)
                        for k in frequency_chunks(omega.size, mech.mass.shape[0])])
    return np.moveaxis(_outputs(mech, omega, X, idx), 0, -1)


def statespace_response(sys, plant, omega, *, direction: float = 0.0, outputs=None):
    """Response per unit wave amplitude of a linearised model (n_omega, n_outputs).

    Drives the w inputs of `sys` with the BEM excitation's phasor (exp(+i omega t)).
    """
    omega = np.atleast_1d(np.asarray(omega, float))
    hyd = plant.hydro
    F = hyd.excitation_phasor(omega, direction)
    w_idx = [sys.input_labels.index(f"w__{d}") for d in hyd.dofs]
    names = outputs or sys.output_labels
    y_idx = [sys.output_labels.index(o) for o in names]
    A, B, C, D = (np.asarray(M) for M in (sys.A, sys.B, sys.C, sys.D))
    G = frequency_response(A, B[:, w_idx], C[y_idx], D[np.ix_(y_idx, w_idx)], omega)
    return np.einsum("omw,wm->wo", G, F)


def steady_amplitude(ds, name: str, period: float, n_periods: int = 10) -> float:
    """Half the peak-to-peak of a signal over its last n_periods periods (regular waves)."""
    t = ds["time"].values
    window = t >= t[-1] - n_periods * period
    values = ds[name].values[window]
    return 0.5 * float(values.max() - values.min())


def steady_state_initial(sys, plant, wave) -> np.ndarray:
    """State at t = 0 on the linear periodic response to a regular wave (no ramp needed).

    x(t) = Re(X exp(i omega t)) with X = (i omega I - A)^-1 B_w F a (F, a: the excitation's
    and the wave's exp(+i omega t) phasors); starting there
    removes the start-up transient of lightly damped modes, leaving only what the nonlinear
    terms add. Returns the full plant state (sys must be linearize(plant) with all states).
    """
    if wave.omega.size != 1:
        raise InputError("steady_state_initial needs a regular wave")
    w, a = float(wave.omega[0]), float(wave.amplitude[0]) * np.exp(-1j * wave.phase[0])
    hyd = plant.hydro
    F = hyd.excitation_phasor(np.array([w]), wave.direction)[0] * phasor(a)
    w_idx = [sys.input_labels.index(f"w__{d}") for d in hyd.dofs]
    X = state_response(sys.A, np.asarray(sys.B)[:, w_idx] @ F, [w])[:, 0, 0]
    return plant.x0() + X.real


def regular_wave_amplitudes(plant, sys, omegas, outputs, *, height: float, params=None,
                            periods_settle: int = 4, periods_measure: int = 10,
                            steps_per_period: int = 200) -> np.ndarray:
    """Steady amplitudes per unit wave amplitude of the NONLINEAR plant in regular waves.

    For each frequency: start on the linear periodic solution (steady_state_initial, so no
    long start-up transient), run periods_settle + periods_measure periods with
    steps_per_period RK4 steps each, and take half the peak-to-peak of each output over the
    last periods_measure periods, divided by the wave amplitude. Returns (n_omega, n_out).
    """
    from ..sim import simulate
    from ..waves import regular
    out = np.empty((len(omegas), len(outputs)))
    for i, w in enumerate(omegas):
        period = 2 * np.pi / w
        wave = regular(height, period, ramp_time=0.0)
        ds = simulate(plant, wave, duration=(periods_settle + periods_measure) * period,
                      dt=period / steps_per_period, params=params,
                      x0=steady_state_initial(sys, plant, wave))
        t = ds["time"].values
        last = t >= t[-1] - periods_measure * period
        out[i] = [0.5 * np.ptp(ds[name].values[last]) / (height / 2) for name in outputs]
    return out
