"""Identification on the flume tank data (`make bench`): Gauss-Newton with exact sensitivities
against the seed's Nelder-Mead, and batched against one-run-at-a-time evaluation.

All usable runs of series 4, 5 and 6 (../shared/data/tank), the flume_section scene's default
parameters, the harmonic cost. Reports, in one run on this machine:
- Gauss-Newton: simulations (runs simulated, with sensitivities), wall time and final cost;
- Nelder-Mead from the same start: simulations and wall time until its cost first comes within
  0.1 % of Gauss-Newton's final cost (or its best after --nm-evaluations, if it never does);
- one iteration's cost (one residual evaluation, with and without the Jacobian) with every run
  of a plant stepped in one compiled batch for the longest run's duration, against one call
  per run for its own duration (Identification's batch=True / False; compiled before timing;
  best of 3).
"""
from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path


from mbcontrol.studies.identify import fit
from mbcontrol.studies.identify.problem import Identification
from mbcontrol.studies.identify.setup import flume_identification

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "tank" / "scenario_c"


def best_of(n, f):
    times = []
    for _ in range(n):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--data", default=str(DATA), help="folder of the SPPH_R runs")
    parser.add_argument("--nm-evaluations", type=int, default=600,
                        help="Nelder-Mead's evaluation budget (600)")
    parser.add_argument("--out", help="write identify.json here (a folder)")
    args = parser.parse_args(argv)
    files = sorted(Path(args.data).glob("[456]*.csv.xz"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        problem = flume_identification("flume_section", files, drop_bad=True)
        theta0 = problem.theta0()
        problem.residuals(theta0, jacobian=True)               # build and compile, untimed
        gn = fit(problem, "gauss-newton")
        target = gn.cost * 1.001
        history = []
        evaluate = problem.cost_value
        sims0, t0 = problem.simulations, time.perf_counter()

        def logged(theta):
            value = evaluate(theta)
            history.append((problem.simulations - sims0, time.perf_counter() - t0, value))
            return value

        problem.cost_value = logged
        nm = fit(problem, "nelder-mead", max_evaluations=args.nm_evaluations)
        del problem.cost_value
    reached = next((h for h in history if h[2] <= target), None)
    nm_sims, nm_time, nm_cost = reached or (nm.simulations, nm.wall_time_s, nm.cost)

    options = dict(problem.options, batch=not problem.batch)
    other = Identification(problem.scene, problem.runs, problem.fit, outputs=problem.outputs,
                           **options)
    batched, single = (problem, other) if problem.batch else (other, problem)
    theta = problem.theta0()
    single.residuals(theta, jacobian=True)                     # build and compile, untimed
    batched.residuals(theta, jacobian=True)
    per_iteration = {}
    for jac in (False, True):
        t_batched = best_of(3, lambda: batched.residuals(theta, jacobian=jac))
        t_single = best_of(3, lambda: single.residuals(theta, jacobian=jac))
        per_iteration["gauss-newton" if jac else "nelder-mead"] = {
            "batched_s": t_batched, "one_at_a_time_s": t_single,
            "speed_up": t_single / t_batched}
    report = {
        "runs": len(problem.runs), "parameters": [p.name for p in problem.fit],
        "gauss_newton": {"simulations": gn.simulations, "wall_time_s": gn.wall_time_s,
                         "cost": gn.cost, "evaluations": gn.evaluations},
        "nelder_mead": {"simulations": nm_sims, "wall_time_s": nm_time, "cost": nm_cost,
                        "reached_gauss_newton_cost": reached is not None,
                        "evaluations_run": len(history), "best_cost": nm.cost},
        "simulation_ratio": nm_sims / gn.simulations,
        "wall_time_ratio": nm_time / gn.wall_time_s,
        "per_iteration": per_iteration,
    }
    print(f"identification, flume tank data: {report['runs']} runs, "
          f"{len(report['parameters'])} parameters, harmonic cost")
    print(f"  gauss-newton : {gn.simulations:6d} simulations {gn.wall_time_s:7.1f} s  "
          f"cost {gn.cost:.5g}")
    label = "to within 0.1 %" if reached else f"NOT within 0.1 % after {len(history)} evaluations"
    print(f"  nelder-mead  : {nm_sims:6d} simulations {nm_time:7.1f} s  cost {nm_cost:.5g} "
          f"({label})")
    print(f"  nelder-mead / gauss-newton: {report['simulation_ratio']:.1f}x simulations, "
          f"{report['wall_time_ratio']:.1f}x wall time")
    for name, row in per_iteration.items():
        print(f"  one {name} iteration: batched {row['batched_s']:.3f} s, one run at a time "
              f"{row['one_at_a_time_s']:.3f} s ({row['speed_up']:.1f}x)")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "identify.json").write_text(json.dumps(report, indent=2, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
