"""Batch runs against a loop of single runs (`make bench`): the same cases, measured in one run.

rm3 (36 states), 16 JONSWAP seas (Hs 1-3 m, Tp 6-11 s, each 600 s) with 16 PTO dampings,
exp-rk4 at dt 0.1 s: `simulate_batch` (one compiled call per chunk for all cases) against
16 calls of `simulate`. Both include excitation synthesis and stepping; compilation is done
before timing (best of 3). Prints the ratio and checks the two agree.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from mbcontrol import waves
from mbcontrol.sim import simulate_batch
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawTextHelpFormatter)
    parser.add_argument("--cases", type=int, default=16, help="sea states (16)")
    parser.add_argument("--duration", type=float, default=600.0, help="record length, s")
    args = parser.parse_args(argv)
    plant = build_plant("rm3")
    rng = np.random.default_rng(0)
    seas = [waves.irregular(rng.uniform(1, 3), rng.uniform(6, 11), seed=k,
                            duration=args.duration) for k in range(args.cases)]
    params = [{"pto__damping": d} for d in np.geomspace(3e5, 3e6, args.cases)]
    kwargs = dict(duration=args.duration, dt=0.1, method="exp-rk4")
    simulate_batch(plant, seas, params, **kwargs)                  # compile
    simulate(plant, seas[0], params=params[0], **kwargs)
    loop, batch = [], []
    for _ in range(3):
        start = time.perf_counter()
        singles = [simulate(plant, s, params=p, **kwargs) for s, p in zip(seas, params)]
        loop.append(time.perf_counter() - start)
        start = time.perf_counter()
        together = simulate_batch(plant, seas, params, **kwargs)
        batch.append(time.perf_counter() - start)
    diff = max(np.max(np.abs(together["float__Heave"].values[k] - singles[k]["float__Heave"].values))
               for k in range(args.cases))
    total = args.cases * args.duration
    print(f"rm3, {args.cases} seas x {args.duration:.0f} s, exp-rk4 dt 0.1 s (whole calls, "
          f"outputs and audits included)")
    print(f"  loop of simulate: {min(loop):.3f} s ({total / min(loop):,.0f}x real time)")
    print(f"  simulate_batch:   {min(batch):.3f} s ({total / min(batch):,.0f}x real time)")
    print(f"  batch is {min(loop) / min(batch):.1f}x faster; max heave difference {diff:.1e} m")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
