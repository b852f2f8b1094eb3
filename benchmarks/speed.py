"""Real-time factors at 1 % accuracy: mbcontrol against a hand-written convolution baseline.

For each model, in one run and on the same machine, the cheapest setting that meets 1 %
RMS accuracy is searched for, then timed:

  model          sea (JONSWAP, gamma 3.3, 600 s)   targets
  sphere         Hs 2.5 m,  Tp 9.67 s               >= 20,000x real time, >= 50x the baseline
  rm3            Hs 2.5 m,  Tp 8 s                  >= 20,000x real time, >= 50x the baseline
  hinged_barge   Hs 0.03 m, Tp 1.1 s                >= 20,000x real time, >= 50x the baseline
  barge_chain    Hs 0.03 m, Tp 1.1 s  (N = 8)       >= 50x the baseline

Error measure (both sides): the largest, over the joint coordinates (the first plant.n_q
states), of RMS(y - y_ref) / RMS(y_ref) over the record after the wave ramp, y_ref a converged
reference of the SAME equations, interpolated to the run's samples (cubic spline).

mbcontrol (this toolbox): simulate(plant, sea, duration, dt, method) over
  - method: every fixed-step method in mbcontrol.sim.METHODS, dt on a geometric ladder
    Tp/8 ... Tp/256 (ratio 2^(1/4)), coarse to fine: the first dt that meets 1 % is the
    method's cheapest; a run that diverges (SimulationError) is recorded as unstable; a ladder
    stops early at an error floor (a finer step gains < 20 %: model error, no step meets it);
  - the adaptive methods (cvodes, adams): rtol 1e-3 ... 1e-7 on an output grid of Tp/20,
    skipped when a short probe projects more than --adaptive-budget seconds for the record;
  - the radiation model's order: the scene's radiation_tol, and the cruder fits 0.05 and 0.1
    (with rk4 and exp-rk4). A cruder fit is a model error, so every setting is measured
    against the FULL model's reference: RK4 at Tp/320, converged (it differs from Tp/160 by
    < 1e-3; were it not, the step would be halved until it does).
  Steps are whole fractions of the sea's repeat period, so the excitation is synthesised by
  FFT. Real-time factor = record length / wall_time_s (the excitation synthesis and the time
  stepping; compilation excluded), best of --repeat runs, one core (BLAS limited to one
  thread for both sides, unless OPENBLAS_NUM_THREADS etc. are set).

baseline (benchmarks/convolution_baseline.py): the radiation-free plant's CasADi f called
  from Python, the radiation force by direct (trapezoid) convolution of the stored velocity
  history on a grid of step delta (kernel: B over the BEM band, truncated at the memory
  length with a taper), and scipy's solve_ivp (RK45) between grid points with the memory
  force extrapolated linearly. Settings: delta in Tp/10 ... Tp/160 (ratio sqrt 2) and rtol
  1e-3, or 1e-5 where 1e-3 misses by less than 2x, searched coarse to fine on the first
  --search-duration seconds; the cheapest setting that meets 1 % is then run on the whole
  record (the next finer delta if it misses there: errors of slow drift grow with the
  record). Its reference solves the same convolution equations tightly (RK4 at Tp/160 with
  the same kernel, its step halved until it differs from the 2x coarser one by < 1e-3).
  A baseline run projected to take longer than --baseline-budget seconds runs a shorter
  record instead: its real-time factor is then EXTRAPOLATED (the cost per step is constant
  once the kernel is filled) and marked with * in the table.

The last column compares the two converged references (state-space radiation fit vs direct
convolution of the BEM kernel) with the same error measure: the modelling difference between
the two sides, to show that both solve the same physics (per coordinate below the table).

Output: the table on stdout, progress on stderr; in --out: speed_summary.csv (one row per
model), speed_trials.csv (every setting tried, both sides) and speed.png (real-time factors
and work-precision). First run: compiling each (model, method) takes from seconds to a
minute; the compiled code is cached (see mbcontrol.sim.compiled), later runs skip it.

Examples:
  python benchmarks/speed.py                                   # all models, 600 s (~8-12 min)
  python benchmarks/speed.py --models sphere rm3 --duration 120 --baseline-budget 20
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

# one core, as the compiled code: a multi-threaded BLAS in the baseline's convolution would
# both break "one core" and, on a loaded machine, stall in its threads' spin-waits
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import convolution_baseline as conv
from speed_cases import (ADAPTIVE, ADAPTIVE_OUTPUT, ADAPTIVE_RTOLS, BASELINE_LADDER, BASELINE_RTOLS,
                         CASES, CRUDE_RADIATION_METHODS, DT_LADDER, FLOOR_RATIO, RADIATION_TOLS,
                         REF_CONV, REF_SS, REPEAT_UNDER_S, TOL, Case, Result, Trial, converged,
                         coordinate_errors, grid_step, log)
from speed_report import chart, print_table, write_csv

from mbcontrol import waves
from mbcontrol.errors import SimulationError
from mbcontrol.plant import build_plant
from mbcontrol.scene import load_scene
from mbcontrol.sim import simulate

try:
    from mbcontrol.sim import METHODS
except ImportError:                          # before the method registry existed: RK4 only
    METHODS = {"rk4": None}


def _measure(trial, t, q, ref, after, names) -> None:
    errors = coordinate_errors(t, q, *ref, after)
    trial.error, trial.worst = float(errors.max()), names[int(np.argmax(errors))]


def _coordinates(plant, ds) -> tuple[np.ndarray, np.ndarray]:
    return ds["time"].values, ds["state"].values[:, :plant.n_q].copy()


def _run(plant, sea, duration, dt, method, rtol=None):
    kwargs = {"rtol": rtol} if rtol is not None else {}
    return simulate(plant, sea, duration=duration, dt=dt, method=method, **kwargs)


def _timed(trial: Trial, plant, sea, duration, dt, method, rtol, ref, after, repeat):
    """Run once for the error, then (for short runs) repeat for a best-of timing."""
    try:
        ds = _run(plant, sea, duration, dt, method, rtol)
    except SimulationError as exc:
        text = str(exc)
        trial.status = "unstable" if ("diverged" in text or "non-finite" in text) else \
            "failed: " + text.split(";")[0][-80:]
        return trial
    t, q = _coordinates(plant, ds)
    walls = [ds.attrs["wall_time_s"]]
    _measure(trial, t, q, ref, after, plant.states[:plant.n_q])
    trial.record_s = float(t[-1])
    if trial.error <= TOL and walls[0] < REPEAT_UNDER_S:
        walls += [_run(plant, sea, duration, dt, method, rtol).attrs["wall_time_s"]
                  for _ in range(repeat - 1)]
    trial.wall_s, trial.runs = min(walls), len(walls)
    return trial


def toolbox_side(case: Case, scene, sea, duration: float, repeat: int, adaptive_budget: float,
                 result: Result) -> None:
    """Search mbcontrol's settings (method, dt, radiation order) for the cheapest at 1 %."""
    tp, after = case.tp, sea.ramp_time
    full = build_plant(scene)
    start = time.perf_counter()
    k, (ref, result.ss_check) = converged(
        lambda k: _coordinates(full, _run(full, sea, duration, grid_step(sea, tp / k), "rk4")),
        REF_SS, after)
    result.ss_k = k
    log(f"  mbcontrol reference RK4 Tp/{k}: vs Tp/{k // 2} {result.ss_check:.1e} "
        f"({time.perf_counter() - start:.0f} s)")
    result.ss_reference = ref

    variants, seen = [], []
    for tol in RADIATION_TOLS:
        plant = full if tol is None else build_plant(scene, radiation_tol=tol)
        A = plant.hydro.radiation.A
        if any(A.shape == B.shape and np.allclose(A, B) for B in seen):
            continue                                     # the same fit as one already tried
        seen.append(A)
        variants.append((tol, plant))
    default_tol = scene.hydro.radiation_tol
    fixed = [m for m in METHODS if m not in ADAPTIVE and
             getattr(METHODS[m], "kind", "explicit") != "adaptive"]
    for tol, plant in variants:
        methods = fixed if tol is None else [m for m in fixed if m in CRUDE_RADIATION_METHODS]
        rad_tol = default_tol if tol is None else tol
        for method in methods:
            best, previous, floor = None, None, False
            for k in DT_LADDER:
                dt = grid_step(sea, tp / k)
                trial = _timed(Trial(case.name, "mbcontrol", method, dt, None, rad_tol, plant.nx),
                               plant, sea, duration, dt, method, None, ref, after, repeat)
                result.trials.append(trial)
                if trial.meets:
                    best = trial
                    break
                # a smaller step no longer reduces the error: what is left is model error (a
                # cruder radiation fit), which no step meets
                if trial.status == "ok" and previous is not None and previous.status == "ok" \
                        and trial.error > FLOOR_RATIO * previous.error:
                    floor = True
                    break
                previous = trial
            log(f"  mbcontrol {method:8s} rad.tol {rad_tol:<5g} ({plant.nx:3d} states): " +
                (f"dt {best.step:.4g} s, err {best.error:.1e}, {best.rtf:,.0f}x real time"
                 if best else f"error floor {trial.error:.1e} > 1 % (model error): stopped"
                 if floor else "no dt on the ladder met 1 %"))
    for method in (m for m in METHODS if m in ADAPTIVE or
                   getattr(METHODS[m], "kind", "") == "adaptive"):
        out_dt = grid_step(sea, tp / ADAPTIVE_OUTPUT)
        probe_s = min(duration, max(10 * out_dt, duration / 20))
        try:
            probe = _run(full, sea, probe_s, out_dt, method, ADAPTIVE_RTOLS[0])
            projected = probe.attrs["wall_time_s"] * duration / probe_s
        except SimulationError:
            projected = np.inf
        if projected > adaptive_budget:
            result.trials.append(Trial(case.name, "mbcontrol", method, out_dt, ADAPTIVE_RTOLS[0],
                                       default_tol, full.nx, status=f"skipped: projected "
                                       f"{projected:.0f} s > {adaptive_budget:g} s budget"))
            log(f"  mbcontrol {method:8s} skipped: a probe projects {projected:.0f} s for "
                f"the record (budget {adaptive_budget:g} s)")
            continue
        best = None
        for rtol in ADAPTIVE_RTOLS:
            trial = _timed(Trial(case.name, "mbcontrol", method, out_dt, rtol, default_tol,
                                 full.nx), full, sea, duration, out_dt, method, rtol, ref, after,
                           repeat)
            result.trials.append(trial)
            if trial.meets:
                best = trial
                break
            if trial.wall_s > adaptive_budget:
                break
        log(f"  mbcontrol {method:8s}: " + (f"rtol {best.rtol:g}, err {best.error:.1e}, "
                                            f"{best.rtf:,.0f}x real time" if best else
                                            "no rtol met 1 % within the budget"))
    meeting = [t for t in result.trials if t.side == "mbcontrol" and t.meets]
    if meeting:
        result.toolbox = max(meeting, key=lambda t: t.rtf)
        result.toolbox.chosen = True


def baseline_side(case: Case, scene, sea, duration: float, search_duration: float,
                  budget: float, result: Result) -> None:
    """Search the baseline's settings (delta, rtol) on a short record, then run the cheapest
    on the whole record (or, beyond the budget, on a shorter one: extrapolated)."""
    tp, after = case.tp, sea.ramp_time
    model = conv.radiation_free(scene)
    n_states = model[0].nx
    start = time.perf_counter()
    runs = {}

    def reference_at(k):
        runs[k] = conv.converged_reference(scene, sea, duration=duration,
                                           dt=grid_step(sea, tp / k), model=model)
        return runs[k].t, runs[k].q

    k, (_, result.conv_check) = converged(reference_at, REF_CONV, after)
    result.conv_k, ref = k, runs[k]
    diff = coordinate_errors(ref.t, ref.q, *result.ss_reference, after)
    names = model[0].states[:model[0].n_q]
    result.model_diff = float(diff.max())
    result.model_diff_by_coordinate = dict(zip(names, map(float, diff)))
    log(f"  convolution reference RK4 Tp/{k} (kernel {ref.kernel_s:.1f} s): vs "
        f"Tp/{k // 2} {result.conv_check:.1e}; state space vs convolution "
        f"{result.model_diff:.1e} ({time.perf_counter() - start:.0f} s)")
    reference = (ref.t, ref.q)

    def attempt(delta, rtol, record):
        trial = Trial(case.name, "baseline", "solve_ivp RK45 + convolution", delta, rtol, None,
                      n_states)
        run = conv.simulate_baseline(scene, sea, duration=record, delta=delta, rtol=rtol,
                                     model=model)
        _measure(trial, run.t, run.q, reference, after, names)
        trial.wall_s, trial.record_s, trial.runs = run.wall_s, float(run.t[-1]), 1
        trial.note = f"{run.rhs_per_step:.1f} f calls/step; kernel {run.kernel_s:.1f} s"
        return trial

    search = min(duration, search_duration)
    candidates, ladder = [], list(BASELINE_LADDER)
    for j, k in enumerate(ladder):
        delta = grid_step(sea, tp / k)
        trial = None
        for rtol in BASELINE_RTOLS:
            if trial is not None and (candidates or trial.error > 2 * TOL):
                break        # a tighter rtol only costs more; it cannot rescue a far miss,
                #              which is delta's (the memory force's) error
            trial = attempt(delta, rtol, search)
            trial.note = f"search ({search:.0f} s record); " + trial.note
            result.trials.append(trial)
            log(f"  baseline search delta {delta:.4g} s rtol {rtol:g}: err {trial.error:.1e}, "
                f"{trial.rtf:,.1f}x real time")
            if trial.meets:
                candidates.append((j, trial))
        if candidates:
            break
    if not candidates:
        log("  baseline: no setting met 1 % on the search record")
        return
    j, pick = max(candidates, key=lambda c: c[1].rtf)
    cost = pick.wall_s / pick.record_s                 # wall seconds per simulated second
    k = ladder[j]
    while True:
        delta = grid_step(sea, tp / k)
        record = duration if cost * duration <= budget else max(search, budget / cost)
        record = min(duration, record)
        trial = attempt(delta, pick.rtol, record)
        if record < duration:
            trial.extrapolated = True
            trial.note = f"EXTRAPOLATED from a {trial.record_s:.0f} s record; " + trial.note
        result.trials.append(trial)
        log(f"  baseline final delta {delta:.4g} s rtol {pick.rtol:g} on {trial.record_s:.0f} s: "
            f"err {trial.error:.1e}, {trial.rtf:,.1f}x real time")
        if trial.meets:
            trial.chosen = True
            result.baseline = trial
            return
        if k >= ladder[-1]:
            log("  baseline: no delta on the ladder met 1 % on the whole record")
            return
        # missed on the whole record (slow drift errors grow with it): the scheme is second
        # order in delta, so go straight to the rung expected to meet 1 % with a 10 % margin
        needed = k * np.sqrt(trial.error / (0.9 * TOL))
        k_next = next((kk for kk in ladder if kk >= needed and kk > k), ladder[-1])
        cost *= k_next / k
        k = k_next


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--models", nargs="+", choices=list(CASES), default=list(CASES),
                        help="models to run (default: all four)")
    parser.add_argument("--duration", type=float, default=600.0,
                        help="record length, s (default 600)")
    parser.add_argument("--repeat", type=int, default=3,
                        help="best of this many timed runs for mbcontrol (runs under "
                             f"{REPEAT_UNDER_S:g} s; default 3)")
    parser.add_argument("--seed", type=int, default=1, help="wave phase seed (default 1)")
    parser.add_argument("--search-duration", type=float, default=120.0,
                        help="record length of the baseline's setting search, s (default 120)")
    parser.add_argument("--baseline-budget", type=float, default=180.0,
                        help="longest baseline run, s; longer ones run a shorter record and "
                             "are extrapolated (default 180)")
    parser.add_argument("--adaptive-budget", type=float, default=30.0,
                        help="skip an adaptive method (cvodes, adams) projected to take longer "
                             "than this for the record, s (default 30)")
    parser.add_argument("--out", default="out/bench/speed", help="folder for CSVs and chart")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    warnings.simplefilter("ignore", RuntimeWarning)   # coarse-step trials warn by design

    results, t0 = [], time.perf_counter()
    for key in args.models:
        case = CASES[key]
        log(f"{case.name}: JONSWAP Hs {case.hs} m, Tp {case.tp} s, {args.duration:.0f} s")
        scene = load_scene(case.scene, case.params) if case.params else load_scene(case.scene)
        sea = waves.irregular(case.hs, case.tp, gamma=3.3, seed=args.seed,
                              duration=max(600.0, args.duration))
        if args.duration <= sea.ramp_time + 5 * case.tp:
            parser.error(f"--duration {args.duration:g} s: too short for {case.name} (ramp "
                         f"{sea.ramp_time:g} s plus five peak periods)")
        result = Result(case)
        toolbox_side(case, scene, sea, args.duration, args.repeat, args.adaptive_budget, result)
        baseline_side(case, scene, sea, args.duration,
                      max(args.search_duration, sea.ramp_time + 10 * case.tp),
                      args.baseline_budget, result)
        results.append(result)
    write_csv(results, out)
    chart(results, out / "speed.png")
    print_table(results, args, time.perf_counter() - t0)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
