"""A sweep in the frequency domain: every sea of a site in milliseconds, for a linear law.

Linear theory straight from the BEM data, no radiation fit and no simulation. The device's
responses are computed once on one frequency grid (`analysis.law_responses` with the law in
place, `analysis.multiport_bound` for the bound), and each sea enters only through the
variances a_k^2 of its components, one row of a matrix (seas x frequencies). With the law
F = -(c v + k x) on each PTO, a sea's mean absorbed power and its complex-conjugate bound are

    P = sum_k a_k^2 p(omega_k),   p = sum_PTO c |V_PTO(omega)|^2 / 2       (W per m^2),
    P_cc = sum_k a_k^2 b(omega_k),  b = H^H Y_h^-1 H / 8                  (W per m^2),

(V per unit wave amplitude; the spring's k x v averages to zero; H, Y_h: `analysis.ports`),
so all seas are two matrix-vector products.

The seas are the time-domain sweep's own (`case_run.sea_wave`, deterministic amplitudes):
JONSWAP from 0.3 to 4 times the peak frequency, cut to the hydro data's band, on the grid
d_omega = 2 pi / max(duration, 20 Tp), its variance rescaled so that 4 sqrt(m0) = Hs on the
kept components. Per sea this is exactly linear theory's expected power of the record the
time-domain sweep simulates (`spectral.expected_power`; its rows' "expected_power_W"). What
the simulation adds is the radiation fit, the record's finite window, the start-up and any
nonlinearity (a saturating force, large motions): validity is linear theory's.
"""
from __future__ import annotations

import math
import time

import numpy as np

from ... import defaults
from ...errors import InputError
from ...waves import (DEFAULT_BAND, Wave, energy_flux, gamma_for_te_over_tp, jonswap_spectrum,
                      site_energy_flux)

GRAVITY_STEEPNESS = 9.80665      # m/s^2: the deep-water wavelength of waves' steepness check


def sea_arrays(seas) -> dict:
    """The seas' hs, tp, gamma (and their weights) as arrays, one entry per sea."""
    return {name: np.array([getattr(s, name) for s in seas], float)
            for name in ("hs", "tp", "gamma", "weight")}


def repeat_periods(seas, duration: float) -> np.ndarray:
    """Each sea's repeat period (s) as `waves.irregular` makes it: max(duration, 20 Tp)."""
    return np.maximum(float(duration), 20.0 * sea_arrays(seas)["tp"])


def sea_variances(seas, d_omega: float, data_band) -> tuple[np.ndarray, np.ndarray, list]:
    """(omega, A2, reasons): the grid k d_omega (rad/s) spanning every sea's components, the
    variance a^2 (m^2) of each sea's component at each frequency (n_seas, n_omega; zero
    outside its band) exactly as `waves.irregular` draws it with deterministic amplitudes,
    and per sea None or why it has no components (steeper than a wave can be, or outside the
    hydro data's band: the time-domain sweep's case fails there too)."""
    a = sea_arrays(seas)
    hs, tp, gamma = a["hs"], a["tp"], a["gamma"]
    wp = 2 * np.pi / tp
    lo = np.maximum(DEFAULT_BAND[0], data_band[0] / wp)           # waves.band_limits
    hi = np.minimum(DEFAULT_BAND[1], data_band[1] / wp)
    first = np.ceil(lo * wp / d_omega)
    last = np.floor(hi * wp / d_omega)
    steep = hs > defaults.get("waves.breaking_steepness") * GRAVITY_STEEPNESS * tp ** 2 / (
        2 * math.pi)
    reasons = [f"Hs {h:g} m over Tp {t:g} s is steeper than a wave can be" if s else
               f"the sea with Tp {t:g} s lies outside the hydro data's band "
               f"{data_band[0]:.3g}..{data_band[1]:.3g} rad/s" if not l < u or f > z else None
               for h, t, s, l, u, f, z in zip(hs, tp, steep, lo, hi, first, last)]
    ok = np.array([r is None for r in reasons])
    if not ok.any():
        return np.zeros(0), np.zeros((len(seas), 0)), reasons
    k = np.arange(int(first[ok].min()), int(last[ok].max()) + 1)
    omega = k * d_omega
    inside = ok[:, None] & (k >= first[:, None]) & (k <= last[:, None])
    A2 = np.where(inside, 2 * jonswap_spectrum(omega[None, :], hs[:, None], tp[:, None],
                                               gamma[:, None]) * d_omega, 0.0)
    total = A2.sum(axis=1)
    # irregular: a *= hs / (4 sqrt(sum a^2 / 2)), so a^2 *= hs^2 / (8 sum a^2)
    A2 *= np.divide(hs ** 2, 8 * total, out=np.zeros_like(total), where=total > 0)[:, None]
    return omega, A2, reasons


def device_responses(plant, omega, gains: dict, *, direction: float = 0.0,
                     params=None) -> tuple[np.ndarray, np.ndarray]:
    """(p, b) per unit wave amplitude squared (W/m^2) at each omega (rad/s): the mean power
    the law `gains` (pto -> (damping, stiffness), every scene PTO) absorbs, sum c |V|^2 / 2,
    and the multiport complex-conjugate bound H^H Y_h^-1 H / 8 (inf where a PTO sees no
    dissipation). Both from one solve of the device seen from its PTOs
    (`analysis.port_responses`, exp(-i omega t): V = Y F + H A): with the law
    F = -(c V + k X) = -Z_L V, Z_L = c + i k / omega, the velocities are
    V = (I + Y Z_L)^-1 H A (one plant solve, not one for the law and one for the bound)."""
    from ...analysis import multiport_bound, port_responses
    ptos = [p.name for p in plant.scene.ptos]
    Y, H = port_responses(plant, omega, ptos, direction, params)
    c = np.array([gains[name][0] for name in ptos], float)
    k = np.array([gains[name][1] for name in ptos], float)
    Z_law = c[None, :] + 1j * k[None, :] / omega[:, None]          # (n_omega, n_pto)
    closed = np.eye(len(ptos))[None] + Y * Z_law[:, None, :]       # I + Y diag(Z_law)
    V = np.linalg.solve(closed, H[..., None])[..., 0]
    p = 0.5 * np.sum(c[None, :] * np.abs(V) ** 2, axis=1)
    unit = Wave("components", omega, np.ones(omega.size), np.zeros(omega.size), direction)
    return p, multiport_bound(plant, unit, responses=(Y, H)).power_by_component


def sea_directions(plant, seas) -> np.ndarray:
    """Each sea's direction (rad) as `case_run.sea_wave` takes it: its own, else the data's
    one heading, else 0."""
    headings = plant.hydro.data["wave_direction"].values
    default = float(headings[0]) if len(headings) == 1 else 0.0
    return np.array([s.direction if math.isfinite(s.direction) else default for s in seas])


def sea_powers(plant, seas, gains: dict, *, duration: float, params=None) -> dict:
    """Every sea's linear-theory mean absorbed power and complex-conjugate bound (W), the
    responses computed once per (repeat period, direction) group (one group when every
    sea's 20 Tp fits in `duration`, s, and the seas share a direction). Returns {"power_W",
    "bound_W" (inf: unbounded), "reasons" (per sea None, or why it has no power), "groups",
    "components" (the largest grid's frequencies)}."""
    spread = [k for k, s in enumerate(seas) if s.spread_given]
    if spread:
        raise InputError(f"--domain frequency: sea {spread[0] + 1} is short-crested (a spread); "
                         f"not built here (long-crested seas only): run --domain time")
    omega_data = plant.hydro.omega
    band = (float(omega_data[0]), float(omega_data[-1]))
    repeat, direction = repeat_periods(seas, duration), sea_directions(plant, seas)
    power, bound = np.full(len(seas), np.nan), np.full(len(seas), np.nan)
    reasons: list = [None] * len(seas)
    groups = sorted(set(zip(repeat.tolist(), direction.tolist())))
    components = 0
    for T, theta in groups:
        rows = np.flatnonzero((repeat == T) & (direction == theta))
        omega, A2, why = sea_variances([seas[k] for k in rows], 2 * np.pi / T, band)
        for k, reason in zip(rows, why):
            reasons[k] = reason
        if omega.size == 0:
            continue
        components = max(components, omega.size)
        p, b = device_responses(plant, omega, gains, direction=theta, params=params)
        power[rows] = A2 @ p
        finite = np.isfinite(b)
        bound[rows] = A2 @ np.where(finite, b, 0.0)
        bound[rows[np.any((A2 > 0) & ~finite, axis=1)]] = np.inf
        bad = [k for k, r in zip(rows, why) if r is not None]
        power[bad], bound[bad] = np.nan, np.nan
    return {"power_W": power, "bound_W": bound, "reasons": reasons, "groups": len(groups),
            "components": components}


def sea_energy_fluxes(seas, depth: float, rho: float, g: float) -> np.ndarray:
    """J (W/m) of each sea as `waves.site_energy_flux` gives it (the site's own Te / Tp where
    the file gave Te), in deep water from one flux per spectral shape: J is Hs^2 Tp times that
    of the unit sea (Hs 1 m, Tp 1 s) on energy_flux's grid, which scales with the peak
    frequency; in finite depth sea by sea."""
    if math.isfinite(depth):
        return np.array([site_energy_flux(s, depth, rho, g) for s in seas], float)
    shape = np.array([gamma_for_te_over_tp(s.te / s.tp) if math.isfinite(s.te) and s.tp > 0
                      else s.gamma for s in seas], float)
    unit = {gam: energy_flux(1.0, 1.0, gam, depth, rho, g) for gam in set(shape.tolist())}
    a = sea_arrays(seas)
    return a["hs"] ** 2 * a["tp"] * np.array([unit[gam] for gam in shape.tolist()])


def linear_gains(plant, controller, settings, params) -> dict:
    """pto -> (damping, stiffness) of the sweep's law (`spectral.law_gains`); InputError,
    saying why, for a law linear theory does not describe."""
    from .spectral import law_gains
    gains, why = law_gains(plant, controller, dict(settings or {}), params)
    if gains is None:
        raise InputError(f"--domain frequency needs a linear law: {why}; run --domain time "
                         f"(the simulation) for it")
    check_stable(plant, gains, params)
    return gains


def check_stable(plant, gains: dict, params=None) -> None:
    """InputError where linear theory's steady state need not exist: a law with negative
    damping, or a stiffness that leaves the device statically unstable (the stiffness matrix,
    hydrostatics and the law's springs, not positive semi-definite). With damping >= 0 and
    that matrix >= 0 the device is passive (radiation damping >= 0) and its motion bounded."""
    from ...analysis import law_params, mechanical_matrices
    negative = [name for name, (c, _k) in gains.items() if c < 0]
    if negative:
        raise InputError(f"--domain frequency: PTO {negative[0]}'s damping "
                         f"{gains[negative[0]][0]:.4g} < 0 is not passive: no steady state is "
                         f"assured; run --domain time")
    if all(k >= 0 for _c, k in gains.values()):      # springs only add to the scene's own
        return                                       # restoring, which the plant checks
    K = mechanical_matrices(plant, law_params(plant, gains, params)).stiffness
    eig = np.linalg.eigvalsh(0.5 * (K + K.T)) if K.size else np.zeros(1)
    if eig[0] < -1e-9 * max(abs(eig[-1]), 1.0):
        raise InputError(f"--domain frequency: the law's stiffness leaves {plant.scene.name} "
                         f"statically unstable (its stiffness matrix with the law in place has "
                         f"the eigenvalue {eig[0]:.4g} < 0): no steady state exists; run "
                         f"--domain time to see it diverge")


def frequency_sweep(model, seas, *, controller: str | None = None, settings=None, params=None,
                    scene_params=None, duration: float | None = None,
                    width: float | None = None, plant=None):
    """The frequency-domain sweep of `seas` (SeaStates): (Dataset, summary), the summary with
    the keys of the time-domain sweep's (`study.sweep`; per sea "mean_power_W",
    "capture_width_m", "energy_flux_W_per_m"...; "weighted_mean_power_W",
    "annual_energy_MWh") and per sea "conjugate_bound_W" and "percent_of_conjugate_bound",
    "domain": "frequency", "compute_time_s" (after the plant is built, s). The law: the scene
    PTOs' own (controller None, with --param's pto__damping/stiffness) or a linear
    controller's `settings`. duration (s; default "sweep.duration"): the records the
    time-domain sweep would run, which set the frequency grid. plant: one already built
    (else built from model and scene_params)."""
    from .frequency_summary import frequency_dataset, frequency_summary
    start = time.perf_counter()
    if plant is None:
        from ...plant import build_plant
        from ...scene import load_scene
        plant = build_plant(load_scene(model, scene_params or None))
    duration = defaults.resolve("sweep.duration", duration)
    built = time.perf_counter()
    unknown = [p for p in (params or {}) if p not in plant.parameters]
    if unknown:
        raise InputError(f"--param {unknown[0]}: not a parameter of {plant.scene.name}; it has "
                         f"{', '.join(plant.parameters)}")
    gains = linear_gains(plant, controller, settings, params)
    result = sea_powers(plant, seas, gains, duration=duration, params=params)
    water = plant.scene.water
    result["energy_flux_W_per_m"] = sea_energy_fluxes(seas, water.depth, water.rho, water.g)
    ds = frequency_dataset(plant, seas, result, width)
    summary = frequency_summary(plant, seas, ds, result, gains=gains, controller=controller,
                                settings=settings, duration=duration)
    summary["compute_time_s"] = time.perf_counter() - built
    summary["wall_time_s"] = time.perf_counter() - start
    return ds, summary


def froude_seas(seas, scale: float) -> list:
    """The seas a device `scale` times larger sees in `seas`, at the original device's scale
    (Froude similarity: Hs / scale, Tp and Te / sqrt(scale); weights, gamma and directions
    kept): the scaled device's power in a sea is scale^3.5 times the original's in the
    sea returned here, with the PTO damping scaled by scale^2.5 and stiffness by scale^2."""
    import dataclasses
    if not scale > 0:
        raise InputError(f"a Froude scale must be > 0, got {scale}")
    root = math.sqrt(scale)
    return [dataclasses.replace(s, hs=s.hs / scale, tp=s.tp / root, te=s.te / root,
                                j=s.j / scale ** 2.5) for s in seas]
