"""The WEC Control Competition (WECCCOMP) on the 1:20 Wavestar: EC per controller and sea state.

The six WECCCOMP JONSWAP sea states (SEAS), each a seeded irregular sea with a 5 Tp ramp and
100 Tp after it (waves.irregular, duration 105 Tp: its repeat period, so the record never
repeats), run on the nonlinear `wavestar` plant in closed loop with each controller of
CONTROLLERS, and scored by the competition's evaluation criterion over t > 25 s
(metrics.wecccomp_score):

    EC = P_e / (2 + F98 / F_max + z98 / z_max - mean|P| / P98)      (W)

with the motor's limits F_max = 60 N, z_max = 0.08 m and efficiency 0.7 from the scene. Every
controller saturates at F_max (the scene's force_max); the stroke is kept by tuning.

Controllers (CONTROLLERS: name -> factory(plant, wave, sea) -> controller, or raises Skip
with the reason; add one, e.g. MPC, with --extra NAME=module:function or by adding to the
dict before calling main()):

- scene_damper: the untuned baseline, the scene's own PTO damping (350 N s/m, optimal for a
  regular wave H 6.25 cm, T 1.412 s);
- passive: a damper tuned for the sea, constrained (optimal_damping with force_max and
  stroke_max: the predicted force and stroke peaks within the limits);
- reactive: the tuned spring-damper baseline, constrained the same way, maximising the
  predicted mean electrical power (reactive_tuning with efficiency 0.7: reactive power is
  bought back at 1 / 0.7);
- latching: latch time from Tp by the classical rule (Tp - T_n) / 2 (T_n the natural period,
  0.81 s), damping Re Z_i(omega_n) when free (as optimal_latch_time); the brake is limited
  to 60 N like every command;
- declutching: gains only in waves shorter than the natural period; every WECCCOMP Tp is
  longer, so it is skipped (tuned on the regular wave H = Hs / sqrt 2 at Tp, optimal_declutch
  returns a declutch time of 2-3 ms: the passive damper). A sea with Tp < T_n would be run,
  tuned that way.

Step: dt = 0.005 s (RK4). The linearised closed loops' fastest poles are ~35 rad/s (RK4 is
stable to |lambda dt| < 2.8, dt < 0.08 s); the step is set by accuracy: the seas reach
25 rad/s (4 omega_p at Tp 0.988 s), omega dt = 0.125, and latching switches at samples.
Halving it to 0.0025 s changes EC by <= 0.3 % (SS1 and SS6, every controller; measured).

Writes wecccomp.csv, wecccomp.md (the tables) and wecccomp.png (EC bars) to --out.
Usage: python benchmarks/wecccomp.py --out out/wecccomp
"""
from __future__ import annotations

import argparse
import csv
import importlib
import json
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.controllers.latching import (Declutching, Latching, natural_period,
                                            optimal_declutch)
from mbcontrol.controllers.passive import Passive, optimal_damping
from mbcontrol.controllers.impedance import intrinsic_impedance
from mbcontrol.controllers.reactive import Reactive, reactive_tuning
from mbcontrol.analysis.metrics import pto_metrics, wecccomp_score
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate

MODEL = "wavestar"
RAMP_PERIODS = 5          # ramp, Tp
LENGTH_PERIODS = 100      # record after the ramp, Tp
SCORE_START = 25.0        # s, WECCCOMP scores t > 25 s
DT = 0.005                # s
SEED = 0                  # wave phases, the same for every sea and controller


@dataclass(frozen=True)
class Sea:
    name: str
    hs: float             # m
    tp: float             # s
    gamma: float


SEAS = (Sea("SS1", 0.0208, 0.988, 1.0), Sea("SS2", 0.0625, 1.412, 1.0),
        Sea("SS3", 0.1042, 1.836, 1.0), Sea("SS4", 0.0208, 0.988, 3.3),
        Sea("SS5", 0.0625, 1.412, 3.3), Sea("SS6", 0.1042, 1.836, 3.3))


class Skip(Exception):
    """A controller that does not apply to a sea state; the message says why."""


def sea_wave(sea: Sea, periods: int = LENGTH_PERIODS, seed: int = SEED) -> waves.Wave:
    """The sea's irregular wave: ramp RAMP_PERIODS Tp, then `periods` Tp, no repetition."""
    return waves.irregular(sea.hs, sea.tp, gamma=sea.gamma, seed=seed,
                           duration=(RAMP_PERIODS + periods) * sea.tp,
                           ramp_time=RAMP_PERIODS * sea.tp)


def _pto(plant):
    return plant.scene.ptos[0]


def scene_damper(plant, wave, sea):
    return Passive(_pto(plant).damping)


def passive(plant, wave, sea):
    pto = _pto(plant)
    damping, _ = optimal_damping(plant, wave, force_max=pto.force_max,
                                 stroke_max=pto.stroke_max)
    return Passive(damping)


def reactive(plant, wave, sea):
    pto = _pto(plant)
    damping, stiffness, _ = reactive_tuning(plant, wave, force_max=pto.force_max,
                                            stroke_max=pto.stroke_max,
                                            efficiency=pto.efficiency)
    return Reactive(damping, stiffness)


def latching(plant, wave, sea):
    t_n = natural_period(plant)
    if sea.tp <= t_n:
        raise Skip(f"latching needs Tp > T_n = {t_n:.3f} s")
    damping = float(intrinsic_impedance(plant, [2 * np.pi / t_n])[0][0].real)
    return Latching(damping, 0.5 * (sea.tp - t_n))


def declutching(plant, wave, sea):
    t_n = natural_period(plant)
    if sea.tp >= t_n:
        raise Skip(f"declutching gains only in waves shorter than the natural period "
                   f"T_n = {t_n:.3f} s, and Tp >= T_n (tuned on the regular wave at Tp its "
                   f"declutch time is ~0: the passive damper)")
    tau, damping, _ = optimal_declutch(plant, waves.regular(sea.hs / np.sqrt(2), sea.tp))
    return Declutching(damping, tau)


def mpc(plant, wave, sea):
    """Linear MPC: the motor's limits (from the scene), electrical objective with its
    efficiency, Kalman filter on the arm's encoder, AR forecast (the wave is not given to
    it beyond the Kalman filter's wave-model frequencies), about one Tp ahead."""
    from mbcontrol.controllers.mpc import Mpc
    return Mpc(horizon_s=2.0, dt_s=0.05, wave=wave, forecast="ar")


CONTROLLERS = {"scene_damper": scene_damper, "passive": passive, "reactive": reactive,
               "latching": latching, "declutching": declutching, "mpc": mpc}


def run_one(plant, sea: Sea, name: str, factory, *, dt: float = DT,
            periods: int = LENGTH_PERIODS, seed: int = SEED) -> tuple[dict, object]:
    """(row, dataset) for one controller in one sea; dataset None when skipped.

    Row: sea and controller, EC_W, mean electrical and mechanical power (W, t > 25 s), max
    |F| (N) and max |z| (m) over the record after the ramp and over the scored window, the
    98th percentiles, the controller's settings and the wall time (s, tuning + simulation).
    """
    wave = sea_wave(sea, periods, seed)
    row = {"sea": sea.name, "hs_m": sea.hs, "tp_s": sea.tp, "gamma": sea.gamma,
           "controller": name, "seed": seed, "dt_s": dt}
    start = time.perf_counter()
    try:
        controller = factory(plant, wave, sea)
    except Skip as why:
        return {**row, "skipped": str(why)}, None
    duration = (RAMP_PERIODS + periods) * sea.tp
    ds = simulate(plant, wave, duration=duration, dt=dt, controller=controller)
    pto = _pto(plant)
    score = wecccomp_score(ds, pto, start=SCORE_START)
    after_ramp = pto_metrics(ds, pto, start=wave.ramp_time)
    row.update({"EC_W": score["EC"], "Pe_W": score["mean_electrical_power_W"],
                "P_W": score["mean_power_W"], "max_force_N": after_ramp["max_force"],
                "max_stroke_m": after_ramp["max_stroke"],
                "max_force_scored_N": score["max_force"],
                "max_stroke_scored_m": score["max_stroke"], "f98_N": score["f98"],
                "z98_m": score["z98"], "settings": json.dumps(controller.describe()),
                "wall_s": time.perf_counter() - start, "skipped": ""})
    return row, ds


def run_all(controllers=None, seas=SEAS, *, dt: float = DT, periods: int = LENGTH_PERIODS,
            seed: int = SEED, progress: bool = True, keep: bool = False):
    """Every controller in every sea: (rows, {(sea, controller): dataset} if keep else {})."""
    from tqdm.auto import tqdm
    controllers = CONTROLLERS if controllers is None else controllers
    plant = build_plant(MODEL)
    jobs = [(sea, name, f) for sea in seas for name, f in controllers.items()]
    rows, data = [], {}
    for sea, name, factory in tqdm(jobs, desc="wecccomp", unit="run", disable=not progress):
        row, ds = run_one(plant, sea, name, factory, dt=dt, periods=periods, seed=seed)
        rows.append(row)
        if keep and ds is not None:
            data[(sea.name, name)] = ds
    return rows, data


def markdown(rows, controllers) -> str:
    """Two tables: EC (W) per sea and controller; then every run's power, force and stroke."""
    seas = list(dict.fromkeys(r["sea"] for r in rows))
    by = {(r["sea"], r["controller"]): r for r in rows}
    ran = [c for c in controllers if any(not by[(s, c)]["skipped"] for s in seas)]
    lines = ["| sea (Hs m, Tp s, γ) | " + " | ".join(ran) + " |",
             "|---|" + "---:|" * len(ran)]
    for s in seas:
        r0 = by[(s, ran[0])]
        cells = [("–" if by[(s, c)]["skipped"] else f"{by[(s, c)]['EC_W']:.4f}") for c in ran]
        lines.append(f"| {s} ({r0['hs_m']}, {r0['tp_s']}, {r0['gamma']:g}) | "
                     + " | ".join(cells) + " |")
    lines += ["", ("| sea | controller | EC (W) | P̄e (W) | P̄ mech (W) | max abs F (N) | "
                   "max abs z (m) |"), "|---|---|---:|---:|---:|---:|---:|"]
    for s in seas:
        for c in ran:
            r = by[(s, c)]
            if r["skipped"]:
                continue
            lines.append(f"| {s} | {c} | {r['EC_W']:.4f} | {r['Pe_W']:.4f} | {r['P_W']:.4f} | "
                         f"{r['max_force_N']:.1f} | {r['max_stroke_m']:.4f} |")
    skipped = sorted({(c, by[(s, c)]["skipped"]) for s in seas for c in controllers
                      if by[(s, c)]["skipped"]})
    if skipped:
        lines.append("")
        lines += [f"- {c} skipped: {why}" for c, why in skipped]
    return "\n".join(lines) + "\n"


def bar_chart(rows, controllers, path: Path) -> None:
    """EC per sea and controller (log scale: the seas span 20x), and EC relative to the first
    controller (the untuned scene damper)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    seas = list(dict.fromkeys(r["sea"] for r in rows))
    by = {(r["sea"], r["controller"]): r for r in rows}
    ran = [c for c in controllers if any(not by[(s, c)]["skipped"] for s in seas)]
    width = 0.8 / len(ran)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8))
    x = np.arange(len(seas))
    for i, c in enumerate(ran):
        ec = np.array([math.nan if by[(s, c)]["skipped"] else by[(s, c)]["EC_W"] for s in seas])
        ref = np.array([by[(s, ran[0])]["EC_W"] for s in seas])
        for ax, values in zip(axes, (ec, ec / ref)):
            ax.bar(x + (i - (len(ran) - 1) / 2) * width, values, width, label=c)
    labels = [(f"{s}\nHs {by[(s, ran[0])]['hs_m']} m\nTp {by[(s, ran[0])]['tp_s']} s, "
               f"γ {by[(s, ran[0])]['gamma']:g}") for s in seas]
    for ax in axes:
        ax.set_xticks(x, labels, fontsize=7)
        ax.grid(axis="y", alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("EC (W, log scale)")
    axes[0].set_title("WECCCOMP EC (t > 25 s)")
    axes[1].set_ylabel(f"EC / EC of {ran[0]}")
    axes[1].set_title(f"relative to {ran[0]}")
    axes[1].axhline(1.0, color="k", lw=0.8)
    axes[1].set_ylim(0, 1.25 * axes[1].get_ylim()[1])      # room for the legend
    axes[1].legend(fontsize=8, ncol=len(ran), loc="upper center")
    fig.suptitle("Wavestar 1:20, motor limits 60 N and 0.08 m, efficiency 0.7")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def _load_extra(spec: str):
    """NAME=module:function -> (NAME, factory)."""
    try:
        name, target = spec.split("=", 1)
        module, function = target.split(":", 1)
    except ValueError:
        raise SystemExit(f"--extra expects NAME=module:function, got {spec!r}") from None
    return name, getattr(importlib.import_module(module), function)


def main(argv=None, controllers=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="Controllers: " + ", ".join(CONTROLLERS))
    parser.add_argument("--out", type=Path, default=Path("out/wecccomp"),
                        help="output folder (default out/wecccomp)")
    parser.add_argument("--dt", type=float, default=DT, help=f"step, s (default {DT})")
    parser.add_argument("--periods", type=int, default=LENGTH_PERIODS,
                        help=f"record after the ramp, in Tp (default {LENGTH_PERIODS})")
    parser.add_argument("--seed", type=int, default=SEED, help=f"wave seed (default {SEED})")
    parser.add_argument("--seas", nargs="*", default=None,
                        help="sea names to run (default all: " + " ".join(s.name for s in SEAS)
                        + ")")
    parser.add_argument("--controllers", nargs="*", default=None,
                        help="controller names to run (default all; --extra ones always)")
    parser.add_argument("--extra", action="append", default=[],
                        help="an extra controller column NAME=module:function, the function "
                             "(plant, wave, sea) -> controller; may repeat")
    args = parser.parse_args(argv)
    table = dict(CONTROLLERS if controllers is None else controllers)
    if args.controllers:
        unknown = set(args.controllers) - set(table)
        if unknown:
            parser.error(f"unknown controller(s) {sorted(unknown)}; have {sorted(table)}")
        table = {n: table[n] for n in args.controllers}
    table.update(dict(_load_extra(spec) for spec in args.extra))      # always run
    seas = SEAS if not args.seas else [s for s in SEAS if s.name in args.seas]
    if not seas:
        parser.error(f"no sea named {args.seas}; have {[s.name for s in SEAS]}")
    start = time.perf_counter()
    rows, _ = run_all(table, seas, dt=args.dt, periods=args.periods, seed=args.seed)
    wall = time.perf_counter() - start
    args.out.mkdir(parents=True, exist_ok=True)
    fields = list(dict.fromkeys(k for r in rows for k in r))
    tmp = args.out / "wecccomp.csv.tmp"
    with open(tmp, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields)
        writer.writeheader()
        writer.writerows(rows)
    os.replace(tmp, args.out / "wecccomp.csv")
    text = markdown(rows, list(table))
    _write_atomic(args.out / "wecccomp.md", text)
    bar_chart(rows, list(table), args.out / "wecccomp.png")
    print(text)
    print(f"{len(rows)} runs in {wall:.0f} s; wrote {args.out}/wecccomp.csv, wecccomp.md, "
          f"wecccomp.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
