"""`mbcontrol design`: tune a controller, check and bound it, simulate it, print how to re-run it."""
from __future__ import annotations

import json
import math
import sys

from ..errors import InputError
from .commands import _plant, _wave
from .messages import invalid_lines


def add_design_flags(p) -> None:
    """design's flags of the margins and the loop's figures."""
    p.add_argument("--aggressive", action="store_true",
                   help="reactive: the unconstrained optimum, near the stability edge (by\n"
                        "default a law is tuned within the margins design.gain_margin_min and\n"
                        "design.phase_margin_min_deg of `mbcontrol defaults`: 2 and 30 deg)")
    p.add_argument("--robust", action="store_true",
                   help="accepted for old scripts: tuning within the margins is the default")
    p.add_argument("--bode", metavar="FILE.png",
                   help="write the designed linear law's loop L(i omega), gain and phase\n"
                        "margins marked (python-control's conventions)")
    p.add_argument("--nyquist", metavar="FILE.png",
                   help="write the designed linear law's Nyquist plot, margins marked")


def design_wave(args, plant, what: str = "design"):
    """(wave, repeat s): the wave `design` tunes for, and `export` too, so that both tune the
    same law: a sea's components spaced 2 pi / repeat with repeat = --duration or 600 s (the
    spacing moves a sea's tuned law: sphere, Hs 2 m, Tp 8 s, 600 s against 200 s: damping
    243 against 224 kN s/m), a record over --duration (None: its own length)."""
    if args.wave == "none":
        raise InputError(f"{what} needs a wave to tune for: --wave regular|jonswap|pm")
    repeat = args.duration or 600.0          # a sea's repeat period, s (its components' spacing)
    return _wave(args, plant, args.duration if args.wave == "elevation" else repeat), repeat


def run_design(args) -> int:
    from mbcontrol.studies.design import design
    plant = _plant(args)
    wave, repeat = design_wave(args, plant)
    result = design(plant, wave, args.controller, pto=args.pto, simulate_s=args.duration,
                    dt=args.dt, bounds={"auto": True, "full": "full", "off": False}[args.bounds],
                    limits=not args.unconstrained, robust=not args.aggressive)
    command = _simulate_command(args, result, repeat)
    figures = _loop_figures(args, result)
    if args.json:
        print(json.dumps({**result.to_dict(), "model": plant.name, "wave": wave.describe(),
                          "simulate_command": command, "figures": figures}, indent=2,
                         allow_nan=False))
    else:
        _print_design(plant, wave, result, command)
        for kind, path in figures.items():
            print(f"{kind} plot of the loop written to {path}")
    checked = [] if result.simulation is None else \
        result.simulation["summary"].get("validity_warnings", [])
    for note in dict.fromkeys([*result.warnings, *checked]):   # as `simulate` warns, once
        print(f"mbcontrol: warning: {note}", file=sys.stderr)
    return 0


def _loop_figures(args, result) -> dict:
    """--bode / --nyquist: the designed linear law's loop with its margins marked
    (controllers.loop_plots); {"bode": path, "nyquist": path} of those written."""
    wanted = {k: getattr(args, k, None) for k in ("bode", "nyquist")}
    wanted = {k: v for k, v in wanted.items() if v}
    if not wanted:
        return {}
    if result.margins is None or result.margins.loop is None:
        raise InputError(f"--{'/--'.join(wanted)}: {result.name} is not a linear law (passive "
                         f"or reactive), so it has no loop transfer to plot")
    from mbcontrol.controllers import loop_bode, loop_nyquist
    draw = {"bode": loop_bode, "nyquist": loop_nyquist}
    for kind, path in wanted.items():
        draw[kind](result.margins, path=path)
    return wanted


def _robustness_line(result) -> str:
    """How the law stands against the floors, and how it was tuned."""
    r = result.tuner["robustness"]
    f = r["floors"]
    how = ""
    from mbcontrol.controllers import REGISTRY
    if REGISTRY[result.name].floors:          # a law tuned within the floors when robust
        how = (" tuned within them (--aggressive: the unconstrained optimum);"
               if result.tuner.get("robust") else " the unconstrained optimum (--aggressive);")
        cost = result.tuner.get("margins_cost") or {}
        if cost.get("share") is not None:     # below 1e-4: the optimum meets them already
            share = f"{100 * cost['share']:.3g} %" if cost["share"] > 1e-4 else "nothing"
            how += (f" they cost {share} of the unconstrained optimum's "
                    f"{_power(cost['aggressive_predicted_W'])} predicted;")
    signed = r.get("phase_margin_signed_deg")
    pc = "" if signed is None else f", python-control's signed phase margin {signed:+.3g} deg"
    gm = "inf" if r["gain_margin"] is None else f"{r['gain_margin']:.3g}"
    pm = "inf" if r["phase_margin_deg"] is None else f"{r['phase_margin_deg']:.3g} deg"
    return (f"  robustness (floors: gain margin {f['gain_margin']:g}, phase margin "
            f"{f['phase_margin_deg']:g} deg; `mbcontrol defaults` design.*):{how} gain margin "
            f"{gm}, phase margin {pm}{pc}: {r['why']}")


def _unbounded(result) -> bool:
    """Is the wave's complex-conjugate bound infinite: as the tuner's share found it (a
    linear law), else as the closed-loop run's validity check did (simulate's criterion)?"""
    cc = (result.tuner.get("share") or {}).get("complex_conjugate_W")
    if cc is not None:
        return math.isinf(cc)
    checks = {} if result.simulation is None else result.simulation["summary"]["validity"]
    return "bound_W" in checks and not _finite(checks["bound_W"])


def _finite(value) -> bool:
    return value is not None and math.isfinite(value)


def _simulate_command(args, result, repeat: float) -> str:
    """The `mbcontrol simulate` command line that re-runs the design's simulation and scores it
    as design did: the same sea (its repeat period `repeat`, s, when the run is longer) and the
    same statistics window; numbers in repr form, which round-trips a float exactly, except
    duration, step and repeat period: 12 significant digits (289.992, not
    289.99199999999996: the same steps)."""
    import shlex
    words = ["mbcontrol", "simulate", args.model]
    for item in args.scene_param:
        words += ["--scene-param", item]
    words += ["--wave", args.wave]
    if args.wave == "regular":
        words += ["--height", repr(args.height), "--period", repr(args.period)]
    elif args.wave == "elevation":          # the record repeats over its own length
        words += ["--eta", args.eta]
    else:
        words += ["--hs", repr(args.hs), "--tp", repr(args.tp), "--seed", str(args.seed)]
        if args.wave == "jonswap":
            words += ["--gamma", repr(args.gamma)]
    sim = result.simulation
    if sim is not None:
        words += ["--duration", f"{sim['duration_s']:.12g}", "--dt", f"{sim['dt_s']:.12g}"]
        if args.wave in ("jonswap", "pm") and abs(sim["duration_s"] - repeat) > 1e-9 * repeat:
            words += ["--repeat", f"{repeat:.12g}"]
        if "repeat period" in sim["summary"]["window"]:      # scored as its bounds are
            words += ["--from", "last-repeat"]
    words += ["--controller", result.name]
    for key, value in result.parameters.items():
        items = value.items() if isinstance(value, dict) else [(None, value)]
        for pto, v in items:          # per-PTO values as KEY.PTO=VALUE
            words += ["--set", f"{key}{'' if pto is None else '.' + pto}={_tidy(v)}"]
    return shlex.join(words)


def _power(value) -> str:
    if value is None:
        return "n/a"
    for scale, unit in ((1e6, "MW"), (1e3, "kW"), (1.0, "W"), (1e-3, "mW")):
        if abs(value) >= scale or scale == 1e-3:
            return f"{value / scale:.4g} {unit}"


def _print_design(plant, wave, result, command) -> None:
    F = plant.units(f"{result.pto}__force")
    X = plant.units(f"{result.pto}__position")
    units = {"damping": f"{F} s/{X}", "stiffness": f"{F}/{X}", "force_max": F, "stroke_max": X,
             "rate_max": f"{F}/s"}
    s = wave.settings
    sea = (f"a regular wave (H {s['height']:.6g} m, T {s['period']:.6g} s)"
           if wave.kind == "regular" else
           f"the record {s['source']} ({s['duration_s']:.6g} s; Hs {s['hs_m']:.4g} m, Tp "
           f"{s['tp_s']:.4g} s)" if wave.kind == "record" else
           f"a {wave.kind.upper()} sea (Hs {s['hs']:.6g} m, Tp {s['tp']:.6g} s, seed {s['seed']})")
    print(f"{plant.name}: {result.name} control of PTO {result.pto!r} designed for {sea}")
    print("  parameters:")
    for key, value in result.parameters.items():
        print(f"    {key} = {_tidy(value)} {units.get(key, 's')}")
    print(f"  predicted (linear theory): {_power(result.predicted_power_W)}")
    if "other_ptos" in result.tuner:
        print(f"  other PTOs: {result.tuner['other_ptos']}")
    if "simulated_power_W" in result.tuner:
        print(f"  tuner's own simulation: {_power(result.tuner['simulated_power_W'])}")
    if result.margins is not None:
        print(f"  stability: {result.margins.message}")
    if "robustness" in result.tuner:
        print(_robustness_line(result))
    if "share" in result.tuner:
        print(f"  why this share: {result.tuner['share']['why']}")
    b = result.bound
    limits = f"|F| <= {b['force_max']:.4g} {F}, |x| <= {b['stroke_max']:.4g} {X}"
    constrained = (_power(b["constrained_W"]) if b["constrained_W"] is not None
                   else f"n/a ({b['constrained_reason']})")
    reference = b.get("constrained_kind") == "reference"   # not a bound on what was simulated
    if reference:
        constrained += " (a reference, not a bound: see below)"
    conjugate = "unbounded" if _unbounded(result) else _power(b["complex_conjugate_W"])
    print(f"  bounds: complex-conjugate {conjugate}; constrained "
          f"({limits}) {constrained}")
    if reference:
        print(f"    why a reference: {b['constrained_kind_reason']}")
    if b.get("electrical_W") is not None:
        within = ("within the force and stroke limits" if b.get("electrical_within_limits")
                  else "no limits")
        print(f"  electrical bound (drivetrain model, linear theory, {within}): "
              f"{_power(b['electrical_W'])}")
    if b.get("total_complex_conjugate_W") is not None:
        print(f"  bound on all PTOs together (multiport complex-conjugate): "
              f"{_power(b['total_complex_conjugate_W'])}")
    _print_simulated(result, F, X)
    if result.envelope_lifted is not None:
        _print_lifted(result.envelope_lifted, units)
    print(f"  re-run: {command}")


def _print_simulated(result, F: str, X: str) -> None:
    """The closed-loop run's lines: power against each finite bound, peaks, verdict."""
    b, m = result.bound, result.metrics
    if m is None:
        print("  not simulated (see the warning)")
        return
    sim = result.simulation
    pct = result.percent_of_bound
    kind = {"constrained": "reference" if b.get("constrained_kind") == "reference"
            else "bound"}
    share = ", ".join(f"{v:.1f} % of the {k.replace('_', '-')} {kind.get(k, 'bound')}"
                      for k, v in pct.items() if v is not None and k != "electrical") \
        or "no finite bound to set it against"
    print(f"  simulated ({sim['duration_s']:.4g} s, dt {sim['dt_s']:.4g} s, nonlinear plant): "
          f"mean absorbed power {_power(m['mean_power_W'])} ({share})")
    if "mean_winding_loss_W" in m:
        print(f"    mean electrical power {_power(m['mean_electrical_power_W'])} "
              f"({pct['electrical']:.1f} % of the electrical bound), winding loss "
              f"{_power(m['mean_winding_loss_W'])}, peak current {m['max_current_A']:.4g} A, "
              f"peak voltage {m['max_voltage_V']:.4g} V")
    if "total_mean_power_W" in m:
        print(f"    all PTOs together: {_power(m['total_mean_power_W'])} "
              f"({pct['total_complex_conjugate']:.1f} % of their bound)")
    print(f"    max force {m['max_force']:.4g} {F}, max stroke {m['max_stroke']:.4g} {X}, "
          f"peak/mean power {m['papr']:.3g}, samples outside the limits "
          f"{100 * m['violation_fraction']:.3g} %")
    estimator = sim["summary"].get("estimator")
    if estimator:
        print(f"    excitation estimate error {100 * estimator['excitation_error']:.3g} % "
              f"(RMS, against the simulation's true excitation, after "
              f"{estimator['window_start_s']:.4g} s)")
    bounded = _finite(sim["summary"]["validity"].get("bound_W"))   # as `simulate` says
    print(f"    result: valid ({'bound, ' if bounded else ''}energy balance, "
          f"linear-hydrodynamics range checked"
          f"{'' if bounded else '; no finite bound to check against'})"
          if result.valid else "\n".join(invalid_lines(result.invalid_reasons, "    ")))


def _tidy(value) -> str:
    """A setting as printed: floats to 6 significant digits (the re-run reproduces the design
    to ~1e-6), per-PTO dicts and other values as they are."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_tidy(v)}" for k, v in value.items()) + "}"
    return repr(value)


def _print_lifted(lifted: dict, units: dict) -> None:
    """The design with the linear model's envelope lifted, on a plant that covers large
    motions (studies.design.envelope_gain)."""
    used = ", ".join(f"{k} {v:.2f}" for k, v in lifted["envelope_used"].items() if v > 0) or "n/a"
    gains = ", ".join(f"{k} = {_tidy(v)} {units.get(k, '')}" for k, v in lifted["parameters"].items()
                      if k in ("damping", "stiffness"))
    verdict = "valid" if lifted["valid"] else "INVALID: " + "; ".join(lifted["invalid_reasons"])
    gain = (f" ({lifted['gain_percent']:+.1f} % against the design inside the envelope)"
            if lifted["gain_percent"] is not None else "")
    if lifted["mean_power_W"] is None:
        print(f"  envelope lifted: {'; '.join(lifted['invalid_reasons'])}")
        return
    print(f"  envelope lifted (nonlinear hydrostatics and Froude-Krylov cover large motions): "
          f"{gains}; simulated {_power(lifted['mean_power_W'])}{gain}; linear theory "
          f"predicted {_power(lifted['predicted_power_W'])}")
    print(f"    motion against the linear model's range (1 = its edge): {used}; {verdict}")
