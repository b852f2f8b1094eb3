"""Stepping speed in the two cases of issue 38 (`make bench`): the sphere and the hinged barge,
600 s JONSWAP records at dt = 0.01 s, compiled RK4, no controller.

For each: the excitation at RK4's 3 x 60,000 nodes by the repeat-period inverse FFT (one per
fractional node offset, what `simulate` does), by blocks of phasors (the method for steps that
do not divide the repeat period) and by the direct sum (the reference: the largest difference
is printed), then the stepping alone, then `simulate`'s own wall_time_s (synthesis + stepping,
compile and outputs excluded) as a real-time factor, the median and the best of --repeat runs
(one core; on a shared machine the best is the machine's, the median the day's).

    python benchmarks/stepping.py [--repeat 7] [--json]
"""
from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np

from mbcontrol.plant import build_plant
from mbcontrol.sim import integrators, simulate
from mbcontrol.waves import from_args, ramp
from mbcontrol.waves.synthesis import _synthesise_blocks, _synthesise_direct

CASES = {"sphere": (2.0, 9.0), "hinged_barge": (0.06, 1.9)}     # Hs m, Tp s
DURATION, DT, NODES = 600.0, 0.01, (0.0, 0.5, 1.0)
TARGETS = {"sphere": 50_000, "hinged_barge": 5_000}              # x real time (issue 38)


def _best(fun, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = fun()
        times.append(time.perf_counter() - start)
    return out, times


def measure(name: str, repeat: int) -> dict:
    hs, tp = CASES[name]
    plant = build_plant(name)
    om = plant.hydro.omega
    wave = from_args("jonswap", hs=hs, tp=tp, gamma=3.3, seed=1, duration=DURATION,
                     data_band=(float(om[0]), float(om[-1])))
    n = int(round(DURATION / DT))
    simulate(plant, wave, duration=DURATION, dt=DT)              # compile, outside the timing
    W, t_fft = _best(lambda: integrators.excitation_at_nodes(plant, wave, n, DT, NODES), repeat)
    coeffs = plant.hydro.excitation_at(wave.omega, wave.direction)
    weights = (wave.amplitude * np.exp(-1j * wave.phase))[:, None] * coeffs

    def per_node(method):
        return np.stack([method(c) for c in NODES], axis=1)
    _, t_blocks = _best(lambda: per_node(lambda c: _synthesise_blocks(
        wave.omega, weights * np.exp(-1j * wave.omega * c * DT)[:, None], n, DT)), 1)
    start = time.perf_counter()
    direct = per_node(lambda c: _synthesise_direct(wave.omega, weights, (np.arange(n) + c) * DT))
    t_direct = time.perf_counter() - start
    ramp_at = np.stack([ramp((np.arange(n) + c) * DT, wave.ramp_time)
                        for c in NODES], axis=1)
    error = float(np.max(np.abs(W - ramp_at[..., None] * direct)) / np.max(np.abs(direct)))
    U = np.zeros((n, len(plant.inputs)))
    _, t_step = _best(lambda: integrators.run_fixed_step(plant, plant.x0(), U, W, plant.p0, DT),
                      repeat)
    walls = [simulate(plant, wave, duration=DURATION, dt=DT).attrs["wall_time_s"]
             for _ in range(repeat)]
    return {"model": name, "states": plant.nx, "components": int(wave.omega.size),
            "nodes": n * len(NODES), "synthesis_fft_ms": 1e3 * min(t_fft),
            "synthesis_blocks_ms": 1e3 * min(t_blocks), "synthesis_direct_ms": 1e3 * t_direct,
            "fft_vs_direct_max_rel": error, "stepping_ms": 1e3 * min(t_step),
            "rtf_median": DURATION / float(np.median(walls)), "rtf_best": DURATION / min(walls),
            "target": TARGETS[name]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=7, help="timed runs per measurement")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    rows = [measure(name, args.repeat) for name in CASES]
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    print("| model | states | components x nodes | synthesis: FFT / blocks / direct (ms) | FFT vs direct |"
          " stepping (ms) | x real time, median / best | target |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['model']} | {r['states']} | {r['components']} x {r['nodes']:,} | "
              f"{r['synthesis_fft_ms']:.1f} / {r['synthesis_blocks_ms']:.0f} / {r['synthesis_direct_ms']:.0f} | "
              f"{r['fft_vs_direct_max_rel']:.1e} | {r['stepping_ms']:.1f} | "
              f"{r['rtf_median']:,.0f} / {r['rtf_best']:,.0f} | {r['target']:,} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
