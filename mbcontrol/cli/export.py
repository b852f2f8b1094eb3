"""`mbcontrol export`: a controller (designed, or as --set gives it) and its plant out of
Python, as C and FMI 2.0 FMUs, checked in closed loop and timed."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from ..errors import InputError
from ..sim import period_of
from .commands import _plant, _wave

EXPORT_HELP = """Export a PTO controller as C and as FMI 2.0 co-simulation FMUs, with its plant.

The controller is designed for the wave as `mbcontrol design` tunes it (no --set: the same
tuner and the same sea, so the same numbers; a sea's components spaced by --duration or
600 s as design spaces them), or built from --set KEY=VALUE settings as `mbcontrol simulate`
takes them. Safe by default: a reactive law is tuned within the least gain and phase margins
of `mbcontrol defaults` (design.gain_margin_min, design.phase_margin_min_deg), and a linear
law below them, designed or --set, is refused; --aggressive exports the unconstrained optimum
(or the --set law) anyway and flags it (text and --json "robustness"). Written to --out DIR:
  DIR/c/                       self-contained C: mbc_controller.h (the documented API:
                               init(ctx, params), step(ctx, measurements, t, force), reset),
                               the generated and hand-written sources, a Makefile, the
                               built library lib<model>_<controller>.so
  DIR/<model>_<controller>.fmu the controller as an FMI 2.0 co-simulation FMU
  DIR/<model>_plant.fmu        the plant with the wave inside, RK4 at --dt
Then it checks the export: the same closed loop with the Python controller, with the C
library, and (fmpy installed) with both FMUs co-simulated in fmpy; and it times the C step
against the Python step on the run's own measurements.
Exportable: passive, reactive, latching, declutching, mpc (causal: AR forecast and Kalman
estimator; without the linear model's envelope, which the C engine does not hold yet: the
exported MPC and its Python twin both run with envelope=false, and it says so). Not nmpc
(IPOPT generates no C), nor an MPC oracle (forecast=known).
"""


def add_parser(sub, model_options, wave_options) -> None:
    p = sub.add_parser("export", help="a controller and its plant as C and FMI 2.0 FMUs, "
                                      "checked in closed loop and timed",
                       description=EXPORT_HELP, formatter_class=argparse.RawTextHelpFormatter)
    model_options(p)
    wave_options(p)
    p.add_argument("--controller", required=True, metavar="NAME",
                   help="passive, reactive, latching, declutching or mpc")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting, repeatable; given: no tuning (e.g. --set damping=2e5)")
    p.add_argument("--aggressive", action="store_true",
                   help="reactive: export the unconstrained optimum, and any linear law below\n"
                        "the margins (design.gain_margin_min, design.phase_margin_min_deg),\n"
                        "flagged rather than refused")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for the C sources and FMUs")
    p.add_argument("--duration", type=float, default=None,
                   help="closed-loop check, s (default: 20 periods, or 200 s in a sea)")
    p.add_argument("--dt", type=float, default=None,
                   help="simulation step and FMU communication step, s (default: period / 200,\n"
                        "a divisor of the controller's period)")
    p.add_argument("--no-check", action="store_true", help="export only: no closed-loop check, "
                                                          "no timing")
    p.add_argument("--json", action="store_true", help="print paths, checks and timings as JSON")
    p.set_defaults(run=run_export)


def _controller(args, plant, wave):
    """(controller, origin): designed as `design` designs it (studies.design.tune on
    cli.design.design_wave's sea, within the margins unless --aggressive), or from --set.
    wave: the closed-loop check's (a sea: tuned on the design's own spacing instead)."""
    from mbcontrol.controllers import REGISTRY, make
    from mbcontrol.studies.design import tune

    from .commands import _controller as from_settings
    from .design import design_wave
    if args.controller not in REGISTRY:
        raise InputError(f"export: unknown controller {args.controller!r}; expected one of "
                         f"{', '.join(REGISTRY)}")
    # settings the law's C engine needs (the MPC's: no envelope, which needs a surface probe
    # the engine does not read): the export and its Python twin both run with them, said so
    given = {item.split("=")[0].strip() for item in args.set}
    extra_settings = {k: v for k, v in getattr(REGISTRY[args.controller], "export_settings",
                                               {}).items() if k not in given}
    if extra_settings:
        print(f"mbcontrol: note: {REGISTRY[args.controller].export_note}", file=sys.stderr)
        args.set = [*args.set, *(f"{k}={str(v).lower()}" for k, v in extra_settings.items())
                    ] if args.set else []
    if args.set:
        return from_settings(args, wave), "--set"
    pto = plant.scene.ptos[0]
    notes: list[str] = []
    tuned_for = wave if args.wave == "regular" else design_wave(args, plant, "export")[0]
    parameters, _, _, extra = tune(plant, tuned_for, args.controller, pto, True, None, notes,
                                   robust=not getattr(args, "aggressive", False))
    if "wave" in extra:              # a predictive controller previews the check's wave
        extra["wave"] = wave
    return make(args.controller, **parameters, **extra, **extra_settings), "designed"


def _robustness(args, plant, controller, origin: str) -> dict | None:
    """A linear law's margins on every PTO against the floors (controllers.robustness):
    {pto: robustness dict}, None for other laws. InputError below the floors unless
    --aggressive (then flagged on stderr)."""
    from mbcontrol.sim import law_kind
    if law_kind(controller) != "linear":      # a loop transfer to check
        return None
    from mbcontrol.controllers import loop_margins, loop_robustness, pto_gains
    gains = pto_gains(plant, controller)
    out = {}
    for pto in gains:
        others = {n: g for n, g in gains.items() if n != pto} or None
        out[pto] = loop_robustness(loop_margins(plant, controller, pto=pto, others=others))
    short = {p: r for p, r in out.items() if not r["meets"]}
    if short:
        f = next(iter(short.values()))["floors"]
        why = "; ".join(f"PTO {p!r}: {r['why']}" for p, r in short.items())
        if not getattr(args, "aggressive", False):
            raise InputError(f"export: the {origin} {controller.name} law is below the "
                             f"robustness floors (gain margin {f['gain_margin']:g}, phase "
                             f"margin {f['phase_margin_deg']:g} deg; `mbcontrol defaults` "
                             f"design.gain_margin_min, design.phase_margin_min_deg): {why}. "
                             f"Export it anyway with --aggressive, or give a law within them")
        print(f"mbcontrol: warning: exported with --aggressive, below the robustness floors: "
              f"{why}", file=sys.stderr)
    return out


def run_export(args) -> int:
    from mbcontrol.export import export_controller
    from mbcontrol.export import closed_loop_check, footprint, step_timing
    from mbcontrol.export import export_plant
    from mbcontrol.results import jsonable
    plant = _plant(args)
    if args.wave == "none":
        raise InputError("export needs a wave to design and check in: --wave regular|jonswap|pm")
    period_hint = args.period if args.wave == "regular" else args.tp
    duration = args.duration or (20 * period_hint if args.wave == "regular" else 200.0)
    wave = _wave(args, plant, duration)
    controller, origin = _controller(args, plant, wave)
    robustness = _robustness(args, plant, controller, origin)
    dt = args.dt or _step(float(wave.period) / 200, period_of(controller))
    out = Path(args.out)
    exported = export_controller(controller, plant, out, model=plant.name,
                                 step=period_of(controller) or dt)
    plant_fmu = export_plant(plant, wave, out, dt=dt, model=plant.name)
    report = {"model": plant.name, "controller": controller.name, "origin": origin,
              "parameters": {p.name: p.value for p in exported.spec.parameters},
              "settings": jsonable(exported.spec.settings),    # as exported, bound
              "inputs": exported.spec.inputs, "outputs": exported.spec.outputs,
              "fmus": {"controller": str(exported.fmu), "plant": str(plant_fmu)},
              "c_library": str(exported.library), "c_sources": str(exported.c_folder),
              "footprint": footprint(exported), "robustness": robustness,
              "aggressive": bool(args.aggressive),
              "below_floors": bool(robustness) and not all(r["meets"]
                                                           for r in robustness.values())}
    if not args.no_check:
        checked = closed_loop_check(plant, wave, controller, exported, duration=duration,
                                    dt=dt, plant_fmu=plant_fmu)
        report["closed_loop_check"] = checked["check"]
        timing = step_timing(controller, exported, checked["record"], plant)
        report["step_time_us"] = timing["c"]           # wall
        report["step_cpu_time_us"] = timing["c_cpu"]   # thread CPU: the scheduler's share out
        report["python_step_time_us"] = timing["python"]
        if "c_counts" in timing:            # the MPC engine's: fallbacks, soft solves, fits
            report["c_counts"] = timing["c_counts"]
    if args.json:
        print(json.dumps(jsonable(report), indent=2, allow_nan=False))
    else:
        _print(report)
    return 0


def _step(target: float, period) -> float:
    """The largest step <= target that divides the controller's period (s)."""
    if not period:
        return target
    return period / math.ceil(period / target - 1e-9)


def _print(r: dict) -> None:
    print(f"{r['model']} {r['controller']} ({r['origin']}) exported")
    print(f"  reads {', '.join(r['inputs'])}; writes {', '.join(r['outputs'])}")
    print(f"  C library  {r['c_library']}  (context {r['footprint']['context_bytes']} bytes)")
    print(f"  FMUs       {r['fmus']['controller']}\n             {r['fmus']['plant']}")
    for pto, rob in (r.get("robustness") or {}).items():
        gm = "inf" if rob["gain_margin"] is None else f"{rob['gain_margin']:.3g}"
        pm = "inf" if rob["phase_margin_deg"] is None else f"{rob['phase_margin_deg']:.3g} deg"
        print(f"  margins of PTO {pto!r}: gain {gm}, phase {pm} (floors "
              f"{rob['floors']['gain_margin']:g}, {rob['floors']['phase_margin_deg']:g} deg): "
              + ("meets both" if rob["meets"] else "BELOW THE FLOORS (--aggressive): "
                 + rob["why"]))
    check = r.get("closed_loop_check")
    if check:
        print(f"  closed loop, {check['duration_s']:g} s at dt {check['dt_s']:g} s: C against "
              f"Python force {check['max_rel_force_error']:.2g} (relative to the peak), mean "
              f"power {check['mean_power_rel_error']:.2g} ({check['python_mean_power_W']:.6g} W)")
        if not check["python_run_valid"]:
            print(f"  INVALID run (its mean power is not a result): "
                  f"{'; '.join(check['python_run_invalid_reasons'])}")
        floor = check["round_off_floor"]
        print(f"  round-off floor (Python against itself from a start moved by 1e-12): force "
              f"{floor['max_rel_force_error']:.2g}, mean power {floor['mean_power_rel_error']:.2g}")
        fmu = check.get("fmu", {})
        if "max_rel_force_error" in fmu:
            print(f"  FMUs in fmpy against Python: force {fmu['max_rel_force_error']:.2g}")
        elif fmu:
            print(f"  FMUs not co-simulated: {fmu.get('skipped')}")
        c, py = r["step_time_us"], r["python_step_time_us"]
        print(f"  step: C median {c['median']:.3g} us, p99 {c['p99']:.3g}, max {c['max']:.3g} "
              f"({c['steps']} steps); Python median {py['median']:.3g} us")
        cpu = r.get("step_cpu_time_us")
        if cpu:     # what a real-time core sees (plus its own jitter); wall adds the scheduler
            print(f"  step, thread CPU time: C median {cpu['median']:.3g} us, p99 "
                  f"{cpu['p99']:.3g}, max {cpu['max']:.3g}")
        k = r.get("c_counts")
        if k:
            print(f"  C QP: {k['solves']} solves, {k['soft_solves']} soft, {k['failures']} "
                  f"fallbacks (previous plan's next move); AR: {k['ar_fits']} fits, {k['ar_unstable_fits']} stabilised")
