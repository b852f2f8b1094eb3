"""How long the command takes to answer: `mbcontrol --version`, `--help`, `models` and
`simulate --help`, each a fresh process (what a user waits for), the median of --repeat runs,
against issue 58's goals (1.0 s, 1.5 s, 2.5 s; `simulate --help` as `--help`). Also the
modules each one imported that a quick answer should not need (CasADi, xarray, pandas,
python-control, Capytaine): the package faces load what they export on first use.

Then the whole `mbcontrol simulate sphere --wave jonswap --hs 2 --tp 8 --duration 600 --json`
(600 s simulated: goal 1.5 s, >= 400x real time, run once first so that the compiled code and
the hydro fit are cached), with a breakdown from a fresh process that does what the command
does, phase by phase (`--phases`, function `phases`): each library's import (marginal,
in the order the path needs them), mbcontrol's own modules, the plant (scene, hydro, compiled
code), the wave, the run (its synthesis and stepping, `wall_time_s`, apart), the checks and
summary, and the JSON output; wall and CPU seconds (on a shared machine the CPU seconds are
the steadier measure). The breakdown's summary must equal the command's output.

    python benchmarks/startup.py --out out/bench/startup [--repeat 5]

Writes startup.json. The same process's own start-up (python -c pass) is the baseline.
"""
from __future__ import annotations

import argparse
import os
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

GOALS_S = {"--version": 1.0, "--help": 1.5, "models": 2.5, "simulate --help": 1.5}
SIMULATE = "simulate sphere --wave jonswap --hs 2 --tp 8 --duration 600 --json"
SIMULATE_GOAL_S = 1.5                  # 600 s simulated: >= 400x real time
HEAVY = ("casadi", "xarray", "pandas", "control", "capytaine", "dask")
PROBE = ("import sys\nfrom mbcontrol.cli import main\ntry:\n    main({argv!r})\nexcept SystemExit:\n"
         "    pass\nprint('\\n' + ' '.join(m for m in {heavy!r} if m in sys.modules), file=sys.stderr)")


def user_python(cache: Path) -> dict:
    """The environment of a user's Python: one that keeps the modules it compiles (here in
    `cache`). A machine that sets PYTHONDONTWRITEBYTECODE (this one does) compiles every module
    from source in every process, some 2 s of each command here; no user's default does."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPYCACHEPREFIX"] = str(cache.resolve())
    return env


def timed(argv: list[str] | None, env: dict | None = None) -> float:
    """Wall time (s) of `mbcontrol ARGV` in a fresh process (None: the interpreter alone),
    in environment `env` (None: this process's)."""
    command = [sys.executable, "-c", "pass"] if argv is None else \
        [sys.executable, "-m", "mbcontrol", *argv]
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True, env=env)
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
    ap.add_argument("--phases", action="store_true",
                    help="print this process's phases of the simulate command as JSON (internal)")
    args = ap.parse_args(argv)
    if args.phases:
        print(json.dumps(phases()))
        return 0
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
    rows.append(simulate_row(args.repeat, user_python(args.out / "pycache")))
    args.out.mkdir(parents=True, exist_ok=True)
    from mbcontrol.atomic import write_text
    write_text(args.out / "startup.json", json.dumps({"python_s": python, "rows": rows},
                                                     indent=2))
    return 0 if all(r["holds"] for r in rows) else 1


def simulate_row(repeat: int, env: dict) -> dict:
    """The whole `mbcontrol simulate sphere ... --json` against its goal, as a user's Python
    runs it (`env`: modules compiled once and kept), and as this process's environment runs
    it (on this machine: compiled from source every time), with the phases of a fresh process
    doing the same (`phases`) and the heavy modules it imported."""
    words = SIMULATE.split()
    first = subprocess.run([sys.executable, "-m", "mbcontrol", *words], check=True,
                           capture_output=True, text=True, env=env)  # caches warm
    times = [timed(words, env) for _ in range(repeat)]
    median = statistics.median(times)
    here = statistics.median(timed(words) for _ in range(repeat))
    phases = [_phases(env) for _ in range(max(1, min(repeat, 3)))]
    same = all(p.pop("summary") == _without_wall(json.loads(first.stdout)) for p in phases)
    row = {"command": f"mbcontrol {SIMULATE}", "median_s": median, "runs_s": times,
           "goal_s": SIMULATE_GOAL_S, "holds": median <= SIMULATE_GOAL_S,
           "median_s_this_environment": here,
           "heavy_modules_imported": imported(words), "phases": phases,
           "phases_match_command_output": same}
    print(f"mbcontrol {SIMULATE}\n  {median:5.2f} s (goal {SIMULATE_GOAL_S:.1f} s"
          f"{', holds' if row['holds'] else ', MISSED'}; runs "
          f"{', '.join(f'{t:.2f}' for t in times)} s); heavy modules: "
          f"{', '.join(row['heavy_modules_imported']) or 'none'}")
    print(f"  as a user's Python runs it (modules compiled once, kept); in this process's "
          f"environment{' (PYTHONDONTWRITEBYTECODE: modules compiled in every process unless one compiled them before)' if 'PYTHONDONTWRITEBYTECODE' in os.environ else ''}: "
          f"{here:.2f} s")
    print("  phases, wall / CPU s (median of fresh processes):")
    for name in phases[0]:
        wall = statistics.median(p[name][0] for p in phases)
        cpu = statistics.median(p[name][1] for p in phases)
        print(f"    {name:<34} {wall:6.3f} / {cpu:6.3f}")
    print(f"  the phases' summary equals the command's output: {same}")
    return row


def _phases(env: dict) -> dict:
    """{phase: (wall s, CPU s)} and the summary, from a fresh process in `env`."""
    done = subprocess.run([sys.executable, __file__, "--phases"], check=True,
                          capture_output=True, text=True, env=env)
    out = json.loads(done.stdout)
    out["summary"] = _without_wall(out["summary"])
    return out


# the libraries the simulate path imports, in the order it needs them (their marginal cost)
LIBRARIES = ("numpy", "casadi", "scipy.linalg", "scipy.optimize", "pandas", "xarray",
             "dask.array", "netCDF4")


def phases() -> dict:
    """What `mbcontrol simulate sphere --wave jonswap --hs 2 --tp 8 --duration 600 --json`
    does, phase by phase in this (fresh) process: {phase: (wall s, CPU s)} and the summary
    the command prints. A library the path does not import is still imported here (its cost
    shows what leaving it out saves)."""
    import importlib
    out, clock = {}, [time.perf_counter(), time.process_time()]

    def lap(name):
        now = [time.perf_counter(), time.process_time()]
        out[name] = (now[0] - clock[0], now[1] - clock[1])
        clock[:] = now
    for name in LIBRARIES:
        importlib.import_module(name)
        lap(f"import {name}")
    import dataclasses
    from mbcontrol.analysis import summary
    from mbcontrol.plant import build_plant
    from mbcontrol.scene import load_scene
    from mbcontrol.sim import describe_initial, simulate
    from mbcontrol.waves import from_args
    lap("import mbcontrol (cli path modules)")
    plant = build_plant(load_scene("sphere"))
    lap("plant: scene, hydro, fit, compiled code")
    omega = plant.hydro.omega
    wave = from_args("jonswap", height=None, period=None, hs=2.0, tp=8.0, gamma=3.3, seed=0,
                     duration=600.0, data_band=(float(omega[0]), float(omega[-1])))
    headings = plant.hydro.data["wave_direction"].values       # the command's rule
    wave = dataclasses.replace(wave, direction=float(headings[0]) if len(headings) == 1 else 0.0)
    lap("wave")
    ds = simulate(plant, wave, duration=600.0, dt=None, controller=None, method=None)
    lap("run (compile check, synthesis, stepping, outputs, record)")
    out["  of which synthesis + stepping (wall_time_s)"] = (ds.attrs["wall_time_s"],) * 2
    result = summary(ds, plant)
    result["initial"] = describe_initial(plant, {})
    lap("checks and summary")
    json.dumps(result, indent=2)
    lap("JSON output")
    return {**out, "summary": json.loads(json.dumps(result))}


def _without_wall(summary: dict) -> dict:
    """A summary without its wall time (the one number that differs run to run)."""
    return {k: v for k, v in summary.items() if k != "wall_time_s"}


if __name__ == "__main__":
    sys.exit(main())
