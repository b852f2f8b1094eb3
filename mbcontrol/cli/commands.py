"""The commands behind `mbcontrol COMMAND` (the parser and `main` are in `mbcontrol.cli`)."""
from __future__ import annotations

import dataclasses
import json
import math
import sys

import numpy as np

from ..errors import InputError
from ..results import jsonable
from .messages import invalid_lines


HYDRO_SCALES = ("__added_mass_scale", "__radiation_scale", "__excitation_scale")


def _plant(args, **kwargs):
    """The model's plant; with hydro corrections when a --param names one (as `mbcontrol
    identify` reports them), so identified values can be simulated."""
    from ..plant import build_plant
    from ..scene import load_scene
    values = dict(_key_value(item, "--scene-param") for item in args.scene_param)
    if any(item.split("=")[0].endswith(HYDRO_SCALES) for item in getattr(args, "param", [])):
        kwargs.setdefault("hydro_corrections", True)
    scene = load_scene(args.model, values or None)
    if getattr(args, "judged_by", None):
        import dataclasses
        scene = dataclasses.replace(scene, hydro=dataclasses.replace(scene.hydro, fit_judged_by=args.judged_by))
    return build_plant(scene, **kwargs)


def run_models(args) -> int:
    from ..scene import list_models, load_scene
    if getattr(args, "name", None):
        from .describe import run_describe
        return run_describe(args)
    for name in list_models():
        print(f"{name:16s} {load_scene(name).description}")
    return 0


def _what_was_read(data) -> dict | None:
    """A third-party BEM file's conversion: the file, the readers' notes (what they found and
    repaired), their repairs and physical checks in detail, and how its bodies were matched to
    the scene's (BEM body -> {"scene_body", "by", "distance_m"}); None for data made by
    mbcontrol's own BEM run."""
    from ..results import record
    if "converted_from" not in data.attrs:
        return None
    return {"file": str(data.attrs["converted_from"]),
            "notes": [str(n) for n in record(data.attrs, "notes", [])],
            "repairs": jsonable(record(data.attrs, "cleaning", {})),
            "body_mapping": jsonable(record(data.attrs, "body_mapping", {}))}


def run_hydro(args) -> int:
    from ..plant import response_error_of
    plant = _plant(args, radiation_tol=args.tol)
    if plant.hydro is None:
        print(f"{plant.name}: no hydrodynamic bodies")
        return 0
    rad, rep = plant.hydro.radiation, plant.hydro.radiation.report
    judged_by = "response" if rep.get("response_error") is not None else "kernel"
    # a kernel-judged fit's response error too, so the two measures can be set side by side
    response = rep.get("response_worst") if judged_by == "response" else response_error_of(plant)
    report = {"model": plant.name, "source": plant.hydro.source, "dofs": list(plant.hydro.dofs),
              "omega_rad_s": [float(plant.hydro.omega[0]), float(plant.hydro.omega[-1])],
              "n_omega": int(plant.hydro.omega.size), "radiation_states": int(rad.order),
              "fit_error": float(rad.fit_error), "judged_by": judged_by, **{k: rep.get(k) for k in (
                  "tol", "tol_met", "response_band", "band_error", "worst", "rms_error", "limited_by")},
              "response_error": response["error"] if response else None, "response_worst": response,
              "max_pole_real_part": float(np.max(np.linalg.eigvals(rad.A).real)), "report": jsonable(rep),
              "read": _what_was_read(plant.hydro.data)}
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(f"{plant.name}: hydro data {report['source']}\n  DOFs ({len(report['dofs'])}): "
              f"{', '.join(report['dofs'])}\n  {report['n_omega']} frequencies, "
              f"{report['omega_rad_s'][0]:.3g}..{report['omega_rad_s'][1]:.3g} rad/s")
        if report["read"]:
            print(f"  read from {report['read']['file']}, as the readers found it:")
            print("\n".join(f"    - {note}" for note in report["read"]["notes"]))
            for body, match in report["read"]["body_mapping"].items():
                if "distance_m" not in match:     # by position: in the notes already
                    print(f"    - BEM body {body!r} is scene body {match['scene_body']!r} (by "
                          f"{match['by']})")
        print(f"  radiation model: {rad.order} states, slowest pole real part {report['max_pole_real_part']:.3g} 1/s")
        if rep.get("response_worst"):
            rw = rep["response_worst"]
            print(f"  response error {rad.fit_error:.2%} (tol {rep['tol']:.2%}{'' if rep['tol_met'] else ', MISSED'}), "
                  f"the device linear at rest with its PTOs free: worst at {rw['omega']:.4g} rad/s, most the {rw['what']}")
        if rep.get("worst"):   # a fit loaded that missed its tolerance has warned already
            wst, (lo, hi) = rep["worst"], rep["response_band"]
            kernel = (f"in {lo:.3g}-{hi:.3g} rad/s at worst {wst['error']:.2%}, {wst['part']} of "
                      f"K[{wst['entry'][0]}, {wst['entry'][1]}] at {wst['omega']:.4g} rad/s; global RMS {rep['rms_error']:.2%}")
            if rep.get("response_worst"):
                print(f"  the kernel's own error (not what judges the fit): {kernel}")
            else:
                print(f"  fit error {rad.fit_error:.2%} (tol {rep['tol']:.2%}{'' if rep['tol_met'] else ', MISSED'}): {kernel}")
                if response:
                    print(f"  its response error (not what judges this fit): {response['error']:.2%} at "
                          f"{response['omega']:.4g} rad/s, most the {response['what']}")
    if args.plot:
        from ..hydro import hydro_figure
        print(f"  figure: {hydro_figure(plant.hydro, args.plot, name=plant.name, fit_omega_max=plant.scene.hydro.fit_omega_max)}",
              file=sys.stderr if args.json else sys.stdout)
    return 0


def _wave(args, plant, duration):
    """The wave the CLI options describe, None for --wave none; notes on stderr a spectrum cut
    by the hydro data's band, and what a record (--wave elevation --eta FILE) left out,
    resampled, ramped or repeated over `duration` (s; None: the record's length)."""
    from ..waves import from_args, from_record
    if args.wave == "none":
        return None
    omega = plant.hydro.omega if plant.hydro is not None else None
    band = (float(omega[0]), float(omega[-1])) if omega is not None else None
    wave = from_record(args.eta, data_band=band, duration=duration) \
        if args.wave == "elevation" else \
        from_args(args.wave, height=args.height, period=args.period, hs=args.hs, tp=args.tp,
                  gamma=args.gamma, seed=args.seed, duration=duration, data_band=band)
    for note in wave.settings.get("notes", ()):
        print(f"mbcontrol: note: {note}", file=sys.stderr)
    headings = plant.hydro.data["wave_direction"].values if plant.hydro is not None else [0.0]
    direction = math.radians(args.direction) if getattr(args, "direction", None) is not None \
        else float(headings[0]) if len(headings) == 1 else 0.0
    wave = dataclasses.replace(wave, direction=direction)
    outside = wave.settings.get("spectrum_outside_data", 0.0)
    if outside > 1e-3:
        print(f"mbcontrol: note: {100 * outside:.2g} % of the spectrum's variance lies outside the "
              f"hydro data ({band[0]:.3g}..{band[1]:.3g} rad/s) and is left out; Hs is kept on the "
              f"rest", file=sys.stderr)
    return wave


def run_simulate(args) -> int:
    from ..analysis import summary
    from ..sim import describe_initial, initial_state, simulate
    plant = _plant(args)
    duration = args.duration
    if args.wave != "none":
        if duration is None and args.wave != "elevation":      # a record: its own length
            duration = 30 * args.period if args.wave == "regular" and args.period else 600.0
    elif duration is None:
        duration = 60.0
    wave = _wave(args, plant, args.repeat or duration)
    if duration is None:
        duration = wave.settings["duration_s"]
    controller = _controller(args, wave)
    params = dict(_key_value(s, "--param") for s in args.param)
    initial = dict(_key_value(s, "--initial", text=True) for s in args.initial)
    ds = simulate(plant, wave, duration=duration, dt=args.dt, controller=controller,
                  method=args.method, rtol=args.rtol, params=params or None,
                  x0=initial_state(plant, initial) if initial else None, progress=not args.json)
    if args.window_from is not None:
        ds.attrs.update(_window(args.window_from, wave, duration))
    result = summary(ds, plant)             # checks the result; the verdict goes into ds.attrs
    result["initial"] = describe_initial(plant, initial)
    if args.out:
        from ..results import save_dataset
        save_dataset(ds, args.out, precision="float32" if args.out_float32 else "float64",
                     every=args.out_every)
    if args.plot:
        from ..plotting import time_series
        names = list(plant.topology.tree.coordinate_names) + [
            f"{p.name}__power" for p in plant.scene.ptos]
        time_series(ds, ["eta"] + names, path=args.plot, labels=_coordinate_labels(plant))
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        _print_summary(result, plant)
    for note in result["validity_warnings"]:
        print(f"mbcontrol: warning: {note}", file=sys.stderr)
    if not result["valid"]:
        print("\n".join(invalid_lines(result["invalid_reasons"], "mbcontrol: ")), file=sys.stderr)
        return 0 if args.allow_invalid else INVALID_EXIT
    return 0


def _coordinate_labels(plant) -> dict:
    """A joint coordinate's label with its direction: "heave (along z, NED: + down)"."""
    labels = {}
    for joint in plant.scene.joints:
        axis = getattr(joint, "axis", None)
        if joint.type not in ("prismatic", "revolute") or axis is None:
            continue
        named = {(1, 0, 0): "x", (0, 1, 0): "y", (0, 0, 1): "z, NED: + down",
                 (-1, 0, 0): "-x", (0, -1, 0): "-y", (0, 0, -1): "-z, NED: + up"}
        key = tuple(int(round(float(a))) for a in axis)
        where = named.get(key, "(" + ", ".join(f"{float(a):.3g}" for a in axis) + ")")
        labels[joint.name] = f"{joint.name} ({'along' if joint.type == 'prismatic' else 'about'} {where})"
    return labels


INVALID_EXIT = 3        # `simulate`'s exit status for a result that failed its physics checks


def _window(given: str, wave, duration: float) -> dict:
    """--from S or last-repeat: the run record's statistics start (s) and why."""
    if given == "last-repeat":
        if wave is None or wave.omega.size < 2 or not wave.d_omega:
            raise InputError("--from last-repeat needs a sea (--wave jonswap or pm): a regular "
                             "wave's statistics are its last 10 periods already")
        repeat = 2 * math.pi / wave.d_omega
        if duration < repeat * (1 - 1e-9):
            raise InputError(f"--from last-repeat: the run ({duration:g} s) is shorter than the "
                             f"sea's repeat period ({repeat:.6g} s); give --duration of at "
                             f"least that, or --repeat")
        return {"statistics_from_s": duration - repeat,
                "statistics_note": f"the last whole repeat period of the sea ({repeat:.4g} s), "
                                   f"as its bounds"}
    try:
        start = float(given)
    except ValueError:
        raise InputError(f"--from {given}: expected seconds or 'last-repeat'") from None
    if not 0 <= start < duration:
        raise InputError(f"--from {given}: expected 0 <= S < the duration ({duration:g} s)")
    return {"statistics_from_s": start, "statistics_note": f"from {start:g} s (--from)"}


def run_bench(args) -> int:
    from ..studies import run_bench as bench
    plant = _plant(args)
    duration = args.duration or (30 * args.period if args.wave == "regular" and args.period
                                 else 600.0)
    wave = _wave(args, plant, duration)
    if wave is None:
        raise InputError("bench needs a wave: --wave regular|jonswap|pm")
    bench(plant.scene, wave, duration=duration, methods=args.methods,
          radiation_tols=args.radiation_tols, stability=args.stability,
          repeats=args.repeats, out=args.out or f"out/bench/{plant.name}")
    return 0


def run_fidelity(args) -> int:
    from ..studies import auto_fidelity
    plant = _plant(args)
    duration = args.duration
    wave = _wave(args, plant, duration or 600.0)
    if wave is None:
        raise InputError("fidelity needs a wave: --wave regular|jonswap|pm")
    report = auto_fidelity(plant.scene, wave, tol=args.tol, duration=duration, progress=True)
    print(report)
    if args.out:
        from ..results import save_dataset
        save_dataset(report.to_dataset(), args.out)
    return 0


def _controller(args, wave=None):
    """The --controller with its --set settings. A controller that takes a `wave` (a
    predictive controller's preview) is handed the simulated one, as `design` does."""
    if not args.controller:
        if args.set:
            raise InputError("--set needs --controller")
        return None
    import inspect

    from mbcontrol.controllers import REGISTRY, make
    cls = REGISTRY.get(args.controller)
    signature = inspect.signature(cls).parameters if cls is not None else {}
    settings = parse_settings(args.set, signature)
    if wave is not None and cls is not None and "wave" in inspect.signature(cls).parameters:
        settings.setdefault("wave", wave)
    _warn_if_absorbs_nothing(args.controller, settings)
    return make(args.controller, **settings)


def _warn_if_absorbs_nothing(name, settings, varied=()) -> str | None:
    """Warn on stderr (also under --json and -q: it explains a result) when a named law
    absorbs nothing."""
    import sys

    from mbcontrol.controllers import absorbs_nothing
    why = absorbs_nothing(name, settings, varied)
    if why:
        print(f"mbcontrol: warning: {why}", file=sys.stderr)
    return why


def parse_settings(items, signature) -> dict:
    """--set KEY=VALUE items as a controller's settings: numbers, true/false, none, or words
    (for a setting that takes text, e.g. forecast=ar). KEY.PTO=VALUE sets one PTO's value
    (a dict by PTO name, e.g. damping.pto1=3.5). A word for a numeric setting is an error (a
    key the controller does not take, or an unknown PTO, is named by the controller)."""
    settings = {}
    for item in items:
        if "=" not in item:
            raise InputError(f"--set expects KEY=VALUE, got {item!r}")
        key, text = (part.strip() for part in item.split("=", 1))
        key, _, pto = key.partition(".")
        value = _setting_value(text)
        # text only for a setting that is text (a choice), so a typo in a number is caught
        if isinstance(value, str) and not _takes_text(signature.get(key)):
            raise InputError(f"--set {key}: expected a number, true/false or none, got {text!r}")
        if not pto:
            settings[key] = value
        elif not isinstance(settings.setdefault(key, {}), dict):
            raise InputError(f"--set {key}.{pto}: {key} was already set for every PTO")
        else:
            settings[key][pto] = value
    return settings


def _setting_value(text: str):
    """'2.5' -> 2.5, '3' -> 3.0, 'true'/'false' -> bool, 'none' -> None, else the word."""
    lowered = text.lower()
    if lowered in ("true", "false"):
        return lowered == "true"
    if lowered in ("none", "null"):
        return None
    try:
        return float(text)
    except ValueError:
        if not text:
            raise InputError("--set: empty value") from None
        return text


def _takes_text(parameter) -> bool:
    """Does a controller setting take text: a str default or a str annotation?"""
    if parameter is None:
        return False
    return isinstance(parameter.default, str) or "str" in str(parameter.annotation)


def _key_value(item: str, flag: str, text: bool = False):
    """(key, float value); with text, a value that is not a number stays a string (a
    controller's choice such as --set forecast=ar)."""
    if "=" not in item:
        raise InputError(f"{flag} expects KEY=VALUE, got {item!r}")
    key, value = item.split("=", 1)
    try:
        return key.strip(), float(value)
    except ValueError:
        if text and value.strip():
            return key.strip(), value.strip()
        raise InputError(f"{flag} {key}: expected a number, got {value!r}") from None


def _print_summary(result: dict, plant) -> None:
    from ..analysis import tension_lines
    print(f"{result['model']}: {result['duration_s']:.4g} s simulated in "
          f"{result['wall_time_s']:.3g} s ({result['method']}, dt = {result['dt_s']} s)")
    for name, start in result.get("initial", {}).items():
        print(f"  from {name} = {start['value']:.4g} {start['unit']}, {start['direction']}")
    for body, values in result["bodies"].items():
        print(f"  {body}: heave amplitude {values['heave_amplitude_m']:.4g} m, pitch amplitude "
              f"{values['pitch_amplitude_rad']:.4g} rad")
    for pto, values in result["ptos"].items():
        print(f"  {pto}: mean absorbed power {values['mean_power_W']:.4g} W, max force "
              f"{values['max_force']:.4g} {plant.units(pto)}, max stroke "
              f"{values['max_stroke']:.4g} {plant.units(pto + '__position')}")
    checks = result.get("validity", {})
    if "bound_W" in checks:
        bound = checks["bound_W"]
        print(f"  complex-conjugate bound of this wave {bound:.4g} W (all PTOs, linear theory)"
              if bound is not None and math.isfinite(bound) else
              "  complex-conjugate bound of this wave: unbounded (a component excites a PTO "
              "where the hydro data give it no radiation damping)")
    for text in tension_lines(result.get("moorings", {})):
        print("  " + text)
    if result.get("estimator"):
        print(f"  excitation estimate error {100 * result['estimator']['excitation_error']:.3g} %"
              f" (RMS, against the simulation's true excitation)")
    bounded = checks.get("bound_W") is not None and math.isfinite(checks["bound_W"])
    print(f"  result: valid ({'bound, ' if bounded else ''}energy balance, linear-hydrodynamics "
          f"range checked{'' if bounded else '; no finite bound to check against'})"
          if result["valid"] else "\n".join(invalid_lines(result["invalid_reasons"])))
