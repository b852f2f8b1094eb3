"""`mbcontrol identify`: fit a model's unknown parameters to measured tank runs."""
from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path

from ..errors import InputError
from .describe import default_help

IDENTIFY_HELP = """Fit a model's unknown parameters so it reproduces measured regular-wave runs.

Data files follow the flume dataset's naming SPPH[_R] (../shared/data/tank, its README): series
3-6 free different DOFs, which the model's joints of the same names follow (the blocked one is
frozen). The incident wave at the model comes from the calibration runs (default: the
'calibration' folder beside the data files' folder). Each run is simulated from rest into its
steady window, driven by its own measured incident wave; each run is one call of the plant's
compiled integrator (compiled once per series), with exact sensitivities for Gauss-Newton.
Record units are read from the headers ("Sway [mm]") and converted to SI; an unknown unit, a
channel of the wrong kind, a record cut before its steady window closes or a window of fewer
than 3 whole periods is refused naming the file (--drop-bad: skipped and listed).

--fit NAME[=LO:HI] names a plant parameter (PTO, friction, springs, drag) or a hydrodynamic
correction <body>__<Dof>__{added_mass,radiation,excitation}_scale (dimensionless: A(inf);
the radiation kernel B(w) + jw(A(w) - A(inf)); the excitation force); without bounds they come
from the scene's [identify] table, which is also the default set. Positive bounds fit the
logarithm. Costs: harmonic (relative error of first-harmonic amplitudes, dimensionless;
--phase adds the phase error, rad), peaks (the seed's Eq. 67 on peaks and lows, per channel
scale), timeseries (output error over the window). Prints the parameter table with standard
errors (Gauss-Newton Hessian scaled by the residual variance), the amplitude errors per channel
before and after (beside the spread of repeated runs, the data's floor), and --validate runs
predicted with the fitted values, each with a 95 % prediction interval ("predictions" in
--json); runs outside the fitted runs' frequencies or above the radiation fit are warned about
and crossed on the figures.

The interval (interval_95) is calibrated on the fitted runs' own errors: --validate now refits
per fold (one fit per series left out, or up to 5 folds of frequencies when the fitted runs
are one series; 36 s for the three folds of the 31 flume runs) and takes CV+ (jackknife+,
Barber et al. 2021) over the held-out scores |measured - model| / (model sqrt(1 + (0.3 dln a /
dln omega)^2)): relative, widened on resonance flanks. Guarantee: if the new runs are
exchangeable with the fitted ones, coverage >= 1 - 2 alpha - O(K/n) in the worst case (about
84 % for 62 scores in 3 folds), about 95 % in practice; none for runs unlike them (another
wave height: the relative score is what carries over). It is the hull of the CV+ interval and
the parametric one (parameter covariance and repeatability, kept per row as
interval_95_parametric, sigma_parameters, sigma_repeatability); the --json "calibration"
block states method, folds, score, n_scores, quantile and guarantee; the text report counts
the amplitudes inside both. 9-18 scores (runs x channels): too few for 95 %, the largest score
is used (nominal n/(n + 1), said); fewer: the parametric interval is kept, the block says why.

--cross-validate replaces the fit by leave-one-series-out cross-validation of candidate
structures (--candidate NAME=SPEC,SPEC...): each series predicted by a fit on the others, the
held-out RMS relative amplitude error per channel and pooled, the best (fewest parameters
within 1 %) marked.

A measured elevation record (simulate's --wave elevation --eta FILE) is not an input here:
every run is a regular wave of one frequency (from its file name), its wave at the model is
rebuilt from the calibration runs without the model (a probe beside the model measures the
waves it diffracts and radiates too, not the incident wave), and each cost compares motions
at that frequency over whole periods of it.

Example:
  mbcontrol identify flume_section --data ../shared/data/tank/scenario_c/5*.csv.xz \\
      --validate ../shared/data/tank/scenario_c/6*.csv.xz --out out/identify
"""


PREDICTION_KEYS = ("run", "channel", "omega", "unit", "measured", "model", "sigma",
                   "sigma_parameters", "sigma_repeatability", "interval_95",
                   "interval_95_parametric", "extrapolated")


def add_parser(sub) -> None:
    import argparse
    p = sub.add_parser("identify", help="fit parameters to measured tank runs",
                       description=IDENTIFY_HELP, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("model", help="catalogue name or path to a scene .toml")
    p.add_argument("--data", nargs="+", required=True, metavar="FILE",
                   help="measured runs (flume naming SPPH[_R].csv[.xz])")
    p.add_argument("--calibration", metavar="DIR",
                   help="calibration runs 1PPH[_R] (default: 'calibration' beside the data folder)")
    p.add_argument("--fit", action="append", default=[], metavar="NAME[=LO:HI]",
                   help="a parameter to fit (repeatable; default: the scene's [identify] table)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="a fixed parameter value (repeatable)")
    p.add_argument("--method", choices=("gauss-newton", "nelder-mead"),
                   help=f"optimiser ({default_help('identify.method')})")
    p.add_argument("--cost", choices=("harmonic", "peaks", "timeseries"), default="harmonic")
    p.add_argument("--phase", action="store_true", help="harmonic cost: fit phases too")
    p.add_argument("--starts", type=int, default=1, help="multi-start: random starts in the bounds")
    p.add_argument("--validate", nargs="+", default=[], metavar="FILE",
                   help="runs to predict with the fitted values (not fitted), with 95 %%\n"
                        "intervals calibrated by refitting per fold of the fitted runs (CV+)")
    p.add_argument("--dt", type=float, help=f"simulation step, s ({default_help('identify.dt')})")
    p.add_argument("--settle", type=float,
                   help="simulated time before each steady window, s (the flume model's "
                        f"lightly damped 8 s sway mode needs 60; {default_help('identify.settle')})")
    p.add_argument("--drop-bad", action="store_true",
                   help="skip unusable runs with a warning instead of stopping")
    p.add_argument("--out", metavar="DIR", help="write summary.json, tables and figures here")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--cross-validate", action="store_true",
                   help="instead of one fit: leave each series out in turn, fit on the others,\n"
                        "predict it; per candidate structure (--candidate; default the --fit\n"
                        "set or the scene's [identify] table), the held-out errors and the best")
    p.add_argument("--candidate", action="append", default=[], metavar="NAME=SPEC[,SPEC...]",
                   help="a candidate structure for --cross-validate: the parameters to fit,\n"
                        "--fit specs joined by commas (repeatable), e.g.\n"
                        "'coulomb=viscous__Roll_linear,sway_rig__coulomb=0.05:2'")
    p.set_defaults(run=run_identify)


def _candidates(args) -> dict:
    """name -> fit specs from --candidate (default: the --fit set, or the scene's table)."""
    out = {}
    for text in args.candidate:
        name, _, specs = text.partition("=")
        if not name or not specs:
            raise InputError(f"--candidate {text}: expected NAME=SPEC[,SPEC...]")
        out[name] = [s for s in specs.split(",") if s]
    return out or {"given" if args.fit else "scene [identify]": list(args.fit)}


def _cross_validate(args, runs, common) -> int:
    from ..studies.identify import cross_validate, crossval_table
    cv = cross_validate(args.model, runs, _candidates(args), progress=not args.json, **common)
    if args.json:
        print(json.dumps({"model": args.model, "cross_validation": cv}, indent=2))
    else:
        print(crossval_table(cv))
    return 0


def run_identify(args) -> int:
    from ..studies.identify import (ExtrapolationWarning, amplitude_rows, calibrate,
                                    calibrated_rows, coverage, error_table, errors_block, fit,
                                    flume_identification, identification_summary, load_runs,
                                    parameter_table, prediction, prediction_intervals,
                                    repeatability)
    from .commands import _key_value

    params = dict(_key_value(s, "--param") for s in args.param)
    common = dict(cost=args.cost, phase=args.phase, params=params, dt=args.dt,
                  settle=args.settle)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        runs = load_runs(args.data, args.calibration, drop_bad=args.drop_bad)
        validation = load_runs(args.validate, args.calibration, drop_bad=args.drop_bad) \
            if args.validate else []
        if not args.cross_validate:
            problem = flume_identification(args.model, None, runs=runs, fit=args.fit, **common)
            vproblem = prediction(problem, validation) if validation else None
    for w in caught:
        print(f"mbcontrol: warning: {w.message}", file=sys.stderr)
    if args.cross_validate:
        return _cross_validate(args, runs + validation, common)
    said = [str(w.message) for w in caught if issubclass(w.category, ExtrapolationWarning)]
    before = amplitude_rows(problem, {})      # the scene's own values: the model as built
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fit(problem, args.method, starts=args.starts, progress=not args.json)
    after = amplitude_rows(problem, result.values)
    v_before = v_after = None
    if validation:
        # fixed at the fitted values (those its plants have: a DOF may be blocked there)
        v_before = amplitude_rows(vproblem, {})
        # each with its interval: parameter uncertainty and the fitted runs' repeatability
        v_after = prediction_intervals(vproblem, result, amplitude_rows(vproblem, result.values),
                                       repeatability(after))
        # calibrated on the fitted runs' held-out errors: one refit per fold
        cal = calibrate(args.model, runs, validation, fit=args.fit, method=args.method,
                        progress=not args.json, **common)
        v_after = calibrated_rows(v_after, cal["intervals"])
    summary = identification_summary(problem.scene_name, problem, result, after, v_after)
    summary["warnings"] = said + summary["warnings"]
    if validation:
        summary["predictions"] = [{k: r[k] for k in PREDICTION_KEYS} for r in v_after]
        summary["prediction_coverage"] = {
            **coverage(v_after), "parametric": coverage(v_after, "interval_95_parametric")}
        summary["calibration"] = cal["calibration"]
    summary["fit_before"] = errors_block(before)
    summary["validation_before"] = errors_block(v_before) if v_before else None
    if args.out:
        _write(Path(args.out), problem, result, summary, before, after, v_before, v_after)
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0
    for w in caught:
        print(f"mbcontrol: warning: {w.message}", file=sys.stderr)
    print(parameter_table(problem, result))
    print(error_table(before, "fit runs, scene values"))
    print(error_table(after, "fit runs, identified"))
    if validation:
        print(error_table(v_before, "validation, scene values"))
        print(error_table(v_after, "validation, identified"))
        c, b = summary["prediction_coverage"], summary["calibration"]
        p = c["parametric"]
        how = (f"calibrated: {b['method']}, {b['folds']}, {b['n_scores']} scores, nominal "
               f"{b['nominal_coverage']:.1%}"
               if b["method"] else f"not calibrated: {b['reason']}")
        print(f"validation: {c['inside']} of {c['rows']} measured amplitudes inside their 95 % "
              f"prediction intervals ({how}); {p['inside']} of {p['rows']} inside the "
              f"parametric ones (parameter sigma and the runs' repeatability)")
    if args.out:
        print(f"wrote {args.out}/summary.json, parameters.txt, amplitudes.png, time_series.png")
    return 0


def _write(out: Path, problem, result, summary, before, after, v_before, v_after) -> None:
    from ..atomic import write_text
    from ..studies.identify import parameter_table, plot_amplitudes, plot_time_series
    for name, text in (("summary.json", json.dumps(summary, indent=2)),
                       ("parameters.txt", parameter_table(problem, result) + "\n")):
        write_text(out / name, text)
    plot_amplitudes({"scene values": before, "identified": after}, out / "amplitudes.png")
    if v_after:
        plot_amplitudes({"scene values": v_before, "identified": v_after},
                            out / "amplitudes_validation.png")
    worst = max(after, key=lambda r: abs(r["relative_error"]))["run"]
    plot_time_series(problem, worst, {"scene values": {}, "identified": result.values},
                         out / "time_series.png")
    import matplotlib.pyplot as plt
    plt.close("all")
