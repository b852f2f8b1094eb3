"""How long the command takes to answer: `mbcontrol --version`, `--help`, `models` and
`simulate --help`, each a fresh process (what a user waits for), the median of --repeat runs,
against issue 58's goals (1.0 s, 1.5 s, 2.5 s; `simulate --help` as `--help`). Also the
modules each one imported that a quick answer should not need (CasADi, xarray, pandas,
python-control, Capytaine): the package faces load what they export on first use.

    python benchmarks/startup.py --out out/bench/startup [--repeat 5]

Writes startup.json. The same process's own start-up (python -c pass) is the baseline.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

GOALS_S = {"--version": 1.0, "--help": 1.5, "models": 2.5, "simulate --help": 1.5}
HEAVY = ("casadi", "xarray", "pandas", "control", "capytaine", "dask")
PROBE = ("import sys\nfrom mbcontrol.cli import main\ntry:\n    main({argv!r})\nexcept SystemExit:\n"
         "    pass\nprint('\\n' + ' '.join(m for m in {heavy!r} if m in sys.modules), file=sys.stderr)")


def timed(argv: list[str] | None) -> float:
    """Wall time (s) of `mbcontrol ARGV` in a fresh process (None: the interpreter alone)."""
    command = [sys.executable, "-c", "pass"] if argv is None else \
        [sys.executable, "-m", "mbcontrol", *argv]
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


def imported(argv: list[str]) -> list[str]:
    """The heavy modules a command leaves in sys.modules."""
    done = subprocess.run([sys.executable, "-c", PROBE.format(argv=argv, heavy=HEAVY)],
                          capture_output=True, text=True)
    return done.stderr.strip().splitlines()[-1].split() if done.stderr.strip() else []


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("out/bench/startup"))
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    python = statistics.median(timed(None) for _ in range(args.repeat))
    rows = []
    for command, goal in GOALS_S.items():
        words = command.split()
        median = statistics.median(timed(words) for _ in range(args.repeat))
        rows.append({"command": f"mbcontrol {command}", "median_s": median, "goal_s": goal,
                     "holds": median <= goal, "heavy_modules_imported": imported(words)})
        print(f"mbcontrol {command:<16} {median:5.2f} s (goal {goal:.1f} s"
              f"{', holds' if median <= goal else ', MISSED'}); heavy modules: "
              f"{', '.join(rows[-1]['heavy_modules_imported']) or 'none'}")
    print(f"python -c pass        {python:5.2f} s (the interpreter alone)")
    args.out.mkdir(parents=True, exist_ok=True)
    from mbcontrol.atomic import write_text
    write_text(args.out / "startup.json", json.dumps({"python_s": python, "rows": rows},
                                                     indent=2))
    return 0 if all(r["holds"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
