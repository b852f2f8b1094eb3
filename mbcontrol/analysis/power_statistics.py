"""How much a linear law's mean power scatters from one record of a sea to the next: the
spectral estimate, from the frequency-domain solution alone.

A sea is the sum of components on the grid omega_k with complex amplitudes z_k = a_k e^{i phi_k}
(`waves.irregular`); with a linear law (a damper c and a spring k per PTO: F = -(c v + k x))
every response is linear in u = [Re z; Im z], so the power the PTOs absorb, averaged over the
metrics' window [t0, t1] (after the ramp, `analysis.metrics`), is a quadratic form

    P_mean = u^T Q u,    Q = sym( 1/T int_{t0}^{t1} sum_PTO [c g_v g_v^T + k g_x g_v^T] dt ),

with g_y(t) = [Re(Y e^{i w t}); -Im(Y e^{i w t})] the per-component responses
(`frequency_domain_response`, straight from the BEM data). Its mean and variance are exact for
both kinds of sea (steady state over the window; the start-up transient is left out):
- random amplitudes (Rayleigh, a record's statistics): u is Gaussian with Sigma =
  diag(a_rms^2 / 2), so E = tr(Q Sigma) and Var = 2 tr((Q Sigma)^2);
- deterministic amplitudes, uniform phases (the expected power): E = sum_k a_k^2 (Q_kk +
  Q_k'k') / 2 and Var = sum_{j<k} a_j^2 a_k^2 N_jk + sum_k a_k^4 (((B11 - B22) / 2)^2 +
  B12^2) / 2, with B_jk the 2 x 2 block of Q coupling components j and k and N_jk the sum
  of its four entries squared.
For c v^2 and a window of whole repeat periods, the random case reduces to Bendat & Piersol's
mean-square error CV^2 = 1 / (B_s T), B_s = (int G df)^2 / int G^2 df the statistical
bandwidth of the power density (reported as `bandwidth_hz`). The effective sample count
1 / CV^2 is the number of independent exponential samples that scatter alike.
Units: W, s, Hz.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError


def law_params(plant, gains: dict, params=None) -> dict:
    """Plant parameter overrides that put the linear law F = -(c v + k x) in place on each
    PTO of `gains` (pto -> (c, k)), Coulomb friction left out (`ports.linear_params`)."""
    from .ports import linear_params
    values = linear_params(plant, list(gains), params)
    for name, (c, k) in gains.items():
        values[f"{name}__damping"], values[f"{name}__stiffness"] = float(c), float(k)
    return values


def law_responses(plant, omega, gains: dict, *, direction: float = 0.0, params=None) -> dict:
    """{pto: (V, X)}: complex velocity and position of each PTO per unit wave amplitude
    (exp(+i w t)) with the law F = -(c v + k x) in place; gains: pto -> (c, k) in N s/m and
    N/m (or N m s/rad, N m/rad). Coulomb friction is left out (it is not linear)."""
    from .frequency import frequency_domain_response
    values = law_params(plant, gains, params)
    omega = np.asarray(omega, float)
    names = [f"{name}__velocity" for name in gains]
    V = frequency_domain_response(plant, omega, direction=direction, params=values,
                                  outputs=names)
    return {name: (V[:, i], V[:, i] / (1j * omega)) for i, name in enumerate(gains)}


def power_form(omega, responses: dict, gains: dict, window: tuple[float, float]) -> np.ndarray:
    """Q (2n x 2n): the window's mean absorbed power (W) as u^T Q u, u = [Re z; Im z] (m).

    Each response is Re(z Y e^{i w t}) = Re z Re(Y e^{i w t}) + Im z Re(i Y e^{i w t}), and
    the window mean of Re(a e^{i w_j t}) Re(b e^{i w_k t}) is, in closed form,
    1/2 Re(a conj(b) E(w_j - w_k)) + 1/2 Re(a b E(w_j + w_k)), E(W) = mean of e^{i W t}."""
    R, C, I = _quadrants(omega, responses, gains, window)
    return np.block([[R, C], [C.T, I]])


def _quadrants(omega, responses: dict, gains: dict, window: tuple[float, float]):
    """The quadrants (R, C, I) of power_form's symmetric Q = [R, C; C^T, I], each (n, n).

    Every law term is linear in its first response (sum over PTOs of c V V' + k X V' is
    (c V + k X) V'), so one pair of products serves them all: with a = c V + k X, b = V,
    A = a conj(b)' E(w_j - w_k) and B = a b' E(w_j + w_k), Q before symmetrising is
    1/2 [Re A + Re B, Im A - Im B; -Im A - Im B, Re A - Re B] (i a, i b stand for Im z)."""
    omega = np.asarray(omega, float)
    t0, t1 = map(float, window)
    if not t1 > t0:
        raise InputError(f"power statistics: the window must have t1 > t0, got {window}")
    A = np.zeros((omega.size, omega.size), complex)
    B = np.zeros_like(A)
    for name, (c, k) in gains.items():
        V, X = responses[name]
        a = c * V + (k * X if k else 0.0)
        A += np.outer(a, np.conj(V))
        B += np.outer(a, V)
    A *= _window_mean(omega, -omega, t0, t1)
    B *= _window_mean(omega, omega, t0, t1)
    R = A.real + B.real
    R += R.T
    I = A.real - B.real
    I += I.T
    C = (A.imag - B.imag) - (A.imag + B.imag).T      # [0, 1] block plus the [1, 0] block's transpose
    R *= 0.25
    I *= 0.25
    C *= 0.25
    return R, C, I


def _window_mean(a, b, t0: float, t1: float):
    """E(W) = 1/(t1 - t0) int_t0^t1 e^{i W t} dt for W = a_j + b_k, (n_a, n_b) (1 at W = 0).

    (e^{i W t1} - e^{i W t0}) / (i W T) with e^{i W t} = e^{i a_j t} e^{i b_k t}: 4 n complex
    exponentials, not 2 n^2 (those were 40 % of a sweep's uncertainty budget); where |W T|
    < 1 the difference of exponentials loses digits, so there E comes from W directly."""
    T = t1 - t0
    W = a[:, None] + b[None, :]
    x = W * T
    ea0, eb0, ea1, eb1 = (np.exp(1j * v * t) for v, t in ((a, t0), (b, t0), (a, t1), (b, t1)))
    with np.errstate(divide="ignore", invalid="ignore"):
        E = (np.outer(ea1, eb1) - np.outer(ea0, eb0)) / (1j * x)
    near = np.abs(x) < 1.0
    if near.any():
        Wn, xn = W[near], x[near]
        small = np.abs(xn) < 1e-8
        safe = np.where(small, 1.0, xn)
        E[near] = np.exp(1j * Wn * t0) * np.where(small, 1.0 + 0.5j * xn,
                                                   (np.exp(1j * xn) - 1) / (1j * safe))
    return E


def form_statistics(Q: np.ndarray, amplitude) -> dict:
    """Mean and standard deviation (W) of u^T Q u over records: "random" (Gaussian u,
    E a_k^2 = amplitude_k^2) and "deterministic" (a_k = amplitude_k, uniform phases)."""
    n = Q.shape[0] // 2
    Q = 0.5 * (Q + Q.T)
    return _quadrant_statistics(Q[:n, :n], Q[:n, n:], Q[n:, n:], amplitude)


def _quadrant_statistics(R, C, I, amplitude) -> dict:
    """form_statistics from the quadrants of a symmetric Q = [R, C; C^T, I] (module docstring:
    Var = 2 tr((Q Sigma)^2) = 2 sum Q_ij^2 s_i s_j; N_jk = R^2 + C^2 + C^T^2 + I^2)."""
    a2 = np.asarray(amplitude, float) ** 2
    s = a2 / 2                                          # Var(Re z) = Var(Im z) = E a^2 / 2
    dR, dI, dC = np.diag(R), np.diag(I), np.diag(C)
    R2, C2, I2 = R * R, C * C, I * I
    mean_r = float(np.sum(s * (dR + dI)))
    var_r = float(2 * (s @ R2 @ s + s @ I2 @ s + 2 * s @ C2 @ s))
    N = R2 + I2 + C2 + C2.T                             # N_jk: the 2 x 2 blocks' squares
    off = a2 @ N @ a2 - np.sum(a2 ** 2 * np.diag(N))
    diag = (0.5 * (dR - dI)) ** 2 + dC ** 2
    mean_d = float(np.sum(a2 * (dR + dI)) / 2)
    var_d = float(0.5 * off + np.sum(a2 ** 2 * diag) / 2)
    return {"random": (mean_r, np.sqrt(max(var_r, 0.0))),
            "deterministic": (mean_d, np.sqrt(max(var_d, 0.0)))}


def record_power_statistics(plant, omega, amplitude, gains: dict, window: tuple[float, float],
                            *, amplitudes: str = "random", direction: float = 0.0,
                            params=None) -> dict:
    """The spectral estimate of one record's mean absorbed power under a linear law.

    omega (rad/s) and amplitude (m) the sea's components (for "random", the rms amplitude
    sqrt(2 S dw) of each); gains: pto -> (damping, stiffness); window (s): the metrics'.
    Returns {"mean_power_W", "std_W", "cv", "effective_samples" (1 / cv^2), "bandwidth_hz"
    (B_s of the power density), "window_s", "amplitudes"}."""
    if amplitudes not in ("random", "deterministic"):
        raise InputError(f"power statistics: amplitudes must be 'random' or 'deterministic', "
                         f"got {amplitudes!r}")
    omega = np.asarray(omega, float)
    responses = law_responses(plant, omega, gains, direction=direction, params=params)
    # straight from the quadrants: Q (2n x 2n, 72 MB for an hour's 1,500 components) is
    # never assembled
    quadrants = _quadrants(omega, responses, gains, window)
    mean, std = _quadrant_statistics(*quadrants, amplitude)[amplitudes]
    # the power density per component (W) for Bendat & Piersol's statistical bandwidth
    a2 = np.asarray(amplitude, float) ** 2
    p = sum(0.5 * c * a2 * np.abs(V) ** 2 for (c, _), (V, _X) in
            zip(gains.values(), responses.values()))
    d_f = (omega[1] - omega[0]) / (2 * np.pi) if omega.size > 1 else np.nan
    bandwidth = float(np.sum(p) ** 2 * d_f / np.sum(p ** 2)) if np.any(p) else np.nan
    cv = std / mean if mean > 0 else np.nan
    return {"mean_power_W": mean, "std_W": std, "cv": float(cv),
            "effective_samples": float(1 / cv ** 2) if cv > 0 else np.inf,
            "bandwidth_hz": bandwidth, "window_s": float(window[1] - window[0]),
            "amplitudes": amplitudes}
