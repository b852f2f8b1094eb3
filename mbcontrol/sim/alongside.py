"""The plant's outputs evaluated on a second core while the steps go on.

A fixed-step run computes its states chunk by chunk, then y_i = h(x_i, u_i, w_i, p) for every
sample (`integrators.outputs`). For a nonlinear plant on a panel surface the output pass costs
as much as the steps (1,048 points: 3.4 s of outputs against 2.7 s of steps for 600 s at
dt 0.01 s), because h integrates the pressure too (the energy audit's power, the field's range).
Compiled CasADi code releases Python's GIL, so `OutputsAlongside` hands each finished block of
samples to one worker thread while the main thread steps on: on two cores the output pass then
costs little wall time. The numbers are those of `integrators.outputs` (the same compiled map,
on the same blocks: tests/sim/test_alongside.py).

A thread is worth it only where the outputs are costly: handing a block to it costs tens of
microseconds, and the sphere's linear outputs take 50 us a block of 512 (the 600 s linear run
went from 18 ms to 33 ms with every block handed over). So the first block is evaluated here,
timed, and the worker is started only if it took more than WORKER_BLOCK_S; otherwise, and on
one core, the rest is evaluated at the end, as `integrators.outputs` does.
"""
from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .integrators import chunk_length, output_block, output_function

WORKER_BLOCK_S = 2e-3      # a block's outputs must take this long for a thread to pay


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                        # not on Linux
        return os.cpu_count() or 1


class OutputsAlongside:
    """Outputs of n_rows samples (the run's n + 1), block by block as the steps finish.

    `advance(ready, X, U, W)` after each chunk of steps: every whole block of rows below
    `ready` (their states, applied inputs and excitation final) goes to the worker. `finish`
    evaluates the rest (the last sample's input is only known at the end) and returns Y
    (n_rows, ny). `close` (also on an error) waits for the worker, so no thread outlives the run.
    """

    def __init__(self, plant, n_rows: int, p, compiled: bool = True):
        self.length = chunk_length(n_rows)
        self._fun = output_function(plant, compiled, self.length)
        self._p = np.ascontiguousarray(p, dtype=float)
        self.Y = np.empty((n_rows, len(plant.outputs)))
        self._done = 0
        self._pool = None                # started by `advance` once the outputs prove costly
        self._decided = _cores() < 2     # one core: everything at the end
        self._futures = []
        self._buffers = {}

    def _block(self, start, X, U, W, thread: str):
        """Rows [start, start + length) into Y; each thread with its own FunctionBuffer."""
        stop = min(start + self.length, self.Y.shape[0])
        if thread not in self._buffers:
            self._buffers[thread] = self._fun.buffer()[0]
        output_block(self._buffers[thread], self._p, X[start:stop], U[start:stop],
                     W[start:stop], self.Y[start:stop], self.length)

    def advance(self, ready: int, X, U, W) -> None:
        """Rows [0, ready) of X, U and W are final: send their whole blocks to the worker
        (the first block, evaluated here, decides whether there is one)."""
        if not self._decided and ready >= self.length:
            start = time.perf_counter()
            self._block(0, X, U, W, "main")
            self._done, self._decided = self.length, True
            if time.perf_counter() - start > WORKER_BLOCK_S:
                self._pool = ThreadPoolExecutor(1, "mbcontrol-outputs")
        if self._pool is None:
            return
        while self._done + self.length <= ready:
            self._futures.append(self._pool.submit(self._block, self._done, X, U, W, "worker"))
            self._done += self.length

    def finish(self, X, U, W) -> np.ndarray:
        """Y for all rows: the rest evaluated here, then the worker's blocks awaited."""
        for start in range(self._done, self.Y.shape[0], self.length):
            self._block(start, X, U, W, "main")
        self.close()
        return self.Y

    def close(self, errors: bool = True) -> None:
        """Stop the worker once its running block ends (blocks not started are dropped);
        with `errors`, after the blocks sent, raising what one raised. Without (the run
        itself failed): the run's own error is the one to see."""
        if self._pool is None:
            return
        try:
            for future in self._futures if errors else ():
                future.result()
        finally:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
