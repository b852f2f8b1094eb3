"""The `mbcontrol` command: catalogue, hydrodynamics, simulation, linearisation, control design.

Examples:
  mbcontrol models
  mbcontrol hydro hinged_barge
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1.0 --duration 30 --json
  mbcontrol simulate hinged_barge --wave jonswap --hs 0.03 --tp 1.0 --seed 3 --out run.nc
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1 --controller passive --set damping=1.5
  mbcontrol linearize hinged_barge --bode bode.png --json
  mbcontrol design sphere --controller reactive --wave regular --height 2.5 --period 9.6664
  mbcontrol design sphere --controller passive --wave jonswap --hs 2.5 --tp 8 --json
  mbcontrol bench rm3 --wave jonswap --hs 2.5 --tp 8 --stability
  mbcontrol fidelity sphere --wave jonswap --hs 2.5 --tp 9.67 --tol 0.01
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from .errors import MbcontrolError
from .integrators import METHODS
from .results import jsonable


DESIGN_HELP = """Tune a PTO controller for a sea, then check, bound and simulate it.

The controller is tuned by its module's tuner (passive: optimal damping; reactive: complex-
conjugate matching, or the best stable pair in a sea; latching / declutching: hold time by
closed-loop simulation, regular waves only; mpc: its defaults, given the wave), within the
PTO's force and stroke limits unless --unconstrained. It prints the tuned parameters, the
power linear theory predicts, the stability margins of a linear law (gain, phase, distance
of the Nyquist curve from -1, closed-loop poles), the complex-conjugate and force/stroke-
constrained power bounds, and the metrics of a closed-loop simulation on the nonlinear plant
with the share of each bound it reaches. It ends with the `mbcontrol simulate` command line
that re-runs that simulation (the parameters as --set KEY=VALUE).

Example:
  mbcontrol design sphere --controller passive --wave regular --height 2.5 --period 9.6664
"""


BENCH_HELP = """Speed against accuracy for one model in one sea, measured on this machine.

Runs every integration method over a ladder of steps (rk3, rk4, dopri5, exp-rk4: period/4
down to period/256) or tolerances (cvodes, adams: rtol 1e-3..1e-7), and the radiation model
at several fit tolerances (fewer states), and measures for each run:
  error: max over joint coordinates of RMS(q - q_ref)/RMS(q_ref) after the ramp, q_ref a
         converged dopri5 run (its own error is printed);
  cost:  wall time of excitation synthesis + time-stepping (compilation excluded), one core.
Writes work_precision.png, work_precision.csv and work_precision.nc to --out, prints the
table, and names the cheapest setting within 1 % RMS. With --stability, adds each method's
largest stable step (stability.csv).

Example:
  mbcontrol bench sphere --wave jonswap --hs 2.5 --tp 9.67 --duration 300
"""


def main(argv=None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        return args.run(args) or 0
    except (MbcontrolError, KeyError, ValueError) as exc:
        message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        print(f"mbcontrol: error: {message}", file=sys.stderr)
        return 1


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="mbcontrol", description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = parser.add_subparsers(title="commands", metavar="COMMAND")

    p = sub.add_parser("models", help="list the catalogue of models")
    p.set_defaults(run=_models)

    p = sub.add_parser("hydro", help="load or compute a model's BEM data and fit its radiation "
                                     "model; print the fit report")
    _model_options(p)
    p.add_argument("--tol", type=float, help="radiation fit tolerance (normalised RMS error)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(run=_hydro)

    p = sub.add_parser("simulate", help="simulate a model in waves (nonlinear process plant)",
                       formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--duration", type=float, default=None,
                   help="simulated time, s (default: 30 periods, or 600 s for irregular seas)")
    p.add_argument("--dt", type=float, default=0.01, help="time step, s (default 0.01)")
    p.add_argument("--method", choices=tuple(METHODS), default="rk4",
                   help="\n".join(f"{m.name}: {m.description}" for m in METHODS.values()))
    p.add_argument("--rtol", type=float, default=1e-8,
                   help="relative tolerance of the adaptive methods (cvodes, adams)")
    p.add_argument("--controller", help="PTO controller by name (e.g. passive)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting, repeatable (e.g. --set damping=2.0)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter override, repeatable (e.g. hinge_pto__damping=3)")
    p.add_argument("--out", help="write the full result to this netCDF file")
    p.add_argument("--plot", help="write a time-series figure (PNG) to this file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=_simulate)

    p = sub.add_parser("design", help="tune a controller for a sea; check its stability margins, "
                                      "bound it and simulate it",
                       description=DESIGN_HELP, formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--controller", required=True, metavar="NAME",
                   help="passive, reactive, latching, declutching or mpc")
    p.add_argument("--pto", help="the PTO to tune and score (default: the first)")
    p.add_argument("--duration", type=float, default=None,
                   help="closed-loop simulation, s (default: 30 periods, longer if the linear\n"
                        "loop settles slowly; a sea: its repeat period, max(600 s, 20 Tp))")
    p.add_argument("--dt", type=float, default=None,
                   help="time step, s (default: period / 1000, or Tp / 1000)")
    p.add_argument("--unconstrained", action="store_true",
                   help="tune without the PTO's force and stroke limits (e.g. complex-conjugate\n"
                        "control) and with no controller saturation; the limits are still\n"
                        "reported (violations, constrained bound)")
    p.add_argument("--bounds", choices=("auto", "full", "off"), default="auto",
                   help="auto: complex-conjugate, and pseudo-spectral unless the sea has more than\n"
                        "150 components; full: always both (slow for long seas); off: none")
    p.add_argument("--json", action="store_true", help="print the design as JSON")
    p.set_defaults(run=_design)

    p = sub.add_parser("bench", help="speed against accuracy: work-precision chart and table of "
                                     "every integration method and radiation order; stability "
                                     "limits", description=BENCH_HELP,
                       formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--duration", type=float, default=None,
                   help="record length, s (default: 600 s for a sea, 30 periods for a regular wave)")
    p.add_argument("--methods", nargs="+", default=list(METHODS), choices=tuple(METHODS),
                   metavar="METHOD", help=f"methods to chart (default: all of {', '.join(METHODS)})")
    p.add_argument("--radiation-tols", nargs="*", type=float, default=[0.2, 0.1, 0.05, 0.02],
                   metavar="TOL", help="radiation fit tolerances to chart (default 0.2 0.1 0.05 0.02;\n"
                                       "new tolerances are fitted once and cached)")
    p.add_argument("--stability", action="store_true",
                   help="also find each method's largest stable step: linearised step map and\n"
                        "simulated search, for the scene, a 5x tighter radiation fit, an end\n"
                        "stop on the first PTO's joint and latching control")
    p.add_argument("--repeats", type=int, default=3, help="timing repeats, best kept (3)")
    p.add_argument("--out", default=None, help="folder for the PNG, CSV and netCDF "
                                               "(default out/bench/MODEL)")
    p.set_defaults(run=_bench)

    p = sub.add_parser("fidelity", help="the cheapest model that meets an error tolerance in a sea "
                                        "(fidelity='auto'): what it dropped and what that cost",
                       formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--tol", type=float, default=0.01,
                   help="largest relative RMS error against the full model, over body motions\n"
                        "and PTO velocity and power (default 0.01)")
    p.add_argument("--duration", type=float, default=None,
                   help="comparison record, s (default: the ramp plus 40 peak periods)")
    p.add_argument("--out", help="write the candidate table to this netCDF file")
    p.set_defaults(run=_fidelity)

    p = sub.add_parser("linearize", help="linearise about rest; poles, Bode plot")
    _model_options(p)
    p.add_argument("--bode", metavar="FILE.png", help="write a Bode plot")
    p.add_argument("--pair", action="append", default=[], metavar="INPUT:OUTPUT",
                   help="Bode channel, repeatable (default: each PTO command to its velocity)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter override, repeatable; e.g. hinge_friction__coulomb=0\n"
                        "(a smoothed Coulomb friction linearises to its slope at rest)")
    p.add_argument("--json", action="store_true", help="print signals and poles as JSON")
    p.set_defaults(run=_linearize)
    return parser


def _model_options(p) -> None:
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    p.add_argument("--scene-param", action="append", default=[], metavar="NAME=VALUE",
                   help="a value for the scene's [parameters], e.g. N=8 for barge_chain (repeatable)")


def _plant(args, **kwargs):
    from .plant import build_plant
    from .scene import load_scene
    values = dict(_key_value(item, "--scene-param") for item in args.scene_param)
    return build_plant(load_scene(args.model, values or None), **kwargs)


def _wave_options(p) -> None:
    g = p.add_argument_group("waves")
    g.add_argument("--wave", choices=("regular", "jonswap", "pm", "none"), default="regular")
    g.add_argument("--height", type=float, help="regular wave height H, m")
    g.add_argument("--period", type=float, help="regular wave period T, s")
    g.add_argument("--hs", type=float, help="significant wave height, m")
    g.add_argument("--tp", type=float, help="peak period, s")
    g.add_argument("--gamma", type=float, default=3.3, help="JONSWAP peak enhancement (3.3)")
    g.add_argument("--seed", type=int, default=0, help="random phase seed (0)")


def _models(args) -> int:
    from .scene import list_models, load_scene
    for name in list_models():
        print(f"{name:16s} {load_scene(name).description}")
    return 0


def _hydro(args) -> int:
    plant = _plant(args, radiation_tol=args.tol)
    if plant.hydro is None:
        print(f"{plant.name}: no hydrodynamic bodies")
        return 0
    rad = plant.hydro.radiation
    report = {"model": plant.name, "source": plant.hydro.source, "dofs": list(plant.hydro.dofs),
              "omega_rad_s": [float(plant.hydro.omega[0]), float(plant.hydro.omega[-1])],
              "n_omega": int(plant.hydro.omega.size), "radiation_states": int(rad.order),
              "fit_error": float(rad.fit_error),
              "max_pole_real_part": float(np.max(np.linalg.eigvals(rad.A).real)),
              "report": jsonable(rad.report)}
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(f"{plant.name}: hydro data {report['source']}")
        print(f"  DOFs ({len(report['dofs'])}): {', '.join(report['dofs'])}")
        print(f"  {report['n_omega']} frequencies, {report['omega_rad_s'][0]:.3g}.."
              f"{report['omega_rad_s'][1]:.3g} rad/s")
        print(f"  radiation model: {rad.order} states, normalised RMS error "
              f"{rad.fit_error:.2%}, slowest pole real part {report['max_pole_real_part']:.3g}")
    return 0


def _wave(args, plant, duration):
    """The wave the CLI options describe, None for --wave none; notes a spectrum cut by the
    hydro data's band on stderr."""
    from .waves import from_args
    if args.wave == "none":
        return None
    omega = plant.hydro.omega if plant.hydro is not None else None
    band = (float(omega[0]), float(omega[-1])) if omega is not None else None
    wave = from_args(args.wave, height=args.height, period=args.period, hs=args.hs,
                     tp=args.tp, gamma=args.gamma, seed=args.seed, duration=duration,
                     data_band=band)
    outside = wave.settings.get("spectrum_outside_data", 0.0)
    if outside > 1e-3:
        print(f"mbcontrol: note: {100 * outside:.2g} % of the spectrum's variance lies outside the "
              f"hydro data ({band[0]:.3g}..{band[1]:.3g} rad/s) and is left out; Hs is kept on the "
              f"rest", file=sys.stderr)
    return wave


def _simulate(args) -> int:
    from .metrics import summary
    from .simulate import simulate
    plant = _plant(args)
    duration = args.duration
    if args.wave != "none":
        if duration is None:
            duration = 30 * args.period if args.wave == "regular" and args.period else 600.0
    elif duration is None:
        duration = 60.0
    wave = _wave(args, plant, duration)
    controller = _controller(args, wave)
    params = dict(_key_value(s, "--param") for s in args.param)
    ds = simulate(plant, wave, duration=duration, dt=args.dt, controller=controller,
                  method=args.method, rtol=args.rtol, params=params or None,
                  progress=not args.json)
    if args.out:
        from .results import save_dataset
        save_dataset(ds, args.out)
    if args.plot:
        from .plotting import time_series
        names = list(plant.topology.tree.coordinate_names) + [
            f"{p.name}__power" for p in plant.scene.ptos]
        time_series(ds, ["eta"] + names, path=args.plot)
    result = summary(ds, plant)
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        _print_summary(result)
    return 0


def _design(args) -> int:
    from mbcontrol.controllers.design import design
    plant = _plant(args)
    if args.wave == "none":
        raise ValueError("design needs a wave: --wave regular|jonswap|pm")
    wave = _wave(args, plant, args.duration or 600.0)
    result = design(plant, wave, args.controller, pto=args.pto, simulate_s=args.duration,
                    dt=args.dt, bounds={"auto": True, "full": "full", "off": False}[args.bounds],
                    limits=not args.unconstrained)
    command = _simulate_command(args, result)
    if args.json:
        print(json.dumps({**result.to_dict(), "model": plant.name, "wave": wave.describe(),
                          "simulate_command": command}, indent=2, allow_nan=False))
    else:
        _print_design(plant, wave, result, command)
    for note in result.warnings:
        print(f"mbcontrol: warning: {note}", file=sys.stderr)
    return 0


def _simulate_command(args, result) -> str:
    """The `mbcontrol simulate` command line that re-runs the design's simulation; numbers
    in repr form, which round-trips a float exactly."""
    import shlex
    words = ["mbcontrol", "simulate", args.model]
    for item in args.scene_param:
        words += ["--scene-param", item]
    words += ["--wave", args.wave]
    if args.wave == "regular":
        words += ["--height", repr(args.height), "--period", repr(args.period)]
    else:
        words += ["--hs", repr(args.hs), "--tp", repr(args.tp), "--seed", str(args.seed)]
        if args.wave == "jonswap":
            words += ["--gamma", repr(args.gamma)]
    sim = result.simulation
    if sim is not None:
        words += ["--duration", repr(sim["duration_s"]), "--dt", repr(sim["dt_s"])]
    words += ["--controller", result.name]
    for key, value in result.parameters.items():
        words += ["--set", f"{key}={value!r}"]
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
    sea = (f"a regular wave (H {wave.settings['height']:.6g} m, T {wave.settings['period']:.6g} s)"
           if wave.kind == "regular" else
           f"a {wave.kind.upper()} sea (Hs "
           f"{wave.settings['hs']:.6g} m, Tp {wave.settings['tp']:.6g} s, seed "
           f"{wave.settings['seed']})")
    print(f"{plant.name}: {result.name} control of PTO {result.pto!r} designed for {sea}")
    print("  parameters:")
    for key, value in result.parameters.items():
        print(f"    {key} = {value!r} {units.get(key, 's')}")
    print(f"  predicted (linear theory): {_power(result.predicted_power_W)}")
    if "simulated_power_W" in result.tuner:
        print(f"  tuner's own simulation: {_power(result.tuner['simulated_power_W'])}")
    if result.margins is not None:
        print(f"  stability: {result.margins.message}")
    b = result.bound
    limits = f"|F| <= {b['force_max']:.4g} {F}, |x| <= {b['stroke_max']:.4g} {X}"
    constrained = (_power(b["constrained_W"]) if b["constrained_W"] is not None
                   else f"n/a ({b['constrained_reason']})")
    print(f"  bounds: complex-conjugate {_power(b['complex_conjugate_W'])}; constrained "
          f"({limits}) {constrained}")
    m = result.metrics
    if m is None:
        print("  not simulated (see the warning)")
    else:
        sim = result.simulation
        pct = result.percent_of_bound
        share = ", ".join(f"{v:.1f} % of the {k.replace('_', '-')} bound"
                          for k, v in pct.items() if v is not None)
        print(f"  simulated ({sim['duration_s']:.4g} s, dt {sim['dt_s']:.4g} s, nonlinear plant): "
              f"mean absorbed power {_power(m['mean_power_W'])} ({share})")
        print(f"    max force {m['max_force']:.4g} {F}, max stroke {m['max_stroke']:.4g} {X}, "
              f"peak/mean power {m['papr']:.3g}, samples outside the limits "
              f"{100 * m['violation_fraction']:.3g} %")
    print(f"  re-run: {command}")


def _bench(args) -> int:
    from .bench_report import bench
    plant = _plant(args)
    duration = args.duration or (30 * args.period if args.wave == "regular" and args.period
                                 else 600.0)
    wave = _wave(args, plant, duration)
    if wave is None:
        raise ValueError("bench needs a wave: --wave regular|jonswap|pm")
    bench(plant.scene, wave, duration=duration, methods=args.methods,
          radiation_tols=args.radiation_tols, stability=args.stability,
          repeats=args.repeats, out=args.out or f"out/bench/{plant.name}")
    return 0


def _fidelity(args) -> int:
    from .fidelity import auto
    plant = _plant(args)
    duration = args.duration
    wave = _wave(args, plant, duration or 600.0)
    if wave is None:
        raise ValueError("fidelity needs a wave: --wave regular|jonswap|pm")
    report = auto(plant.scene, wave, tol=args.tol, duration=duration, progress=True)
    print(report)
    if args.out:
        from .results import save_dataset
        save_dataset(report.to_dataset(), args.out)
    return 0


def _linearize(args) -> int:
    from .linearize import linearize
    plant = _plant(args)
    params = dict(_key_value(s, "--param") for s in args.param)
    sys_ = linearize(plant, params=params or None)
    poles = np.linalg.eigvals(np.asarray(sys_.A))
    pairs = [tuple(p.split(":", 1)) for p in args.pair] or [
        (f"u__{p.name}", f"{p.name}__velocity") for p in plant.scene.ptos]
    if args.bode:
        from .plotting import bode
        omega = np.logspace(np.log10(max(plant.hydro.omega[0], 0.05)) if plant.hydro else -1,
                            np.log10(plant.hydro.omega[-1]) if plant.hydro else 2, 400)
        bode(sys_, pairs, omega, path=args.bode)
    info = {"model": plant.name, "n_states": int(sys_.nstates), "states": sys_.state_labels,
            "inputs": sys_.input_labels, "outputs": sys_.output_labels,
            "poles": [[float(p.real), float(p.imag)] for p in poles],
            "stable": bool(np.all(poles.real < 0)), "bode": args.bode}
    if args.json:
        print(json.dumps(info, indent=2))
    else:
        print(f"{plant.name}: {sys_.nstates} states, {sys_.ninputs} inputs, {sys_.noutputs} "
              f"outputs; {'stable' if info['stable'] else 'NOT stable'} (max pole real part "
              f"{poles.real.max():.3g})")
        if args.bode:
            print(f"Bode plot written to {args.bode}")
    return 0


def _controller(args, wave=None):
    """The --controller with its --set settings. A controller that takes a `wave` (a
    predictive controller's preview) is handed the simulated one, as `design` does."""
    if not args.controller:
        if args.set:
            raise ValueError("--set needs --controller")
        return None
    import inspect

    from mbcontrol.controllers import REGISTRY, make
    cls = REGISTRY.get(args.controller)
    signature = inspect.signature(cls).parameters if cls is not None else {}
    settings = {}
    for item in args.set:
        key, value = _key_value(item, "--set", text=True)
        # text only for a setting that is text (a choice), so a typo in a number is caught
        if isinstance(value, str) and not _takes_text(signature.get(key)):
            raise ValueError(f"--set {key}: expected a number, got {value!r}")
        settings[key] = value
    if wave is not None and cls is not None and "wave" in inspect.signature(cls).parameters:
        settings.setdefault("wave", wave)
    return make(args.controller, **settings)


def _takes_text(parameter) -> bool:
    """Does a controller setting take text: a str default or a str annotation?"""
    if parameter is None:
        return False
    return isinstance(parameter.default, str) or "str" in str(parameter.annotation)


def _key_value(item: str, flag: str, text: bool = False):
    """(key, float value); with text, a value that is not a number stays a string (a
    controller's choice such as --set forecast=ar)."""
    if "=" not in item:
        raise ValueError(f"{flag} expects KEY=VALUE, got {item!r}")
    key, value = item.split("=", 1)
    try:
        return key.strip(), float(value)
    except ValueError:
        if text and value.strip():
            return key.strip(), value.strip()
        raise ValueError(f"{flag} {key}: expected a number, got {value!r}") from None


def _print_summary(result: dict) -> None:
    print(f"{result['model']}: {result['duration_s']:.4g} s simulated in "
          f"{result['wall_time_s']:.3g} s ({result['method']}, dt = {result['dt_s']} s)")
    for body, values in result["bodies"].items():
        print(f"  {body}: heave amplitude {values['heave_amplitude_m']:.4g} m, pitch amplitude "
              f"{values['pitch_amplitude_rad']:.4g} rad")
    for pto, values in result["ptos"].items():
        print(f"  {pto}: mean absorbed power {values['mean_power_W']:.4g} W, max force "
              f"{values['max_force']:.4g}, max stroke {values['max_stroke']:.4g}")


if __name__ == "__main__":
    sys.exit(main())
