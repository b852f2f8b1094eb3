"""The `mbcontrol` command: catalogue, hydrodynamics, simulation, linearisation, control design.

Examples:
  mbcontrol models
  mbcontrol models sphere
  mbcontrol hydro hinged_barge
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1.0 --duration 30 --json
  mbcontrol simulate hinged_barge --wave jonswap --hs 0.03 --tp 1.0 --seed 3 --out out/run.nc
  mbcontrol simulate hinged_barge --wave regular --height 0.02 --period 1 --controller passive --set damping=1.5
  mbcontrol simulate rm3 --wave jonswap --hs 2 --tp 9 --controller mpc --set forecast=ar --json
  mbcontrol linearize hinged_barge --bode out/bode.png --json
  mbcontrol design sphere --controller reactive --wave regular --height 2.5 --period 9.6664
  mbcontrol design sphere --controller passive --wave jonswap --hs 2.5 --tp 8 --json
  mbcontrol bench rm3 --wave jonswap --hs 2.5 --tp 8 --stability
  mbcontrol fidelity sphere --wave jonswap --hs 2.5 --tp 9.67 --tol 0.01
  mbcontrol export sphere --controller mpc --wave jonswap --hs 2 --tp 9 --out out/export
  mbcontrol identify flume_section --data ../shared/data/tank/scenario_c/5*.csv.xz --out out/id

Exit status: 0 done; 1 bad input (the message names the file, the field and what was
expected); 2 a bad command line; 3 a result (simulate) or sweep cases failed their physics
checks: printed INVALID with a remedy (--allow-invalid: 0); 4 sweep cases failed to run;
5 the machine stopped the command (a full disk, no permission, a read-only file system, a
cache entry unreadable even when made again): the message names the path and what to do.
An error is one line, "mbcontrol: error: ..."; -v adds its traceback.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import sys
import traceback
import warnings

from .. import defaults
from ..errors import MbcontrolError
from ..sim import METHODS
from .commands import run_bench, run_fidelity, run_hydro, run_models, run_simulate
from .describe import default_help, run_defaults, run_keys
from .design import add_design_flags, run_design
from .linearize import add_linearize_flags, run_linearize
from .codesign import add_parser as add_codesign_parser
from .export import add_parser as add_export_parser
from .helptext import BENCH_HELP, DESIGN_HELP, SIMULATE_HELP
from .identify import add_parser as add_identify_parser
from .messages import format_warning, refusal, said_once
from .sweep import add_parser as add_sweep_parser


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("mbcontrol")
    except PackageNotFoundError:        # run from a source tree that was never installed
        return "unknown (not installed)"


def main(argv=None) -> int:
    import logging
    logger = logging.getLogger("mbcontrol")
    previous, warnings.formatwarning = warnings.formatwarning, format_warning
    shown, warnings.showwarning = warnings.showwarning, said_once(warnings.showwarning)
    level = logger.level
    quiet = defaults.get("log.quiet") if defaults.source("log.quiet") == "set" else None
    try:
        return _main(argv)
    finally:                     # a caller (a test, a notebook) gets its settings back
        warnings.formatwarning, warnings.showwarning = previous, shown
        logger.setLevel(level)
        if quiet is None:
            defaults.reset("log.quiet")
        else:
            defaults.set("log.quiet", quiet)


def _loudness(args) -> None:
    """-v / -q: the "mbcontrol" logger's level, and progress bars off with -q (the default
    "log.quiet", which our bars and the BEM solver's read: no environment variable)."""
    import logging

    from ..console import set_verbosity
    if args.verbose or args.quiet:
        set_verbosity(logging.DEBUG if args.verbose else logging.WARNING)
    if args.quiet:
        defaults.set("log.quiet", True)     # progress bars, ours and Capytaine's (BEM)


def _main(argv) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    _check_wave_flags(args)
    _loudness(args)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        if getattr(args, "json", False):
            with _stdout_for_json_only():
                return args.run(args) or 0
        return args.run(args) or 0
    except (MbcontrolError, OSError) as exc:
        # bad input or the machine's refusal, named in one line (-v: with its traceback);
        # anything else is a bug and keeps its traceback
        status, line = refusal(exc)
        if status is None:
            raise
        if args.verbose:
            traceback.print_exc()
        print(f"mbcontrol: error: {line}", file=sys.stderr)
        return status


@contextlib.contextmanager
def _stdout_for_json_only():
    """--json output is a contract: while the command runs, whatever C libraries write to
    the process's standard output (qpOASES reports an infeasible QP there whatever its print
    level; compilers, solvers, Dask workers started meanwhile) goes to standard error, and
    only the command's own Python prints reach standard output."""
    sys.stdout.flush()
    try:
        real = os.dup(1)
    except OSError:                  # no file descriptor 1 (an embedding host): nothing to guard
        yield
        return
    swapped = None
    try:
        if _is_fd1(sys.stdout):      # the console or a pipe: Python's prints keep fd 1's target
            swapped = sys.stdout
            sys.stdout = os.fdopen(os.dup(real), "w", buffering=1, encoding=swapped.encoding,
                                   errors=swapped.errors)
        os.dup2(2, 1)
        yield
    finally:
        from ..console import flush_c_stdio
        flush_c_stdio()              # C's buffered writes go where they were meant to
        if swapped is not None:
            sys.stdout.flush()
            sys.stdout.close()
            sys.stdout = swapped
        os.dup2(real, 1)
        os.close(real)


def _is_fd1(stream) -> bool:
    try:
        return stream.fileno() == 1
    except (AttributeError, OSError, ValueError):      # pytest's capture, a StringIO
        return False


def build_parser() -> argparse.ArgumentParser:
    from mbcontrol.controllers import REGISTRY
    controllers = ", ".join(REGISTRY)
    parser = argparse.ArgumentParser(
        prog="mbcontrol", description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--version", action="version", version=f"mbcontrol {_version()}")
    loudness = parser.add_mutually_exclusive_group()
    loudness.add_argument("-v", "--verbose", action="store_true",
                          help="more messages (the 'mbcontrol' logger at DEBUG), and an "
                               "error's traceback")
    loudness.add_argument("-q", "--quiet", action="store_true",
                          help="only warnings and errors: no status lines, no progress bars")
    sub = parser.add_subparsers(title="commands", metavar="COMMAND")
    _add_reference_commands(sub)
    _add_hydro(sub)
    _add_simulate(sub, controllers)
    _add_design(sub, controllers)
    _add_bench(sub)
    _add_fidelity(sub)
    _add_linearize(sub)
    add_identify_parser(sub)
    add_sweep_parser(sub)
    add_codesign_parser(sub, _wave_options)
    add_export_parser(sub, _model_options, _wave_options)
    return parser


def _add_reference_commands(sub) -> None:
    """models, defaults, keys: what the toolbox holds and takes."""
    p = sub.add_parser("models", help="list the catalogue, or describe one model: its bodies, "
                                      "joints, PTOs, parameters and the controllers' settings")
    p.add_argument("name", nargs="?", help="a model (catalogue name or scene .toml) to describe")
    p.add_argument("--json", action="store_true", help="print the description as JSON")
    p.set_defaults(run=run_models)

    p = sub.add_parser("defaults", help="every default (time steps, methods, tolerances, cache "
                                        "folder, workers): value, where it came from, how to "
                                        "change it")
    p.add_argument("--json", action="store_true", help="print the table as JSON")
    p.set_defaults(run=run_defaults)

    p = sub.add_parser("keys", help="every key a scene file takes, by section: value, unit, "
                                     "default, meaning (Markdown, from the parser itself)")
    p.add_argument("--readme", nargs="?", const="notebooks/guide.md", metavar="FILE",
                   help="write the reference into FILE's scene-keys section (default "
                        "notebooks/guide.md, the guide)")
    p.set_defaults(run=run_keys)


def _add_hydro(sub) -> None:
    p = sub.add_parser("hydro", help="load or compute a model's BEM data and fit its radiation "
                                     "model; print the fit report")
    _model_options(p)
    p.add_argument("--tol", type=float, help="radiation fit tolerance (e.g. 0.01) on the error that judges it: "
                   "the device's response error, or the kernel's (the larger of the worst relative error per "
                   "frequency in the scene's response_band and the global RMS error)")
    p.add_argument("--judged-by", choices=("response", "kernel"),
                   help="judge the fit by the device's response or by the kernel's own error "
                        "(default: the scene's [hydro] fit_judged_by)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--plot", metavar="FILE.png",
                   help="draw A(ω), B(ω) and |F_ex(ω)| per DOF: the data, and the fitted\n"
                        "radiation model over them")
    p.set_defaults(run=run_hydro)


def _add_simulate(sub, controllers: str) -> None:
    p = sub.add_parser("simulate", help="simulate a model in waves (nonlinear process plant)",
                       description=SIMULATE_HELP, formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--duration", type=float, default=None,
                   help="simulated time, s (default: 30 periods, or 600 s for irregular seas)")
    p.add_argument("--repeat", type=float, metavar="S",
                   help="a sea's repeat period, s: its components 2 pi / S apart (default: the\n"
                        "duration); design simulates two repeat periods of a 600 s sea")
    p.add_argument("--from", dest="window_from", metavar="S|last-repeat",
                   help="the statistics start at S seconds, or over the sea's last whole repeat\n"
                        "period, as design scores it (default: the last 10 periods of a\n"
                        "regular wave, after the ramp in a sea; after a controller's warm-up)")
    p.add_argument("--dt", type=float, help=f"time step, s ({default_help('sim.dt')})")
    p.add_argument("--method", choices=tuple(METHODS),
                   help="\n".join([*(f"{m.name}: {m.description}" for m in METHODS.values()),
                                   f"({default_help('sim.method')})"]))
    p.add_argument("--rtol", type=float, help="relative tolerance of the adaptive methods "
                   f"(cvodes, adams; {default_help('sim.rtol')})")
    p.add_argument("--controller", metavar="NAME",
                   help=f"PTO controller: {controllers}\n(settings: mbcontrol models MODEL)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting, repeatable (e.g. --set damping=2.0)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter override, repeatable (e.g. hinge_pto__damping=3)")
    p.add_argument("--initial", action="append", default=[], metavar="JOINT=VALUE",
                   help="start with this joint coordinate set, repeatable: a free decay with\n"
                        "--wave none (e.g. --initial heave=0.5 or --initial hinge='10 deg');\n"
                        "along the joint's axis, SI or with a unit; NED: heave + is down")
    p.add_argument("--out", help="write the full result to this netCDF file (compressed)")
    p.add_argument("--out-float32", action="store_true",
                   help="--out in single precision (relative rounding 6e-8; about half the size)")
    p.add_argument("--out-every", type=int, default=1, metavar="K",
                   help="--out keeps every K-th time step (default 1: all)")
    p.add_argument("--plot", help="write a time-series figure (PNG) to this file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--allow-invalid", action="store_true",
                   help="exit 0 even when the result fails its physics checks (mean power\n"
                        "above the complex-conjugate bound of its wave, energy balance,\n"
                        "motions beyond linear hydrodynamics); it is still marked invalid\n"
                        "(exit status 3 without this flag)")
    p.set_defaults(run=run_simulate)


def _add_design(sub, controllers: str) -> None:
    p = sub.add_parser("design", help="tune a controller for a sea; check its stability margins, "
                                      "bound it and simulate it",
                       description=DESIGN_HELP, formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--controller", required=True, metavar="NAME",
                   help=f"{controllers}\n(settings: mbcontrol models MODEL)")
    p.add_argument("--pto", help="the PTO to tune and score (default: the first)")
    p.add_argument("--duration", type=float, default=None,
                   help="closed-loop simulation, s (default: 30 periods, longer if the linear\n"
                        "loop settles slowly; a sea: its repeat period, max(600 s, 20 Tp))")
    p.add_argument("--dt", type=float, default=None,
                   help="time step, s (default: period / 1000, or Tp / 1000)")
    add_design_flags(p)          # --aggressive (--robust), --bode, --nyquist
    p.add_argument("--unconstrained", action="store_true",
                   help="tune without the PTO's force and stroke limits (e.g. complex-conjugate\n"
                        "control) and with no controller saturation; the limits are still\n"
                        "reported (violations, constrained bound)")
    p.add_argument("--bounds", choices=("auto", "full", "off"), default="auto",
                   help="auto: complex-conjugate and pseudo-spectral, a sea's force band cut to\n"
                        "600 frequencies (then a reference, not a bound); full: the whole\n"
                        "band (minutes for long seas); off: none")
    p.add_argument("--json", action="store_true", help="print the design as JSON")
    p.set_defaults(run=run_design)


def _add_bench(sub) -> None:
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
    p.set_defaults(run=run_bench)


def _add_fidelity(sub) -> None:
    p = sub.add_parser("fidelity", help="the cheapest model that meets an error tolerance in a sea "
                                        "(fidelity='auto'): what it dropped and what that cost",
                       formatter_class=argparse.RawTextHelpFormatter)
    _model_options(p)
    _wave_options(p)
    p.add_argument("--tol", type=float,
                   help="largest relative RMS error against the full model, over body motions\n"
                        f"and PTO velocity and power ({default_help('fidelity.tol')})")
    p.add_argument("--duration", type=float, default=None,
                   help="comparison record, s (default: the ramp plus 40 peak periods)")
    p.add_argument("--out", help="write the candidate table to this netCDF file")
    p.set_defaults(run=run_fidelity)


def _add_linearize(sub) -> None:
    p = sub.add_parser("linearize", help="linearise about rest; poles, Bode plot")
    _model_options(p)
    p.add_argument("--bode", metavar="FILE.png", help="write a Bode plot")
    p.add_argument("--pair", action="append", default=[], metavar="INPUT:OUTPUT",
                   help="Bode channel, repeatable (default: each PTO command to its velocity)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter override, repeatable; e.g. hinge_friction__coulomb=0\n"
                        "(a smoothed Coulomb friction linearises to its slope at rest)")
    add_linearize_flags(p)       # --no-pto-law
    p.add_argument("--json", action="store_true", help="print signals and poles as JSON")
    p.set_defaults(run=run_linearize)


def _model_options(p) -> None:
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    p.add_argument("--scene-param", action="append", default=[], metavar="NAME=VALUE",
                   help="a value for the scene's [parameters], e.g. N=8 for barge_chain (repeatable)")


def _wave_options(p) -> None:
    """The shared wave flags; --wave elevation without --eta FILE, or --eta with another wave,
    is a usage error (exit 2), found before the model is built."""
    g = p.add_argument_group("waves")
    g.add_argument("--wave", choices=("regular", "jonswap", "pm", "elevation", "none"),
                   default="regular",
                   help="regular (--height, --period), jonswap or pm (--hs, --tp), elevation (a\n"
                        "measured record: --eta FILE) or none (still water)")
    g.add_argument("--eta", metavar="FILE",
                   help="--wave elevation's record: two columns, time (s) and free-surface\n"
                        "elevation (m, positive up) at the scene's origin; whitespace or commas,\n"
                        "one header line and # comments allowed (mbcontrol.waves.from_record).\n"
                        "simulate's default duration: the record's; a longer run repeats it")
    g.add_argument("--height", type=float, help="regular wave height H, m")
    g.add_argument("--period", type=float, help="regular wave period T, s")
    g.add_argument("--hs", type=float, help="significant wave height, m")
    g.add_argument("--tp", type=float, help="peak period, s")
    g.add_argument("--gamma", type=float, default=3.3, help="JONSWAP peak enhancement (3.3)")
    g.add_argument("--seed", type=int, default=0, help="random phase seed (0)")
    g.add_argument("--direction", type=float, metavar="DEG",
                   help="heading the waves travel towards, degrees in the n-frame (default: the "
                        "hydro data's heading when it has one only, else 0)")
    p.set_defaults(wave_parser=p)          # `_check_wave_flags` reports on it


def _check_wave_flags(args) -> None:
    """Usage errors (exit 2, before any model is built) of the wave flags taken together."""
    p = getattr(args, "wave_parser", None)
    if p is None:
        return
    if args.wave == "elevation" and args.eta is None:
        p.error("--wave elevation needs --eta FILE, the measured elevation record")
    if args.wave != "elevation" and args.eta is not None:
        p.error(f"--eta {args.eta}: a record is read with --wave elevation; expected "
                f"--wave elevation, got --wave {args.wave}")
    if args.wave == "elevation" and p.prog.endswith(" codesign"):
        p.error("--wave elevation: codesign rebuilds its wave per case from --height and "
                "--period or --hs and --tp; expected --wave regular, jonswap or pm")
    if args.wave == "elevation" and getattr(args, "repeat", None) is not None:
        p.error("--repeat does not apply to --wave elevation: a record repeats over its own "
                "length")
