"""What a PTO sees in linear theory: its intrinsic impedance and equivalent excitation, the
frequency-domain statistics of a damper-spring law, and the stability of its closed loop.

Phasors exp(+i omega t), as python-control and `analysis.frequency_domain_response` (see
`controllers.reactive` for the conventions of Z_i and the PTO impedance); the Thevenin
equivalent itself is computed once, by `analysis.pto_thevenin` in exp(-i omega t) (the bound
stack's, notebooks/guide.md "Conventions"), and converted here by `mbcontrol.lti.phasor`.
"""
from __future__ import annotations

import numpy as np

from mbcontrol.errors import ControllerError
from mbcontrol.lti import phasor
from mbcontrol.plant import controlled_params


def base_params(plant, pto: str, params=None) -> dict:
    """Parameters of the plant as a controller of `pto` sees it (mbcontrol.plant.ownership):
    no Coulomb friction (linear theory cannot hold it), every PTO's scene law off unless
    `params` sets it: a law `params` sets, on `pto` itself too, is a damper or spring in
    parallel with the controller, part of the plant it faces (and of Z_i)."""
    return controlled_params(plant, params, linear=True)


def intrinsic_impedance(plant, omega, *, pto: str | None = None, params=None,
                        direction: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(Z_i, F_eq) at each omega (rad/s), exp(+i omega t): the PTO's Thevenin equivalent.

    Z_i (N s/m or N m s/rad): the impedance the PTO's controller sees (everything but the
    controller: inertia, added mass, radiation damping, restoring, the other PTOs and a law
    on this PTO itself as set by params, base_params); F_eq (N per m of wave amplitude): the
    force that drives it, so that with a PTO impedance Z_pto the PTO velocity is
    F_eq / (Z_i + Z_pto). The one computation is `mbcontrol.analysis.pto_thevenin` (exp(-i
    omega t), the PTO's whole force): here converted at this edge (`lti.phasor`), plus the
    law params sets on the PTO itself (c - i k / omega beside the controller).
    """
    from mbcontrol.analysis import pto_thevenin
    name = pto or plant.scene.ptos[0].name
    omega = np.atleast_1d(np.asarray(omega, float))
    base = base_params(plant, name, params)
    th = pto_thevenin(plant, omega, name, direction, base, check_passive=False)
    beside = base[f"{name}__damping"] - 1j * base[f"{name}__stiffness"] / omega
    return phasor(th.impedance) + beside, phasor(th.excitation)


def complex_conjugate_power(plant, wave, *, pto: str | None = None, params=None) -> float:
    """The upper bound of mean absorbed power in `wave` (W): sum |F_eq a|^2 / (8 Re Z_i)."""
    Z, F = intrinsic_impedance(plant, wave.omega, pto=pto, params=params,
                               direction=wave.direction)
    return float(np.sum(np.abs(F * wave.amplitude) ** 2 / (8 * Z.real)))


def electrical_optimum(plant, wave, *, pto: str | None = None, params=None) -> dict:
    """The largest mean electrical power (W) a PTO with a drivetrain can deliver in `wave` in
    linear theory, with no force, stroke or electrical limit, and the load that reaches it.

    Seen from its terminals the machine is a source: with current I (exp(+i omega t)) the PTO
    force is F = G kt' I, the velocity v = (F_eq + F) / Z_i and the voltage
    V = (R + i omega L) I + G kt' v = V_oc + Z_out I, with V_oc = G kt' F_eq / Z_i and
    Z_out = R + i omega L + (G kt')^2 / Z_i. The delivered power -Re(V I*) / 2 is largest at
    I = -V_oc / (2 Re Z_out): |V_oc|^2 / (8 Re Z_out) per component. With R = 0 this is the
    complex-conjugate bound; with losses the optimal mechanical load Z_pto = -F / v is no
    longer conj(Z_i). Z_i holds the drivetrain's reflected inertia, friction and stiffness
    (the plant does). Returns {"power_W", "omega", "power_per_omega_W", "load_impedance"
    (Z_pto, N s/m or N m s/rad), "electrical_load" (V / -I, ohm), "mechanical_power_W" (its
    -F v)}.
    """
    name = pto or plant.scene.ptos[0].name
    drive = next(p for p in plant.scene.ptos if p.name == name).drivetrain
    if drive is None:
        raise ControllerError(f"PTO {name!r} has no [pto.drivetrain]: its electrical optimum is "
                              f"the complex-conjugate bound times its efficiency")
    Z, F = intrinsic_impedance(plant, wave.omega, pto=name, params=params,
                               direction=wave.direction)
    g = drive.force_per_current
    z_out = drive.winding_resistance + 1j * wave.omega * drive.winding_inductance + g * g / Z
    v_oc = g * F * wave.amplitude / Z
    current = -v_oc / (2 * z_out.real)
    velocity = (F * wave.amplitude + g * current) / Z
    power = np.abs(v_oc) ** 2 / (8 * z_out.real)
    return {"power_W": float(power.sum()), "omega": wave.omega, "power_per_omega_W": power,
            "load_impedance": -g * current / velocity,
            "electrical_load": np.conj(z_out),
            "mechanical_power_W": float(np.sum(-0.5 * (g * current * np.conj(velocity)).real))}


def closed_loop_stability(plant, damping: float, stiffness: float, *, pto: str | None = None,
                          params=None) -> tuple[bool, float]:
    """Is the linearised plant stable under u = -(damping v + stiffness x)? (stable, margin).

    margin (1/s): minus the largest real part of the closed-loop poles (python-control); > 0
    when stable, the decay rate of the slowest mode. Linearised about rest, with no Coulomb
    friction and the PTO's own law zeroed, as in closed-loop simulation.
    """
    margin = margin_function(plant, pto or plant.scene.ptos[0].name, params)(damping, stiffness)
    return margin > 0, margin


def margin_function(plant, name: str, params=None):
    """(damping, stiffness) -> stability margin (1/s), from one linearisation."""
    import control

    from mbcontrol.analysis import linearize
    base = base_params(plant, name, params)
    sys = linearize(plant, params=base, inputs=[f"u__{name}"],
                    outputs=[f"{name}__position", f"{name}__velocity"])

    def margin(damping: float, stiffness: float) -> float:
        gain = np.array([[float(stiffness), float(damping)]])     # u = -gain @ [x, v]
        return -float(np.max(control.feedback(sys, gain, sign=-1).poles().real))
    return margin


def fd_statistics(Z, F, wave, damping, stiffness, *, efficiency: float | None = None,
                  exceedance: float = 0.01, winding: float | None = None,
                  hull=None) -> dict:
    """Linear-theory statistics of u = -(damping v + stiffness x) in `wave` (exp(+i omega t)).

    Z, F: intrinsic_impedance at wave.omega. damping (N s/m) and stiffness (N/m) broadcast
    (arrays give arrays). Per component j the PTO velocity is V_j = F_j a_j / (Z_j + c - i k /
    omega_j), its position X_j = V_j / (i omega_j), its force U_j = -(c V_j + k X_j). Keys:

    - power_W: mean absorbed power sum c |V_j|^2 / 2 (W);
    - electrical_W: mean electrical power with `efficiency` eta, eta P when absorbing and P /
      eta when the PTO drives the body (as metrics.electrical_power); with `winding` (a
      drivetrain's R / (gear kt')^2, W/N^2) P less the mean winding loss sum winding |U_j|^2
      / 2 instead; neither: power_W. A regular
      wave's P(t) = A + B cos(2 omega t) is split exactly; in a sea P = -u v with u and v jointly
      Gaussian, E|P| = s_u s_v (2 / pi)(sqrt(1 - r^2) + r asin r) (r their correlation);
    - stroke_peak (m), force_peak (N): a regular wave's amplitudes |X a|, |U a|; in a sea the
      level b that the record of length T (the wave's repeat period 2 pi / d_omega) crosses,
      upwards or downwards, with expected count `exceedance` by Rice's formula,
      2 (T / T_z) exp(-b^2 / 2 s^2) = exceedance, b = s sqrt(2 ln(2 T / (T_z exceedance))):
      a peak factor b / s of 4.5 for 150 zero-crossing periods and the default 1 % (T_z =
      2 pi s / s', the mean zero-crossing period from the spectral moments). The chance that
      the record's largest value exceeds b is at most about `exceedance`: Rice counts
      crossings, and they come in clusters (tests/controllers/test_limits.py measures 2-3 % of
      random-phase records at exceedance 10 %);
    - stroke_std, force_std: standard deviations (m, N).

    hull: a drivetrain's impedance Z_d = gear^2 (i omega J + b - i K / omega) at wave.omega
    (`hull_impedance`) when the force limit acts on the hull: force_peak and force_std are
    then those of the force the drivetrain puts on the hull, U - Z_d V (the winding loss stays
    the machine's).
    """
    w, a = np.asarray(wave.omega, float), np.asarray(wave.amplitude, float)
    c = np.asarray(damping, float)[..., None]
    k = np.asarray(stiffness, float)[..., None]
    V = F * a / (Z + c - 1j * k / w)
    X = V / (1j * w)
    U = -(c * V + k * X)
    return phasor_statistics(V, X, U, c, wave, efficiency=efficiency, exceedance=exceedance,
                             winding=winding, limited=None if hull is None else U - hull * V)


def hull_impedance(plant, pto: str, omega, force_on: str | None = None):
    """Z_d = gear^2 (i omega J + b - i K / omega) (exp(+i omega t); N s/m or N m s/rad), the
    PTO drivetrain's reflected impedance (Drivetrain.reflected_impedance), when its force limit
    acts on the hull (scene Pto.limited_force), else None: the limited force is then the
    machine's."""
    owner = next(p for p in plant.scene.ptos if p.name == pto)
    if owner.limited_force(force_on) != "hull":
        return None
    return owner.drivetrain.reflected_impedance(1j * np.asarray(omega, float))


def phasor_statistics(V, X, U, c, wave, *, efficiency: float | None = None,
                      exceedance: float = 0.01, winding: float | None = None,
                      limited=None) -> dict:
    """fd_statistics' keys from one PTO's velocity, position and force phasors per wave
    component (V, X, U: (..., n_omega), m/s, m, N; either time convention, only moduli and
    c enter) and its damping c (N s/m, broadcast against V): see fd_statistics. limited: the
    phasors of the force the limit acts on when it is not U (force_peak, force_std)."""
    w = np.asarray(wave.omega, float)
    power = np.sum(0.5 * c * np.abs(V) ** 2, axis=-1)
    L = U if limited is None else limited
    var = {name: 0.5 * np.sum(np.abs(z) ** 2, axis=-1) for name, z in
           (("x", X), ("v", V), ("u", U), ("du", w * L), ("limited", L))}
    s_x, s_v, s_u = (np.sqrt(var[n]) for n in ("x", "v", "u"))
    s_l = np.sqrt(var["limited"])
    if w.size == 1:
        stroke, force = np.sqrt(2) * s_x, np.sqrt(2) * s_l           # amplitudes
        half = s_u * s_v                                             # B = |U| |V| / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            theta = np.arccos(np.clip(np.where(half > 0, -power / half, -1.0), -1, 1))
        positive = (power * theta + half * np.sin(theta)) / np.pi   # E[max(P, 0)]
    else:
        record = 2 * np.pi / (wave.d_omega or np.min(np.diff(np.sort(w))))

        def peak(s, s_rate):
            crossings = record * s_rate / (np.pi * np.maximum(s, 1e-300))   # 2 T / T_z
            return s * np.sqrt(2 * np.log(np.maximum(crossings / exceedance, 1.0)))
        stroke, force = peak(s_x, s_v), peak(s_l, np.sqrt(var["du"]))
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.clip(np.where(s_u * s_v > 0, -power / (s_u * s_v), 0.0), -1, 1)
        mean_abs = s_u * s_v * (2 / np.pi) * (np.sqrt(1 - r ** 2) + r * np.arcsin(r))
        positive = 0.5 * (power + mean_abs)
    if winding is not None:             # a drivetrain: the current is the force / (gear kt')
        electrical = power - winding * var["u"]
    elif efficiency is None:
        electrical = power
    else:
        electrical = efficiency * positive + (power - positive) / efficiency
    return {"power_W": power, "electrical_W": electrical, "stroke_peak": stroke,
            "force_peak": force, "stroke_std": s_x, "force_std": s_l}


def default_bounds(plant, wave, name: str, params) -> tuple[float, float]:
    """1e-3 to 1e3 times |Z_i| (N s/m or N m s/rad) at the wave's most energetic component."""
    from mbcontrol.analysis import pto_thevenin
    k = int(np.argmax(wave.amplitude))
    scale = float(np.abs(pto_thevenin(plant, wave.omega[k:k + 1], pto=name,
                                      direction=wave.mean_direction, params=params,
                                      check_passive=False).impedance[0]))
    return 1e-3 * scale, 1e3 * scale
