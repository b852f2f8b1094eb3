"""`mbcontrol codesign`: hull, drivetrain and controller chosen together for a wave or a site."""
from __future__ import annotations

import json
import sys

from ..errors import InputError

CODESIGN_HELP = """Vary a device's design and find the best: scene parameters (the hull: a
revolution profile's radii and heights, box sizes; the drivetrain: gear, inertia, friction,
rated force, whatever the scene writes as "{expr}" of its [parameters]), plant parameters and
controller settings, on a grid (--vary NAME=v1,v2,...) or by an optimiser over a box
(--optimize NAME=LO:HI: one name, bounded Brent; several, Nelder-Mead with bounds; at most
--max-evals evaluations).

Objectives (maximised): electrical_bound and mechanical_bound, the most mean electrical or
absorbed power any PTO force delivers in the wave within the PTO's force and stroke limits
(non-causal; the force limit acts where the scene's force_max_on says: WecOptTool's co-design
objective); controller, the mean power of a causal --controller designed for the wave (as
`sweep --design`) and simulated; annual_energy, the --seas site's annual energy with the
controller designed per sea, its 95 % interval the error bar. A bound with --seas instead of
a wave is the site's annual energy of the bound (MWh). --per divides by a cost proxy: volume
(m^3 displaced), rated_force (kN) or an arithmetic expression of the parameters. --against
OBJECTIVE evaluates the same points under a second objective and says whether the optimum
moves, with error bars (e.g. the causal annual energy against the bound's).

Each geometry's BEM data and radiation fit are cached by content, so a geometry met again
costs nothing; with --store DIR every evaluated point is kept (DIR/points), so an interrupted
study resumes and a rerun computes nothing. Grids run on Dask with --workers N or
--scheduler ADDRESS.

The --json output is a contract: {"points": [{"params", "objective", "valid", "error_95",
"reasons", "wall_s", "reused", "details"}], "best": {"params", "objective", "error_95"},
"objective_name", "search", "computed", "reused", "wall_time_s", "provenance": {"model",
"scene", "spec", "roles"}}; with --against also "against" (the second study, same form) and
"comparison": {"best", "other_best", "at_other_best", "difference", "difference_95",
"share_of_other", "verdict"}.

Examples:
  mbcontrol codesign wavebot --vary r2=0.2,0.35,0.5 --objective electrical_bound \\
      --wave regular --height 0.125 --period 3.3333333 --json
  mbcontrol codesign wavebot --optimize r2=0.05:0.88 --objective electrical_bound \\
      --wave regular --height 0.125 --period 3.3333333 --plot out/r2.png
  mbcontrol codesign wavebot --scene-param scale=10 --scene-param rated=1500 \
      --vary r2=0.05,0.35,0.65,0.88 --objective annual_energy --controller reactive \
      --against mechanical_bound \
      --seas ../shared/data/sites/pacwave_cluster_32.csv --store out/site --plot out/site.png
"""


def add_parser(sub, wave_options) -> None:
    """The codesign sub-command; wave_options adds the shared wave flags (the CLI's own)."""
    import argparse

    from .describe import default_help
    p = sub.add_parser("codesign", help="hull, drivetrain and controller chosen together",
                       description=CODESIGN_HELP, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    search = p.add_mutually_exclusive_group(required=True)
    search.add_argument("--vary", action="append", metavar="NAME=v1,v2,...",
                        help="a grid dimension (repeatable)")
    search.add_argument("--optimize", action="append", metavar="NAME=LO:HI",
                        help="a dimension of the optimiser's box (repeatable)")
    p.add_argument("--objective", default="electrical_bound",
                   help="electrical_bound (default), mechanical_bound, controller, annual_energy")
    p.add_argument("--controller", help="the causal law (objectives controller, annual_energy)")
    p.add_argument("--seas", metavar="FILE.csv",
                   help="weighted seas: annual_energy, or a bound's annual energy (MWh)")
    p.add_argument("--against", metavar="OBJECTIVE",
                   help="the same points under a second objective (e.g. mechanical_bound "
                        "against annual_energy): both curves, both optima and whether the "
                        "optimum moves, with error bars")
    p.add_argument("--per", help="a cost proxy to divide by: volume, rated_force or an "
                                 "expression")
    p.add_argument("--scene-param", action="append", default=[], metavar="NAME=VALUE",
                   help="a fixed scene [parameters] value (repeatable)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a fixed plant parameter (repeatable)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a fixed controller setting (repeatable)")
    p.add_argument("--duration", type=float, default=300.0,
                   help="simulated time per point, s (controller, annual_energy; 300)")
    p.add_argument("--dt", type=float, help=f"time step, s ({default_help('sweep.dt')})")
    p.add_argument("--omega-max", type=float, metavar="RAD_S",
                   help="bounds: the top frequency the force may hold (default: the hydro "
                        "data's; lower is faster: the QP grows as its cube)")
    p.add_argument("--max-evals", type=int, default=40, help="optimiser's evaluations (40)")
    p.add_argument("--store", metavar="DIR", help="keep every evaluated point here (resumable)")
    p.add_argument("--workers", type=int, default=0, help="Dask workers for a grid (0: here)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler")
    p.add_argument("--plot", metavar="FILE.png", help="objective against each varied name")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    wave_options(p)
    p.set_defaults(run=run_codesign)


def _floats(item: str, flag: str, sep: str) -> tuple[str, list[float]]:
    name, _, values = item.partition("=")
    try:
        numbers = [float(v) for v in values.split(sep) if v.strip()]
    except ValueError:
        numbers = []
    if not name.strip() or not numbers or (sep == ":" and len(numbers) != 2):
        form = "NAME=LO:HI" if sep == ":" else "NAME=v1,v2,..."
        raise InputError(f"{flag} {item}: expected {form} with numbers")
    return name.strip(), numbers


def run_codesign(args) -> int:
    import inspect

    from mbcontrol.controllers import REGISTRY

    from ..studies.codesign import Spec, codesign
    from ..studies.codesign import UNLIKE
    from .commands import _key_value, parse_settings
    wave = None
    if args.wave != "none" and args.objective != "annual_energy" and not args.seas:
        wave = {"kind": args.wave, "height": args.height, "period": args.period, "hs": args.hs,
                "tp": args.tp, "gamma": args.gamma, "seed": args.seed}
    cls = REGISTRY.get(args.controller) if args.controller else None
    settings = parse_settings(args.set, inspect.signature(cls).parameters if cls else {})
    spec = Spec(model=args.model, objective=args.objective, wave=wave, seas=args.seas,
                controller=args.controller, per=args.per, duration=args.duration, dt=args.dt,
                omega_max=args.omega_max,
                scene_params=tuple(sorted(dict(_key_value(s, "--scene-param")
                                               for s in args.scene_param).items())),
                params=tuple(sorted(dict(_key_value(s, "--param") for s in args.param).items())),
                settings=tuple(sorted(settings.items())))
    vary = dict(_floats(v, "--vary", ",") for v in args.vary or [])
    optimize = {n: tuple(v) for n, v in (_floats(o, "--optimize", ":")
                                         for o in args.optimize or [])}
    if frozenset((args.objective, args.against)) in UNLIKE:   # before any work is done
        raise InputError(f"--against {args.against}: {args.objective} is absorbed "
                         f"(mechanical) energy; compare it with mechanical_bound")
    result = codesign(spec, vary=vary or None, optimize=optimize or None, store=args.store,
                      workers=args.workers, scheduler=args.scheduler,
                      max_evals=args.max_evals, progress=not args.json)
    unit = spec.unit
    if args.against:
        import dataclasses

        from ..studies.codesign import compare_optima
        other = dataclasses.replace(spec, objective=args.against)
        kw = dict(vary=vary) if vary else dict(at=[p["params"] for p in result["points"]])
        result["against"] = codesign(other, store=args.store, workers=args.workers,
                                     scheduler=args.scheduler, progress=not args.json, **kw)
        result["comparison"] = compare_optima(result, result["against"])
    if args.plot:
        from ..studies.codesign import plot_codesign
        plot_codesign(result, args.plot, unit + (f" per {args.per}" if args.per else ""))
    if args.json:
        print(json.dumps(result, indent=2, default=float))
        return 0
    print(f"{result['provenance']['model']}: {result['objective_name']} ({unit}), "
          f"{result['search']}: {result['computed']} points computed, {result['reused']} "
          f"reused, {result['wall_time_s']:.1f} s")
    for p in result["points"]:
        values = ", ".join(f"{k} {v:.5g}" for k, v in p["params"].items())
        value = "failed" if p["objective"] is None else f"{p['objective']:.6g}"
        flag = "" if p["valid"] else "  INVALID: " + "; ".join(p["reasons"])[:200]
        print(f"  {values}: {value}{flag}")
    best = result["best"]
    if best is None:
        print("  no valid point", file=sys.stderr)
        return 1
    print(f"  best: {', '.join(f'{k} {v:.5g}' for k, v in best['params'].items())}: "
          f"{best['objective']:.6g} {unit}")
    if "comparison" in result:
        from ..studies.codesign import describe_comparison
        print("  " + describe_comparison(result["comparison"], unit))
    return 0
