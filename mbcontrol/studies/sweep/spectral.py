"""What linear theory says about a sweep's seas when the law is linear (no controller and a
linear scene PTO, a passive damper or a reactive spring-damper): each sea's spectral scatter of
a record's mean power (`analysis.power_statistics`), the radiation fit's effect on its power
(the state-space model the simulation steps against the BEM data it was fitted to) and its
power's sensitivity to plant parameters. All from the frequency-domain solution, per sea in
milliseconds; nothing here is simulated. Powers in W.
"""
from __future__ import annotations

import json
import math

import numpy as np

STEP = 1e-3                       # relative central-difference step on a parameter


def law_gains(plant, controller: str | None, settings: dict, params=None):
    """(gains, why): pto -> (damping, stiffness) of a linear law, or (None, why not).
    controller None: the scene PTOs' own law with `params` overrides."""
    from mbcontrol.controllers import REGISTRY
    if controller is not None and (controller not in REGISTRY
                                   or REGISTRY[controller].kind != "linear"):
        return None, f"the {controller} law is not linear"
    if any(f.coulomb for f in plant.scene.frictions):
        return None, "the scene's Coulomb friction is not linear"
    if plant.scene.hydro.hydrostatics != "linear":
        return None, "the scene's hydrostatics (and Froude-Krylov forces) are not linear"
    params = dict(params or {})
    if controller is None:
        return {p.name: (params.get(f"{p.name}__damping", p.damping),
                         params.get(f"{p.name}__stiffness", p.stiffness))
                for p in plant.scene.ptos}, None
    from mbcontrol.controllers import make
    law = make(controller, **{k: v for k, v in settings.items() if k != "wave"})
    law.reset(plant)
    c = law.damping_per_pto                  # a linear law's gains (controllers.law)
    k = law.stiffness_per_pto if hasattr(law, "stiffness_per_pto") else np.zeros_like(c)
    return {p.name: (float(ci), float(ki)) for p, ci, ki in zip(plant.scene.ptos, c, k)}, None


def sea_components(plant, sea, duration: float, direction: float | None = None):
    """(wave, rms amplitudes): the sea as the sweep draws it (`runner.sea_wave`, seed 0; its
    grid, deterministic amplitudes and ramp) and each component's rms amplitude sqrt(2 S dw) (m),
    what random amplitudes scatter about."""
    from ...waves import jonswap_spectrum
    from .runner import sea_wave
    wave = sea_wave(plant, sea, duration, seed=0, direction=direction)
    gamma = wave.settings.get("gamma", sea.gamma)
    rms = np.sqrt(2 * jonswap_spectrum(wave.omega, sea.hs, sea.tp, gamma) * wave.d_omega)
    return wave, rms


def sea_gains(ds, k: int, plant, controller, settings, params):
    """The linear law of sea k: the sweep's settings, or (--design) the settings tuned for it."""
    given = dict(settings or {})
    if "design_settings" in ds:
        first = np.ravel(ds["design_settings"].isel(sea=k).values)[0]
        given = {**(json.loads(first) if first else {}), **given}
    return law_gains(plant, controller, given, params)


def spectral_row(plant, wave, rms, gains, duration: float, amplitudes: str, n_valid: int,
                 mean_power: float | None) -> dict:
    """A sea's spectral entries (wave, rms: `sea_components`): "spectral_cv" (one record's),
    "effective_samples" (over its valid seeds: n / cv^2), "spectral_stderr_W" (cv x the
    mean power / sqrt(n)), "bandwidth_hz" (Bendat & Piersol's B_s of the power density),
    "expected_power_W" (linear theory's expected power: for a spread sea weighted over
    directions, `expected_power`)."""
    from ...analysis import record_power_statistics
    amplitude = rms if amplitudes == "random" else wave.amplitude
    stats = record_power_statistics(plant, wave.omega, amplitude, gains,
                                    (wave.ramp_time, duration), amplitudes=amplitudes,
                                    direction=wave.direction)
    n = max(n_valid, 1)
    base = mean_power if isinstance(mean_power, float) and math.isfinite(mean_power) \
        else stats["mean_power_W"]
    expected = stats["mean_power_W"]
    if wave.directional and "spreading" in wave.settings:
        import dataclasses
        expected = expected_power(plant, dataclasses.replace(wave, amplitude=amplitude), gains)
    return {"spectral_cv": stats["cv"], "effective_samples": n * stats["effective_samples"],
            "spectral_stderr_W": stats["cv"] * base / math.sqrt(n),
            "bandwidth_hz": stats["bandwidth_hz"], "expected_power_W": float(expected)}


def expected_power(plant, wave, gains, *, params=None, statespace: bool = False) -> float:
    """Linear theory's mean absorbed power (W) in `wave` over whole repeat periods, with the
    BEM data straight (statespace False) or with the radiation fit the plant steps
    (`analysis.statespace_response` of the model linearised with the law in place). A spread
    sea's (settings with a spreading): the expected power, weighted over directions
    (`directional.spread_power`), not its realisation's one direction per component."""
    from ...analysis import linearize, statespace_response
    from ...analysis import law_params, law_responses
    a2 = np.asarray(wave.amplitude, float) ** 2
    if wave.directional and "spreading" in wave.settings:   # a spread sea: over directions
        from ...analysis import excitation_transfer
        from .directional import spread_power
        outputs = [f"{name}__velocity" for name in gains]
        values = law_params(plant, gains, params)
        sys = linearize(plant, params=values, outputs=outputs) if statespace else None
        G = excitation_transfer(plant, wave.omega, params=values, outputs=outputs, sys=sys)

        def velocities(direction):          # linear in the excitation: one G for all
            F = plant.hydro.excitation_phasor(wave.omega, direction)
            return np.einsum("ohi,ih->io", G, F)
        return spread_power(plant, wave, velocities, [c for c, _ in gains.values()])
    if not statespace:
        responses = law_responses(plant, wave.omega, gains, direction=wave.direction,
                                  params=params)
        return float(sum(0.5 * c * np.sum(a2 * np.abs(responses[n][0]) ** 2)
                         for n, (c, _) in gains.items()))
    outputs = [f"{name}__velocity" for name in gains]
    sys = linearize(plant, params=law_params(plant, gains, params), outputs=outputs)
    V = statespace_response(sys, plant, wave.omega, direction=wave.direction, outputs=outputs)
    return float(sum(0.5 * c * np.sum(a2 * np.abs(V[:, i]) ** 2)
                     for i, (c, _) in enumerate(gains.values())))


def radiation_fit_effect(plant, wave, gains, params=None) -> float:
    """P(fit) / P(BEM) - 1: how much the radiation fit the simulation steps moves a sea's
    linear-theory power, relative (0 for a law that absorbs nothing: a sea the design left
    idle)."""
    bem = expected_power(plant, wave, gains, params=params)
    if bem == 0.0:
        return 0.0
    return expected_power(plant, wave, gains, params=params, statespace=True) / bem - 1.0


def parameter_gradient(plant, wave, gains, names, values: dict, *,
                       scene_law: bool = False) -> np.ndarray:
    """d ln P / d theta (per unit of theta) of a sea's linear-theory power (BEM data) for each
    named plant parameter, by central differences about `values` (relative step STEP): the
    relative sensitivity, applied to the simulated power (a record's power is the expected
    one scaled by its realisation; so is its sensitivity). scene_law: the
    law is the scene PTOs' own (no controller), so a PTO's damping or stiffness parameter
    moves its gains; under a controller those parameters are set aside (no effect)."""
    out = np.zeros(len(names))
    base = expected_power(plant, wave, gains, params=values)
    for j, name in enumerate(names):
        x = float(values[name])
        h = STEP * abs(x) if x else STEP
        power = []
        for value in (x + h, x - h):
            moved = dict(gains)
            pto, _, kind = name.rpartition("__")
            if scene_law and pto in gains and kind in ("damping", "stiffness"):
                c, k = gains[pto]
                moved[pto] = (value, k) if kind == "damping" else (c, value)
            power.append(expected_power(plant, wave, moved, params={**values, name: value}))
        out[j] = (power[0] - power[1]) / (2 * h) / base
    return out
