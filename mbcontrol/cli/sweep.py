"""`mbcontrol sweep`: a model's power over sea states and settings, closed loop, on Dask."""
from __future__ import annotations

import json
import sys

from .. import defaults
from ..errors import InputError
from .describe import default_help
from .helptext import SWEEP_HELP
from .messages import without_remedies


def add_parser(sub) -> None:
    import argparse
    p = sub.add_parser("sweep", help="power over sea states and settings (Dask)",
                       description=SWEEP_HELP, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    seas = p.add_mutually_exclusive_group(required=True)
    seas.add_argument("--hs", type=float, nargs="+", help="significant wave heights, m")
    seas.add_argument("--seas", metavar="FILE.csv",
                      help="sea states: columns Hm0 and Tp (or Te), optional weights")
    seas.add_argument("--records", metavar="DIR",
                      help="measured seas: every file of DIR a free-surface elevation record\n"
                           "(two columns, time s and elevation m, as simulate's --eta), one\n"
                           "case each, run for its own length unless --duration; no annual\n"
                           "energy (records have no weights)")
    p.add_argument("--tp", type=float, nargs="+", help="peak periods, s (with --hs)")
    p.add_argument("--gamma", type=float, default=3.3, help="JONSWAP peak enhancement (3.3)")
    p.add_argument("--controller", help="controller name (default: the scene's PTO law)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="controller setting (repeatable)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="plant parameter value (repeatable)")
    p.add_argument("--scene-param", action="append", default=[], metavar="NAME=VALUE",
                   help="scene [parameters] value (repeatable)")
    p.add_argument("--vary", action="append", default=[], metavar="NAME=v1,v2,...",
                   help="a swept quantity (repeatable): one dimension per name")
    p.add_argument("--isolated", action="append", default=[], metavar="NAME=VALUE",
                   help="a farm: scene parameters of one device alone (repeatable); adds the q-factor")
    p.add_argument("--design", action="store_true",
                   help="tune the controller for each sea as `design` does (settings and "
                        "bound_W per sea in the JSON)")
    p.add_argument("--aggressive", action="store_true",
                   help="with --design: each sea's unconstrained optimum; by default a reactive\n"
                        "law is tuned within the robustness floors, as `design` tunes it\n"
                        "(design.gain_margin_min, design.phase_margin_min_deg)")
    p.add_argument("--robust", action="store_true", help=argparse.SUPPRESS)   # the default now
    p.add_argument("--spread", type=float, metavar="DEG",
                   help="short-crested seas: every sea's directional spread sigma, degrees\n"
                        "(0 long-crested, below 81; overrides a --seas file's spread column)")
    p.add_argument("--spreading", choices=("cos2s", "mitsuyasu"), default=None,
                   help="the spreading function (cos2s: one s; mitsuyasu: s peaks at Tp)")
    p.add_argument("--seeds", type=int, default=1, help="wave realisations per sea (1)")
    p.add_argument("--amplitudes", choices=("deterministic", "random"), default="deterministic",
                   help="deterministic: a = sqrt(2 S dw), the expected power (default); random: "
                        "Rayleigh amplitudes, a record's statistics")
    p.add_argument("--nonlinear", choices=("scene", "invalid", "always"), default="scene",
                   help="scene: the scene's own hydrostatics (default); invalid: the linear\n"
                        "plant, and for seas whose run leaves the linear range the nonlinear\n"
                        "one (hydrostatics and Froude-Krylov over the instantaneous wetted\n"
                        "surface) with the same controller; always: the nonlinear plant for\n"
                        "every sea. Needs each hydro body's [body.geometry]")
    p.add_argument("--identified", metavar="SUMMARY.json",
                   help="an identification of this model (`identify --json` or its\n"
                        "summary.json): its parameter values are run, and its model error\n"
                        "and covariance enter the annual energy's budget")
    p.add_argument("--resource", nargs="+", metavar="NDBC",
                   help="buoy records (NOAA NDBC spectral density files, text or .gz) for the\n"
                        "budget's resource term: each hour to the nearest --seas sea; one file\n"
                        "per year (the years' spread), or one year: monthly blocks (an upper\n"
                        "estimate: months taken as exchangeable)")
    p.add_argument("--duration", type=float,
                   help=f"simulated time per case, s ({default_help('sweep.duration')})")
    p.add_argument("--dt", type=float, help=f"time step, s ({default_help('sweep.dt')})")
    p.add_argument("--method", help="fixed-step integration method "
                                    f"({default_help('sweep.method')})")
    run = p.add_mutually_exclusive_group()
    run.add_argument("--workers", type=int,
                     help="local Dask workers (-1: one per core; 0: no Dask; "
                          f"{default_help('sweep.workers')})")
    run.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler")
    p.add_argument("--store", metavar="DIR", help="keep cases and sweep.nc here (resumable)")
    p.add_argument("--width", type=float, help="characteristic width, m (capture width ratio)")
    p.add_argument("--plot", metavar="FILE.png", help="power matrix, capture width, energy")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--domain", choices=("time", "frequency", "both"), default="time",
                   help="time: simulate (default); frequency: a linear law's linear theory, every sea\n"
                        "in milliseconds, and its complex-conjugate bound; both: side by side")
    p.add_argument("--allow-invalid", action="store_true",
                   help="exit 0 even when cases fail their physics checks (they are still left\n"
                        "out of every figure); exit status 3 without this flag, 4 when cases\n"
                        "failed to run")
    p.set_defaults(run=run_sweep)


def _design_line(row: dict) -> str:
    """A --design sea's tuned settings and its share of the bound, in one line."""
    settings = ", ".join(f"{k} {v:.4g}" for k, v in (row["settings"] or {}).items()
                         if isinstance(v, float))
    bound = row["bound_W"]
    share = (f"{row['percent_of_bound']:.0f} % of its bound {bound / 1e3:.4g} kW"
             if row["percent_of_bound"] is not None else
             f"bound {bound / 1e3:.4g} kW" if bound is not None else "no bound inside the envelope")
    outside = "" if row["inside_envelope"] else "; OUTSIDE its envelope"
    fragile = "" if row["meets_robustness_floors"] else "; below the robustness floors"
    return f"designed: {settings}; {share}{outside}{fragile}"


def spread_seas(seas, spread_deg: float | None, kind: str | None):
    """The seas with --spread (degrees, sigma; for every sea) and --spreading applied."""
    import dataclasses
    import math

    from ..waves import SPREAD_MAX_DEG
    if spread_deg is not None:
        if not 0 <= spread_deg < SPREAD_MAX_DEG:
            raise InputError(f"--spread {spread_deg:g}: expected a directional spread sigma from "
                             f"0 (long-crested) to below {SPREAD_MAX_DEG:.2f} degrees")
        seas = [dataclasses.replace(s, spread=math.radians(spread_deg)) for s in seas]
    if kind is not None:
        seas = [dataclasses.replace(s, spreading=kind) for s in seas]
    return seas


def _workers(given: int | None) -> int | None:
    """--workers (else the \"sweep.workers\" default) as sweep() takes it: -1 -> None (one per
    core), 0 serial, N."""
    n = defaults.resolve("sweep.workers", given)
    if n < -1:
        raise InputError(f"--workers {n}: expected -1 (one per core), 0 (serial) or a count")
    return None if n == -1 else n


# flags the frequency-domain sweep does not take (attributes of args): the first group also
# under --domain both (they change the plant or the cases), the second under frequency alone
_NOT_FREQUENCY = ("records", "isolated", "design", "vary", "identified")
_TIME_ONLY = ("store", "resource")


def _check_domain(args) -> None:
    """InputError for a flag the --domain frequency (or both) sweep does not take."""
    alone = args.domain == "frequency"
    given = [f"--{name}" for name in _NOT_FREQUENCY + (_TIME_ONLY if alone else ())
             if getattr(args, name) not in (None, [], False)]
    given += [flag for flag, other in (("--nonlinear", args.nonlinear != "scene"),
                                       ("--seeds", alone and args.seeds != 1),
                                       ("--amplitudes", alone and args.amplitudes != "deterministic"))
              if other]
    if given:
        raise InputError(f"{given[0]} with --domain {args.domain}: not built (linear theory's "
                         f"expected power of one linear law per long-crested sea); run "
                         f"--domain time")


def run_sweep(args) -> int:
    import inspect

    from mbcontrol.controllers import REGISTRY

    from ..studies.sweep import sweep
    from .commands import _key_value, _warn_if_absorbs_nothing, parse_settings
    if args.domain != "time":
        _check_domain(args)
    seas = _seas(args)
    if args.set and not args.controller:
        raise InputError("--set needs --controller")
    if args.aggressive and not args.design:
        raise InputError("--aggressive asks the tuner for each sea's unconstrained optimum: it "
                         "goes with --design")
    cls = REGISTRY.get(args.controller) if args.controller else None
    settings = parse_settings(args.set, inspect.signature(cls).parameters if cls else {})
    vary = _vary(args.vary)
    if not args.design:
        _warn_if_absorbs_nothing(args.controller, settings, vary)
    common = dict(seeds=args.seeds, vary=vary, params=dict(_key_value(s, "--param") for s in args.param),
                  controller=args.controller, settings=settings, duration=args.duration, dt=args.dt,
                  method=args.method, store=args.store, workers=_workers(args.workers),
                  scheduler=args.scheduler, width=args.width, progress=not args.json,
                  amplitudes=args.amplitudes)
    scene_params = dict(_key_value(s, "--scene-param") for s in args.scene_param)
    if args.isolated:
        if args.identified:
            raise InputError("--identified with --isolated: not built (a farm's budget); "
                             "sweep one device with --identified instead")
        if args.nonlinear != "scene":
            raise InputError("--nonlinear with --isolated: not built (a farm's plant); sweep "
                             "one device with --nonlinear instead")
        if args.design:
            raise InputError("--design with --isolated: not built (a farm's controllers are "
                             "tuned per device); tune one device with --design instead")
        from ..studies import farm_sweep
        ds, summary = farm_sweep(args.model, seas, scene_params=scene_params,
                                 isolated=dict(_key_value(s, "--isolated") for s in args.isolated), **common)
    elif args.domain == "frequency":
        from ..studies.sweep import frequency_sweep
        ds, summary = frequency_sweep(args.model, seas, controller=args.controller,
                                      settings=settings, params=common["params"],
                                      scene_params=scene_params, duration=args.duration,
                                      width=args.width)
    else:
        years = _years(args, seas)
        ds, summary = sweep(args.model, seas, scene_params=scene_params, design=args.design,
                            robust=not args.aggressive, identified=args.identified, years=years,
                            nonlinear=args.nonlinear, records=args.records, **common)
        if args.domain == "both":
            from ..studies.sweep import compare_domains, frequency_sweep
            summary = compare_domains(summary, frequency_sweep(
                args.model, seas, controller=args.controller, settings=settings,
                params=common["params"], scene_params=scene_params,
                duration=args.duration, width=args.width)[1])
    if args.plot:
        from ..studies.sweep import plot_sweep
        plot_sweep(ds, summary, args.plot)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        _print_summary(summary, args.store)
    if summary["failed_cases"]:
        return FAILED_EXIT
    return INVALID_EXIT if summary["invalid_cases"] and not args.allow_invalid else 0


INVALID_EXIT = 3     # cases failed their physics checks (as `simulate` for one result)
FAILED_EXIT = 4      # cases failed to run (diverged or raised): the sweep is incomplete


def _seas(args) -> list:
    """The seas of --hs/--tp (a grid) or --seas (a site file), spread as asked; None for
    --records (the sweep reads the folder)."""
    from ..studies.sweep import grid, read_seas
    if args.records is not None:
        given = [flag for flag, value in (("--tp", args.tp), ("--spread", args.spread),
                                          ("--spreading", args.spreading),
                                          ("--isolated", args.isolated))
                 if value not in (None, [])]
        if given:
            raise InputError(f"{given[0]} with --records: a record is one measured sea, "
                             f"long-crested at a point, of one device's scene; leave "
                             f"{given[0]} out")
        return None
    if args.hs is not None:
        if not args.tp:
            raise InputError("--hs needs --tp (the grid's peak periods)")
        seas = grid(args.hs, args.tp, args.gamma)
    else:
        if args.tp:
            raise InputError("--tp goes with --hs; a --seas file gives its own periods")
        seas = read_seas(args.seas, args.gamma)
    return spread_seas(seas, args.spread, args.spreading)


def _years(args, seas):
    """The budget's resource blocks: a site file's weights_<year> columns, or --resource."""
    from ..waves import read_year_weights
    years = read_year_weights(args.seas) if args.seas else None
    if args.resource:
        if not args.seas:
            raise InputError("--resource needs --seas (a weighted site whose seas the buoy's "
                             "hours are assigned to)")
        if years:
            raise InputError(f"--resource with {args.seas}'s weights_<year> columns: give one "
                             f"source of year-to-year variability")
        from ..studies.sweep import ndbc_resource
        return ndbc_resource(args.resource, seas)
    return years


def _vary(items: list[str]) -> dict:
    """--vary NAME=v1,v2,... as {name: [values]}."""
    vary = {}
    for item in items:
        name, _, values = item.partition("=")
        try:
            vary[name.strip()] = [float(v) for v in values.split(",") if v.strip()]
        except ValueError:
            raise InputError(f"--vary {item}: expected NAME=v1,v2,... with numbers") from None
        if not vary[name.strip()]:
            raise InputError(f"--vary {item}: expected NAME=v1,v2,... with at least one value")
    return vary


def _print_mooring_loads(rows: list) -> None:
    """MoorDyn moorings: the sea's design loads beside its power, largest over lines and seeds."""
    if not any("mooring_max_N" in row for row in rows):
        return
    print("  mooring loads, the most loaded fairlead (kN; the largest over seeds; a 3-h MPM below "
          "the record's max marks snap loads, where it does not hold):")
    print(f"  {'Hs m':>6s} {'Tp s':>6s} {'max':>9s} {'3-h MPM':>9s}")
    for row in rows:
        print(f"  {row['hs']:6.3g} {row['tp']:6.3g} {_kN(row.get('mooring_max_N')):>9s} "
              f"{_kN(row.get('mooring_mpm_3h_N')):>9s}{_record(row)}")


def _measured(summary: dict) -> bool:
    """A sweep over measured records (--records): its rows carry their file names."""
    return any("record" in row for row in summary["seas"])


def _record(row: dict, before: str = "  ") -> str:
    """A record's file name for a line of the text report (escaped: a name is data, and
    control characters must not reach the terminal); "" for a sea state."""
    from ..textsafe import plain_text
    name = row.get("record")
    return "" if name is None else before + " " + plain_text(name, 60)


_DOMAIN_HEADER = {"frequency": f" {'bound kW':>10s}",
                  "both": f" {'FD kW':>10s} {'TD/FD-1':>8s} {'bound kW':>10s}"}


def _domain_columns(row: dict, domain: str) -> str:
    """The frequency domain's columns of a row: the complex-conjugate bound (kW); with
    --domain both, linear theory's power (kW) and the simulation's relative difference."""
    kw = lambda v: f"{v / 1e3:10.4g}" if isinstance(v, float) else f"{'-':>10s}"  # noqa: E731
    diff = row.get("relative_difference")
    return {"time": "", "frequency": f" {kw(row.get('conjugate_bound_W'))}"}.get(domain, (
        f" {kw(row.get('frequency_domain_power_W'))} "
        f"{'-' if diff is None else f'{100 * diff:+.2f}%':>8s} {kw(row.get('conjugate_bound_W'))}"))


def _kN(value) -> str:
    return f"{value / 1e3:.4g}" if isinstance(value, float) else "-"


def _print_summary(summary: dict, store) -> None:
    """The sweep's text report: a row per sea, notes, invalid and failed cases, the annual
    energy with its interval and budget, a farm's q factor."""
    domain = summary.get("domain", "time")
    if domain == "frequency":
        print(f"{summary['model']}: {summary['cases']} seas in the frequency domain (linear "
              f"theory) in {1e3 * summary['compute_time_s']:.3g} ms after the plant was built")
    else:
        print(f"{summary['model']}: {summary['cases']} cases ({summary['computed']} computed, "
              f"{summary['reused']} reused) in {summary['wall_time_s']:.1f} s")
    farm = summary.get("farm")
    print(f"  {'Hs m':>6s} {'Tp s':>6s} {'weight':>8s} {'power kW':>10s} {'CW m':>8s} {'J kW/m':>8s}"
          + (f" {'q':>6s}" if farm else "") + ("   record" if _measured(summary) else "")
          + _DOMAIN_HEADER.get(domain, ""))
    for row in summary["seas"]:
        power = row["mean_power_W"]
        text = f"{power / 1e3:10.4g}" if isinstance(power, float) else "  (varied)"
        if row.get("mean_power_ci95_W"):
            lo, hi = row["mean_power_ci95_W"]
            text += f" ±{(hi - lo) / 2e3:.3g}"
        cw = row["capture_width_m"]
        cw_text = f"{cw:8.3g}" if isinstance(cw, float) else "    -"
        weight = f"{row['weight']:8.4f}" if row["weight"] is not None else "       -"
        q = row.get("q_factor")
        q_text = "" if not farm else f" {q:6.3f}" if isinstance(q, float) else "  (varied)"
        print(f"  {row['hs']:6.3g} {row['tp']:6.3g} {weight} {text} {cw_text} "
              f"{row['energy_flux_W_per_m'] / 1e3:8.3g}{q_text}{_record(row)}"
              + _domain_columns(row, domain))
        if "bound_W" in row:
            print(f"         {_design_line(row)}")
    _print_mooring_loads(summary["seas"])
    for note in summary["notes"]:
        print(f"  note: {note}")
    remedies = []
    for label, key in (("INVALID", "invalid"), ("FAILED", "failed")):
        for case in summary[key][:10]:
            reasons, found = without_remedies(str(case["reasons"]))
            remedies += [r for r in found if r not in remedies]
            print(f"  {label} Hs {case['hs']:.3g} m, Tp {case['tp']:.3g} s, seed "
                  f"{case['seed']}{_record(case, ' record')}: {reasons}")
        if len(summary[key]) > 10:
            print(f"  ... and {len(summary[key]) - 10} more {label.lower()} cases (--json lists all)")
    for remedy in remedies:
        print(f"  remedy: {remedy}")
    if summary["annual_energy_MWh"] is not None:
        share = summary["annual_energy_coverage"]
        print(f"  weighted mean power {summary['weighted_mean_power_W'] / 1e3:.4g} kW; annual "
              f"energy {summary['annual_energy_MWh']:.4g} MWh"
              + ("" if share == 1 else f" (valid seas only: {100 * share:.3g} % of the year; a "
                                       f"lower bound)"))
    if summary.get("annual_energy_ci95_MWh"):
        from ..studies.sweep import budget_table
        lo, hi = summary["annual_energy_ci95_MWh"]
        print(f"  annual energy 95 % interval [{lo:.4g}, {hi:.4g}] MWh; its budget:")
        print("\n".join("    " + line for line in budget_table(summary["annual_energy_budget"])
                        .splitlines()))
    if summary.get("annual_electrical_energy_ci95_MWh"):
        from ..studies.sweep import budget_table
        lo, hi = summary["annual_electrical_energy_ci95_MWh"]
        print(f"  electrical annual energy {summary['annual_electrical_energy_MWh']:.4g} MWh "
              f"(absorbed {summary['annual_energy_MWh']:.4g} MWh), 95 % interval "
              f"[{lo:.4g}, {hi:.4g}] MWh; its budget:")
        print("\n".join("    " + line for line in
                        budget_table(summary["annual_electrical_energy_budget"]).splitlines()))
    if farm and farm["q_annual"] is not None:
        print(f"  farm of {farm['devices']} devices: annual energy {summary['annual_energy_MWh']:.4g} MWh "
              f"against {farm['annual_energy_isolated_MWh']:.4g} MWh for as many devices alone: "
              f"q = {farm['q_annual']:.3f}")
    if store:
        print(f"wrote {store}/sweep.nc", file=sys.stderr)
