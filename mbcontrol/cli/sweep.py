"""`mbcontrol sweep`: a model's power over sea states and settings, closed loop, on Dask."""
from __future__ import annotations

import json
import sys

from .. import defaults
from ..errors import InputError
from .describe import default_help
from .messages import without_remedies

SWEEP_HELP = """Simulate a model in closed loop over sea states (an Hs x Tp grid or a weighted
list), wave seeds and varied settings, and report power, capture width and annual energy.

Each case is a JONSWAP sea simulated for --duration s with the chosen controller (default:
the scene's PTO law); its metrics are those of `simulate --json` (mean and electrical power,
PAPR, F98, stroke, limit violations). Cases run on a local Dask cluster (--workers N, default
one per core; 0 runs them in this process) or on an existing one (--scheduler ADDRESS).
With --store DIR each finished case is kept in DIR/cases, so an interrupted sweep resumes
where it stopped and a rerun with the same inputs computes nothing; DIR/sweep.nc holds the
labelled result (xarray). --vary NAME=v1,v2 adds a dimension: NAME is a scene parameter,
a plant parameter, a setting of the controller, or `direction` (wave headings in degrees, among
the hydro data's).

Short-crested seas: a --seas file's columns `direction` (degrees, NED: where the waves travel
to, +x towards +y) and `spread` (degrees, the directional spread sigma, the circular standard
deviation), per sea, or --spread DEG for every sea (it overrides the file's), with the
spreading function --spreading cos2s (default; one s = 2 / sigma^2 - 1) or mitsuyasu (Goda's
s_max (f / fp)^5 below the peak, ^-2.5 above; sigma at the peak). Each component travels in
its own direction, drawn stratified from the spreading function; the hydro data need headings
around the mean (mbcontrol.hydro.headings_for_spread: mean +- 3 sigma on 15 deg steps, or the
whole circle, which then keeps the whole spreading function).

A farm: --isolated NAME=VALUE (scene parameters that make one device out of the farm's scene,
e.g. n=1 for array_grid) also runs the lone device over the same cases and reports the q-factor
per sea, q = farm power / (devices x power of one device alone), and the same ratio of the annual
energies (module mbcontrol.studies.farm).

The --json summary is a contract: {"model", "cases", "computed", "reused", "wall_time_s",
"valid_cases", "invalid_cases", "invalid": [{"hs", "tp", "seed", "reasons"}], "failed_cases",
"failed": [{"hs", "tp", "seed", "reasons"}], "notes", "seas": [{"hs", "tp", "weight",
"mean_power_W", "capture_width_m", "energy_flux_W_per_m", "invalid_cases", "failed_cases",
...}], "weighted_mean_power_W", "annual_energy_MWh",
"annual_energy_coverage", "annual_energy_unchecked_MWh", "provenance":
{"model", "version", "scene_sha256", "hydro_sha256", "radiation_sha256", "controller",
"settings", "amplitudes"}, and with --isolated "farm": {"devices", "isolated_devices",
"isolated_scene_params", "q_factor", "annual_energy_isolated_MWh", "q_annual",
"isolated_invalid_cases", "isolated_wall_time_s"} and "q_factor" per sea, and with
--nonlinear invalid per sea "nonlinear_cases" (cases whose linear run left the linear
range and ran on the nonlinear plant) and "linear_mean_power_W" (those linear runs' mean,
INVALID, for comparison; null where none), and with
--design per sea "settings" (the tuned values), "predicted_power_W", "bound_W",
"percent_of_bound", "inside_envelope" and "meets_robustness_floors", and with a PTO
rated_power "rated_power_W" (the weighted figures then cap each sea's power at it), and with
--seeds N >= 2 per sea "valid_seeds", "mean_power_stderr_W" and "mean_power_ci95_W" [lo,
hi] (Student's t over the valid seeds) with "power_std_W", "power_min_W", "power_max_W"
(IEC TS 62600-100 Annex D's per-bin statistics), and for a linear law (the scene's PTO law,
passive, reactive; nothing varied) per sea "spectral_cv" (one record's mean power: its
standard deviation over records / mean, from the frequency-domain solution), "bandwidth_hz"
(B_s of the power density), "effective_samples" (valid seeds / cv^2) and
"spectral_stderr_W" and "expected_power_W" (linear theory's, for a spread sea the
spreading-weighted sum over directions), per sea "direction_deg", "spread_deg" and
"spreading" when given, and for a weighted list "annual_energy_ci95_MWh" [lo, hi] and
"annual_energy_budget": {"components": [{"component" (statistical, model, radiation_fit,
parameters, resource), "type" (A or B), "over_seas" (quadrature, linear, one term),
"std_MWh" (null when absent), "dof", "source", "absent" (why not, or null),
"share_of_variance"}], "combined_std_MWh", "effective_dof", "coverage_factor", "method"},
and with --identified per sea "model_std_W" and "parameter_std_W"}
(per sea, means over the valid seeds; lists over the varied values when --vary
is given; weighted figures only for a weighted --seas file; a sea with no valid case counts
as producing nothing there, the share of the year that is valid is annual_energy_coverage,
and annual_energy_unchecked_MWh is the figure the failed cases would have given).

Error bars: --seeds N (N >= 2) gives each sea its standard error and 95 % interval over
records; --amplitudes random makes each record a real sea's (Rayleigh amplitudes: what a
20-minute measured record scatters by; use --duration 1200 as IEC's sea tests do), while the
default deterministic amplitudes estimate the expected power. The annual energy's budget adds,
in quadrature, the statistical part (each sea's standard error over its seeds, or with one
seed of a linear law the spectral estimate), the radiation fit's effect (linear laws), the
model's error and the parameters' covariance of an identification (--identified
summary.json: its values are run, its calibrated error (else its validation error) is the
model error, its covariance goes through linear theory's sensitivities), and the resource's interannual variability when
the --seas file has weights_<year> columns; a part that cannot be evaluated is listed as
absent with the reason.

Every case is checked like `simulate`'s results (power bound of its own wave, energy
balance, linear-hydrodynamics range); a case that fails is counted and listed, never
averaged. A case whose run raises (a divergence, a solver that gave up) is a result too:
counted in failed_cases with its sea, seed and reason, never averaged; the other cases run
and the JSON and store are written. Controllers run causally: an MPC forecasts the excitation from what it measures
(AR) unless --set forecast=known (an oracle: a non-causal upper bound, labelled so in
provenance.settings). A store remembers the inputs it was made from (content hashes of the
scene, hydro data and radiation fit, and the package version) and refuses others.
--set values are numbers, true/false, none or words (--set forecast=ar).

Per-sea design: with --design the controller is tuned for each sea state as `mbcontrol
design` tunes it for one (passive, reactive: linear theory within the PTO's force and stroke
limits and inside the linear model's envelope: each body's predicted significant heave
relative to the surface within 90 % of its mean draft, roll and pitch within 90 % of 30 deg;
latching, declutching: their simulated tuners; mpc: a horizon of one peak period). A sea where
no setting stays inside is flagged (inside_envelope false; the closest setting runs). bound_W
is the most any PTO force could absorb in that sea inside the same envelope (linear theory,
mbcontrol.analysis.envelope), so percent_of_bound says how much a law leaves. --set values
override the tuned ones. --robust keeps a reactive law within the robustness floors (gain
margin 2, phase margin 30 deg at the least; otherwise laws below them are only flagged,
meets_robustness_floors). Without --design, a damped law named with no settings absorbs
nothing, and says so on stderr.

Examples:
  mbcontrol sweep rm3 --hs 1 2 3 --tp 8 10 12 --duration 300 --store out/rm3 --plot pm.png
  mbcontrol sweep oswec --seas ../shared/data/sites/pacwave_cluster_32.csv --width 18 --json
  mbcontrol sweep rm3 --seas ../shared/data/sites/pacwave_cluster_32.csv --controller reactive \
      --design --json
  mbcontrol sweep sphere --hs 1 2 3 --tp 8 10 --controller passive --set damping=4e5 \
      --seeds 4 --amplitudes random --json
  mbcontrol sweep oswec --seas ../shared/data/sites/pacwave_cluster_32.csv --spread 30 --json
  mbcontrol sweep array_grid --scene-param n=3 --scene-param scale=25 --isolated n=1 \
      --seas ../shared/data/sites/pacwave_cluster_32.csv --vary direction=0,45
"""


def add_parser(sub) -> None:
    import argparse
    p = sub.add_parser("sweep", help="power over sea states and settings (Dask)",
                       description=SWEEP_HELP, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    seas = p.add_mutually_exclusive_group(required=True)
    seas.add_argument("--hs", type=float, nargs="+", help="significant wave heights, m")
    seas.add_argument("--seas", metavar="FILE.csv",
                      help="sea states: columns Hm0 and Tp (or Te), optional weights")
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
    p.add_argument("--robust", action="store_true",
                   help="with --design: a reactive law within the robustness floors (gain "
                        "margin 2, phase margin 30 deg at the least)")
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


def run_sweep(args) -> int:
    import inspect

    from mbcontrol.controllers import REGISTRY

    from ..studies.sweep import sweep
    from .commands import _key_value, _warn_if_absorbs_nothing, parse_settings
    seas = _seas(args)
    if args.set and not args.controller:
        raise InputError("--set needs --controller")
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
    else:
        from ..waves import read_year_weights
        years = read_year_weights(args.seas) if args.seas else None
        ds, summary = sweep(args.model, seas, scene_params=scene_params, design=args.design,
                            robust=args.robust, identified=args.identified, years=years,
                            nonlinear=args.nonlinear, **common)
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
    """The seas of --hs/--tp (a grid) or --seas (a site file), spread as asked."""
    from ..studies.sweep import grid, read_seas
    if args.hs is not None:
        if not args.tp:
            raise InputError("--hs needs --tp (the grid's peak periods)")
        seas = grid(args.hs, args.tp, args.gamma)
    else:
        if args.tp:
            raise InputError("--tp goes with --hs; a --seas file gives its own periods")
        seas = read_seas(args.seas, args.gamma)
    return spread_seas(seas, args.spread, args.spreading)


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
              f"{_kN(row.get('mooring_mpm_3h_N')):>9s}")


def _kN(value) -> str:
    return f"{value / 1e3:.4g}" if isinstance(value, float) else "-"


def _print_summary(summary: dict, store) -> None:
    """The sweep's text report: a row per sea, notes, invalid and failed cases, the annual
    energy with its interval and budget, a farm's q factor."""
    print(f"{summary['model']}: {summary['cases']} cases ({summary['computed']} computed, "
          f"{summary['reused']} reused) in {summary['wall_time_s']:.1f} s")
    farm = summary.get("farm")
    print(f"  {'Hs m':>6s} {'Tp s':>6s} {'weight':>8s} {'power kW':>10s} {'CW m':>8s} {'J kW/m':>8s}"
          + (f" {'q':>6s}" if farm else ""))
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
              f"{row['energy_flux_W_per_m'] / 1e3:8.3g}{q_text}")
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
                  f"{case['seed']}: {reasons}")
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
    if farm and farm["q_annual"] is not None:
        print(f"  farm of {farm['devices']} devices: annual energy {summary['annual_energy_MWh']:.4g} MWh "
              f"against {farm['annual_energy_isolated_MWh']:.4g} MWh for as many devices alone: "
              f"q = {farm['q_annual']:.3f}")
    if store:
        print(f"wrote {store}/sweep.nc", file=sys.stderr)
