"""The `mbcontrol` command: catalogue, hydrodynamics, simulation and linearisation.

Examples:
  mbcontrol models
  mbcontrol hydro hinged_barge
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1.0 --duration 30 --json
  mbcontrol simulate hinged_barge --wave jonswap --hs 0.03 --tp 1.0 --seed 3 --out run.nc
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1 --controller passive --set damping=1.5
  mbcontrol linearize hinged_barge --bode bode.png --json
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from .errors import MbcontrolError


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
    p.add_argument("--method", choices=("rk4", "cvodes"), default="rk4",
                   help="rk4: compiled fixed step (default); cvodes: adaptive BDF")
    p.add_argument("--controller", help="PTO controller by name (e.g. passive)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting, repeatable (e.g. --set damping=2.0)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter override, repeatable (e.g. hinge_pto__damping=3)")
    p.add_argument("--out", help="write the full result to this netCDF file")
    p.add_argument("--plot", help="write a time-series figure (PNG) to this file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=_simulate)

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
              "report": _jsonable(rad.report)}
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


def _simulate(args) -> int:
    from .metrics import summary
    from .simulate import simulate
    from .waves import from_args
    plant = _plant(args)
    wave = None
    duration = args.duration
    if args.wave != "none":
        if duration is None:
            duration = 30 * args.period if args.wave == "regular" and args.period else 600.0
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
    elif duration is None:
        duration = 60.0
    controller = _controller(args)
    params = dict(_key_value(s, "--param") for s in args.param)
    ds = simulate(plant, wave, duration=duration, dt=args.dt, controller=controller,
                  method=args.method, params=params or None, progress=not args.json)
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


def _controller(args):
    if not args.controller:
        if args.set:
            raise ValueError("--set needs --controller")
        return None
    from mbcontrol.controllers import make
    settings = {}
    for item in args.set:
        key, value = _key_value(item, "--set")
        settings[key] = value
    return make(args.controller, **settings)


def _key_value(item: str, flag: str):
    if "=" not in item:
        raise ValueError(f"{flag} expects KEY=VALUE, got {item!r}")
    key, value = item.split("=", 1)
    try:
        return key.strip(), float(value)
    except ValueError:
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


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, complex):
        return [obj.real, obj.imag]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


if __name__ == "__main__":
    sys.exit(main())
