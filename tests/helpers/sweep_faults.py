"""`mbcontrol` with a fault injected, for the sweep's resume tests (the package has no fault
branch of its own): python tests/helpers/sweep_faults.py FAULT ARGS..., FAULT one of
- exit-after:N            the sweep process dies (exit 9) once N cases are stored;
- kill-worker-once:PATH   the first task that finds no PATH creates it and kills its worker.
"""
import os
import sys

from mbcontrol import defaults
from mbcontrol.cli import main
from mbcontrol.studies.sweep import runner
from mbcontrol.studies.sweep.store import CaseStore


def _exit_after(n: int) -> None:
    write, written = CaseStore.write, []

    def write_then_die(self, key, record):
        write(self, key, record)
        written.append(key)
        if len(written) >= n:
            os._exit(9)                  # killed part-way, after n cases were kept

    CaseStore.write = write_then_die


def _kill_worker_once(flag: str) -> None:
    run_group = runner.run_group

    def dying_group(cases, plants=None):   # pickled by value: the worker runs this very code
        if not os.path.exists(flag):
            open(flag, "w").close()
            os._exit(1)                  # a worker dies in the middle of its task
        return run_group(cases, plants)

    runner.run_group = dying_group
    defaults.set("sweep.cluster", "always")   # a cluster even for a sweep this small


if __name__ == "__main__":
    fault, argv = sys.argv[1], sys.argv[2:]
    kind, _, value = fault.partition(":")
    {"exit-after": lambda: _exit_after(int(value)),
     "kill-worker-once": lambda: _kill_worker_once(value)}[kind]()
    sys.exit(main(argv))
