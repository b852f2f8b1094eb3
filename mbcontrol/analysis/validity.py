"""Is a simulated result one a user can stake a project on? Checks against physics.

Every result the toolbox reports (simulate, design, sweep, identification's forward runs) is
checked here before it is printed, stored or averaged; a failed check marks it invalid, with
its reasons. The checks, each independent of the time-domain model that made the numbers:

1. **Power bound.** The PTOs' mean absorbed power over the metrics window may not exceed the
   multiport complex-conjugate bound of the run's own wave (`analysis.ports`: linear theory
   straight from the BEM data, every PTO free) by more than POWER_ALLOWANCE. When it exceeds
   the spectral bound, the bound is recomputed for this realisation over the same window
   (a finite record does not average the cross terms between components out: +3.5 % on
   rm3, Hs 2 m, Tp 9 s, 600 s) and the larger is used. The allowance (10 %) covers what
   linear theory leaves out that a nonlinear plant may show, and energy stored at the
   window's edges; an unstable or non-causal run overshoots by orders of magnitude.
2. **Energy balance.** Over the record, the work the PTOs absorb cannot exceed the work the
   wave excitation did minus the mechanical energy gained: radiation (passive, from rest),
   friction, drag and mooring damping only remove energy. ENERGY_TOLERANCE of the
   excitation's absolute work absorbs time-discretisation error.
3. **Validity of linear hydrodynamics.** A surface-piercing body's significant motion
   relative to the free surface at its position (twice its standard deviation over the
   window, the significant amplitude, as Hs / 2 is the sea's) may not exceed its mean draft
   (in a regular wave, its amplitude) (displaced volume over waterplane area: beyond it the body leaves the water or buries
   its deck, and constant added mass, damping and waterplane stiffness no longer describe
   it); roll and pitch likewise within "validity.angle_max" (30 deg). The verdict is on a mean over
   the record, so it is the typical motion that decides; a peak beyond the limit is
   reported as a warning (with the share of time spent there), not an invalid result.
4. **Statistics window.** The window the statistics are read over may not overlap the wave's
   ramp or the controller's warm-up and must hold "stats.min_periods" (10) wave periods: a mean
   over a transient is not the steady answer (the sphere in a regular 8 s wave with damping
   6e5: 4.8 kW over a 10 s run, 56 kW over 30 s, 93.5 kW steady). The reason names the
   shortest duration that works.
5. **Sampled loop.** A controller with a period whose held linear loop is unstable at rest
   (attrs["sampled_loop"], from mbcontrol.sim.sampled before the run) makes the result
   invalid: what it shows is a transient of a diverging loop, however short the record.

`assess` works on a Dataset from `mbcontrol.sim.simulate` and writes the verdict into its
attrs; `assess_values` works on plain numbers, for callers that keep no Dataset;
`simulate_checked` simulates and assesses in one call, to a Dataset (`mbcontrol.simulate` makes
the same checks and returns a `mbcontrol.Result`).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import defaults
from ..plant import derived
from ..results import jsonable, record

# POWER_ALLOWANCE and ENERGY_TOLERANCE: the defaults "validity.power_allowance" (share above
# the bound a reported mean power may reach) and "validity.energy_tolerance" (of the
# excitation's absolute work over the record)
# ANGLE_MAX_RAD and DRAFT_FACTOR: the defaults "validity.angle_max" (rad, roll and pitch) and
# "validity.draft_factor" (the relative heave limit in mean drafts)

# [hydro] hydrostatics = "large_angle" in waves: said with every result it makes
LARGE_ANGLE_IN_WAVES = (
    "large-angle hydrostatics in waves pairs exact buoyancy (in calm water) with linear "
    "Froude-Krylov forces (the incident pressure on the body at rest): not a consistent pair "
    "once the motions are large, and in a published sphere case it moved the heave response "
    "further from the nonlinear reference than the linear model did. It is right for free "
    "decays (--wave none). The consistent pair: [hydro] hydrostatics = \"nonlinear\" and "
    "froude_krylov = \"nonlinear\"")

# every reason a result is INVALID ends with what to do about it, after REMEDY (the CLI prints
# it on a line of its own; no ";" in a remedy: a sweep joins a case's reasons with "; ")
REMEDY = ". Remedy: "
REMEDIES = {
    "bound": "a smaller time step (--dt) or a tighter radiation fit ([hydro] radiation_tol): "
             "`mbcontrol bench MODEL` shows each method's error",
    "energy": "a smaller time step (--dt) or another method (--method: `mbcontrol bench "
              "MODEL` compares them)",
    "range": "the model that covers large motions: [hydro] hydrostatics = \"nonlinear\" and "
             "froude_krylov = \"nonlinear\" in the scene (the incident pressure over the "
             "instantaneous wetted surface: mbcontrol.plant.nonlinear), or a smaller sea, or a "
             "stroke limit on the PTO (its stroke_max, or --set stroke_max=...), or "
             "--allow-invalid to see the number anyway",
}


def split_remedy(reason: str) -> tuple[str, str | None]:
    """(what failed, what to do) of an INVALID reason; None when it names no remedy."""
    what, _, remedy = reason.partition(REMEDY)
    return what, remedy or None


def left_linear_range(reasons) -> bool:
    """Whether any of a verdict's INVALID reasons is that the motions left the linear range
    (the reason whose remedy is the nonlinear model, REMEDIES["range"])."""
    return any(split_remedy(r)[1] == REMEDIES["range"] for r in reasons)


RESPONSE_GRIDS_KEPT = 256         # (params, direction, frequency grid) a plant keeps responses for


def wave_of(ds):
    """The wave a Dataset was simulated in, rebuilt from the components it records (None for
    still water or a Dataset that does not record them)."""
    from ..waves import Wave
    if "wave_omega" not in ds:
        return None
    desc = record(ds.attrs, "wave", {})
    # a spread sea records each component's direction; its description holds only the mean
    direction = ds["wave_direction"].values if "wave_direction" in ds else \
        float(desc.get("direction_rad", 0.0))
    return Wave(desc.get("type", "components"), ds["wave_omega"].values,
                ds["wave_amplitude"].values, ds["wave_phase"].values,
                direction=direction,
                ramp_time=float(desc.get("ramp_s", 0.0)),
                d_omega=ds["wave_omega"].attrs.get("d_omega"))


UNBOUNDED = ("the complex-conjugate bound of this wave is unbounded: some of its components "
             "excite a PTO at frequencies where the hydro data give no radiation damping (BEM data "
             "repaired to zero, or past the mesh's range), so the power was not checked against a "
             "bound; cut the sea's band, or extend the data")


def power_bound(plant, wave, params, window=None) -> dict:
    """{"bound_W": spectral multiport bound, "window_bound_W": the same over `window` (s)
    for this realisation, or None when not asked}. Cached per plant, parameters, direction
    and frequency grid (seeds of one sea share it)."""
    from .ports import multiport_bound, port_responses, window_mean_power
    p = np.asarray(params, float)
    kept = derived(plant, ("analysis.port_responses",), dict)
    key = (p.tobytes(), np.asarray(wave.direction, float).tobytes(),
           np.asarray(wave.omega).tobytes())
    if key not in kept:
        if len(kept) > RESPONSE_GRIDS_KEPT:
            kept.clear()
        names = [pto.name for pto in plant.scene.ptos]
        kept[key] = port_responses(plant, wave.omega, names, wave.direction,
                                   dict(zip(plant.parameters, p)))
    bound = multiport_bound(plant, wave, responses=kept[key])
    out = {"bound_W": bound.power, "window_bound_W": None}
    if window is not None:
        out["window_bound_W"] = window_mean_power(bound, *window)
    return out


def assess_values(plant, wave, params, *, window, mean_power_W: float, energy=None,
                  excursions=None) -> dict:
    """The verdict on one run from its numbers.

    window: (start, end) s of the metrics; mean_power_W: the PTOs' total mean absorbed power
    over it (W); energy: (excitation work, PTO absorbed work, mechanical energy gained,
    absolute excitation work) over the record (J; `energy_record`), or None (not checked);
    excursions: per body, what `excursions` returns. Returns {"valid", "invalid_reasons",
    "warnings", "checks"}.
    """
    share = defaults.get("validity.power_allowance")
    reasons, checks = [], {"power_allowance": share}
    if wave is not None and plant.hydro is not None and plant.scene.ptos:
        bound = power_bound(plant, wave, params)
        allowed = (1 + share) * bound["bound_W"]
        if mean_power_W > allowed:          # a finite record may beat the spectral mean
            bound = power_bound(plant, wave, params, window)
            allowed = (1 + share) * max(bound["bound_W"], bound["window_bound_W"])
        checks.update(bound, allowed_power_W=allowed, mean_power_W=mean_power_W)
        if mean_power_W > allowed:
            reasons.append(
                f"mean absorbed power {_watts(mean_power_W)} exceeds the complex-conjugate "
                f"bound of its wave ({_watts(bound['bound_W'])}; allowed "
                f"{_watts(allowed)} with {share:.0%} for finite records and "
                f"nonlinear terms): no controller can absorb that{REMEDY}{REMEDIES['bound']}")
    if energy is not None:
        exc, absorbed, gained, magnitude = energy
        slack = defaults.get("validity.energy_tolerance") * magnitude
        checks["energy_J"] = {"excitation_work": exc, "pto_work": absorbed, "gained": gained,
                              "tolerance": slack}
        if absorbed > exc - gained + slack:
            reasons.append(
                f"energy balance: the PTOs absorbed {absorbed:.4g} J while the waves did "
                f"{exc:.4g} J of work and the device gained {gained:.4g} J"
                f"{REMEDY}{REMEDIES['energy']}")
    warnings = []
    nonlinear = plant.scene.hydro.froude_krylov == "nonlinear"
    for body, e in (excursions or {}).items():
        angle_max = defaults.get("validity.angle_max")
        limits = (("relative heave", "relative_heave", e.get("relative_heave_limit_m"), "m", 1.0),
                  ("roll", "roll", angle_max, "deg", 180 / math.pi),
                  ("pitch", "pitch", angle_max, "deg", 180 / math.pi))
        for what, key, limit, unit, scale in limits:
            if limit is None or f"{key}_significant" not in e:
                continue
            limit = (defaults.get("validity.draft_factor") * limit if key == "relative_heave"
                     else limit)
            where = "beyond its mean draft" if key == "relative_heave" else "beyond"
            if e[f"{key}_significant"] > limit and nonlinear:
                warnings.append(
                    f"body {body!r}: significant {what} {e[f'{key}_significant'] * scale:.3g} "
                    f"{unit}, {where} ({limit * scale:.3g} {unit}): hydrostatics and "
                    f"Froude-Krylov forces are nonlinear here, radiation and diffraction "
                    f"linear (approximate at such motions)")
            elif e[f"{key}_significant"] > limit:
                reasons.append(
                    f"body {body!r}: significant {what} {e[f'{key}_significant'] * scale:.3g} "
                    f"{unit}, {where} ({limit * scale:.3g} {unit}): linear hydrodynamics do "
                    f"not hold there{REMEDY}{REMEDIES['range']}")
            elif e[f"{key}_max"] > limit:
                warnings.append(
                    f"body {body!r}: {what} peaks at {e[f'{key}_max'] * scale:.3g} {unit}, "
                    f"{where} ({limit * scale:.3g} {unit}) {100 * e[f'{key}_share_beyond']:.2g} "
                    f"% of the time; linear hydrodynamics are approximate there")
    checks["excursions"] = excursions or {}
    if not math.isfinite(checks.get("bound_W", 0.0)):
        warnings.append(UNBOUNDED)
    return {"valid": not reasons, "invalid_reasons": reasons, "warnings": warnings,
            "checks": checks}


def excursions(plant, ds, wave, mask) -> dict:
    """Per body with hydro data, over the samples in `mask`: its mean draft V / A_wp
    (relative_heave_limit_m; None for a submerged body) and, for its heave relative to the
    free surface at its centre of buoyancy (m, surface-piercing bodies only), roll and pitch
    (rad): the significant amplitude (2 std; in a regular wave the amplitude), the largest |value| and the share of samples
    beyond the limit (`<key>_significant`, `<key>_max`, `<key>_share_beyond`)."""
    if plant.hydro is None:
        return {}
    data = plant.hydro.data
    if "body" not in data.coords:
        return {}
    t = ds["time"].values
    out, surface = {}, {}                   # surface: elevation at a point, once per point
    for body in map(str, data["body"].values):
        if f"{body}__Heave" not in ds:
            continue
        limit = mean_draft(data, body)
        entry = {"relative_heave_limit_m": limit}
        signals = {key: ds[f"{body}__{name}"].values[mask] for key, name in
                   (("roll", "Roll"), ("pitch", "Pitch"))}
        if limit is not None:
            up = -(ds[f"{body}__Heave"].values[mask] - ds[f"{body}__Heave"].values[0])
            if wave is not None:
                cob = data["center_of_buoyancy"].sel(body=body).values
                point = (float(cob[0]), float(cob[1]))
                if point not in surface:
                    surface[point] = _elevation_at(plant, wave, t, *point)[mask]
                up = up - surface[point]
            signals["relative_heave"] = up
        regular = wave is not None and np.size(wave.omega) == 1
        for key, x in signals.items():
            bound = limit if key == "relative_heave" else defaults.get("validity.angle_max")
            # a sea's significant amplitude is 2 std (Rayleigh peaks); a regular wave's is
            # its amplitude
            entry[f"{key}_significant"] = float(np.max(np.abs(x)) if regular else 2 * np.std(x))
            entry[f"{key}_max"] = float(np.max(np.abs(x)))
            entry[f"{key}_share_beyond"] = float(np.mean(np.abs(x) > bound))
        out[body] = entry
    return out


def mean_draft(data, body: str):
    """A body's mean draft V / A_wp (m) from its hydro data, where linear hydrodynamics hold;
    None for a submerged body (no waterplane) or data without hydrostatics."""
    if "waterplane_area" not in data or "displaced_volume" not in data:
        return None
    area = float(data["waterplane_area"].sel(body=body))
    volume = float(data["displaced_volume"].sel(body=body))
    if area <= 1e-6 * max(volume, 1e-12) ** (2 / 3):
        return None                        # submerged: no waterline to leave
    return volume / area


def _elevation_at(plant, wave, t, x: float, y: float) -> np.ndarray:
    """Wave elevation (m, up) at the n-frame point (x, y) at times t (s)."""
    return wave_at(plant, wave, x, y).elevation(t)


def wave_at(plant, wave, x: float, y: float):
    """The wave as seen at the n-frame point (x, y): its elevation() is the surface there
    (m, up): the origin's components delayed by the phase k (x cos beta + y sin beta), k from
    the dispersion relation in the scene's depth."""
    from ..waves import wavenumber
    if x == 0.0 and y == 0.0:
        return wave
    water = plant.scene.water
    omega = np.atleast_1d(np.asarray(wave.omega, float))
    k = omega ** 2 / water.g if not math.isfinite(water.depth) else np.array(
        [wavenumber(float(w), water.depth, water.g) for w in omega])
    shift = k * (x * np.cos(wave.direction) + y * np.sin(wave.direction))
    return dataclasses.replace(wave, phase=np.asarray(wave.phase) - shift)


def energy_record(plant, ds):
    """(excitation work, PTO absorbed work, mechanical energy gained, |excitation| work) over
    the whole record (J), or None when the plant's energy is not audited (catenary)."""
    from .metrics import step_power
    col = set(ds.data_vars)
    if "energy" not in col or "excitation_power" not in col or any(
            m.kind == "catenary" for m in plant.scene.moorings):
        return None
    t = ds["time"].values
    p_exc = ds["excitation_power"].values
    exc = float(np.trapezoid(p_exc, t))
    magnitude = float(np.trapezoid(np.abs(p_exc), t))
    absorbed = 0.0
    for pto in plant.scene.ptos:
        t_k, p_k = step_power(ds, pto.name)
        absorbed += float(np.sum(p_k * np.diff(t)))
    gained = float(ds["energy"].values[-1] - ds["energy"].values[0])
    return exc, absorbed, gained, magnitude


def assess(ds, plant, wave=None, *, mean_power_W: float | None = None) -> dict:
    """Check a simulated Dataset (see the module doc); the verdict goes into ds.attrs
    ("valid": 1/0, "invalid_reasons", "validity_warnings" and "validity") and is returned. mean_power_W:
    the PTOs' total over the metrics window when the caller has it already (W)."""
    from .metrics import analysis_window, pto_metrics, statistics_window
    wave = wave if wave is not None else wave_of(ds)
    window = statistics_window(ds)
    if np.count_nonzero(ds["time"].values >= window["start_s"] - 1e-9) < 2:
        verdict = {"valid": False, "invalid_reasons": [_window_reason(window)], "warnings": [],
                   "checks": {"window": _window_check(window)}}      # nothing to check over
        mark(ds, verdict)
        return verdict
    mask = analysis_window(ds)
    t = ds["time"].values[mask]
    power = mean_power_W if mean_power_W is not None else sum(
        pto_metrics(ds, pto)["mean_power_W"] for pto in plant.scene.ptos)
    ran_with = record(ds.attrs, "parameters")
    params = np.array([ran_with[name] for name in plant.parameters])
    verdict = assess_values(plant, wave, params, window=(float(t[0]), float(ds["time"][-1])),
                            mean_power_W=power, energy=energy_record(plant, ds),
                            excursions=excursions(plant, ds, wave, mask))
    verdict["checks"]["window"] = _window_check(window)
    if plant.scene.hydro.hydrostatics == "large_angle" and wave is not None and \
            np.any(np.asarray(wave.amplitude) > 0):
        verdict["warnings"].append(LARGE_ANGLE_IN_WAVES)
    if window["problem"] is not None:
        verdict["valid"] = False
        verdict["invalid_reasons"].append(_window_reason(window))
    _field_ranges(ds, verdict)
    loop = record(ds.attrs, "sampled_loop")
    if loop is not None and not loop["stable"]:       # sim.sampled, checked before the run
        verdict["valid"] = False
        verdict["invalid_reasons"].append(f"sampled control loop: {loop['message']}")
    if loop is not None:
        verdict["checks"]["sampled_loop"] = loop
    mark(ds, verdict)
    return verdict


def _field_ranges(ds, verdict: dict) -> None:
    """Nonlinear Froude-Krylov bodies that left the box their incident field's series cover
    (mbcontrol.plant.nonlinear.field_range above 1), where the series held their edge values."""
    for name in (n for n in ds.data_vars if str(n).endswith("__field_range")):
        used = float(np.max(ds[name].values))
        verdict["checks"][name] = used
        if used > 1.0:
            body = str(name)[:-len("__field_range")]
            verdict["valid"] = False
            verdict["invalid_reasons"].append(
                f"body {body!r} left the region its nonlinear incident field covers ({used:.3g} "
                f"of it): the Froude-Krylov series held their edge values there{REMEDY}a larger "
                f"[hydro] nonlinear_reach (the horizontal excursion and sinking the field covers), "
                f"or an end stop on a joint whose body swings into the sea bed (the field ends "
                f"there)")


def _window_check(window: dict) -> dict:
    return {k: window[k] for k in ("start_s", "end_s", "periods", "shortest_duration_s")}


def _window_reason(window: dict) -> str:
    return (f"{window['problem']}: its numbers are of a transient, not the steady response{REMEDY}"
            f"simulate at least {math.ceil(window['shortest_duration_s'])} s (--duration)")


def simulate_checked(plant, wave=None, **options):
    """`mbcontrol.sim.simulate`, then `assess`: the Dataset carries its verdict in its attrs
    ("valid", "invalid_reasons", "validity"), and an invalid result warns (RuntimeWarning)
    with its reasons. `mbcontrol.simulate` makes the same checks and returns a Result."""
    import warnings

    from ..sim import simulate
    ds = simulate(plant, wave, **options)
    verdict = assess(ds, plant, wave)
    if not verdict["valid"]:
        warnings.warn(f"{plant.name}: the result failed its physics checks: "
                      + "; ".join(verdict["invalid_reasons"]), RuntimeWarning, stacklevel=2)
    return ds


def mark(ds, verdict: dict) -> None:
    """Write a verdict into a Dataset's attrs (Python values: mbcontrol.results encodes them in
    a file)."""
    ds.attrs["valid"] = int(verdict["valid"])
    ds.attrs["invalid_reasons"] = list(verdict["invalid_reasons"])
    ds.attrs["validity_warnings"] = list(verdict.get("warnings", []))
    ds.attrs["validity"] = jsonable(verdict["checks"])


def _watts(value: float) -> str:
    for scale, unit in ((1e6, "MW"), (1e3, "kW"), (1.0, "W")):
        if abs(value) >= scale:
            return f"{value / scale:.4g} {unit}"
    return f"{value * 1e3:.4g} mW"
