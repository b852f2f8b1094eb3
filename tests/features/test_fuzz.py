"""Fuzzing the inputs (Hypothesis): mutated catalogue scenes, mutated BEM files and random
command lines. Whatever comes in, the toolbox answers with a result or with one of its typed
errors (mbcontrol.errors.MbcontrolError: the CLI's exit 1), within a time limit; the command
line exits with a documented status (0 done, 1 bad input, 2 bad command line, 3 invalid
result, 4 sweep cases failed, 5 the machine refused) and prints no traceback. What loads is
what the rules allow: its names obey the name rule, its BEM data the physical checks.

The examples are derandomised (the same ones every run, so CI is reproducible): about 20 s of
CI in all. HYPOTHESIS_PROFILE=deep runs ten times as many with fresh randomness, a search to
run before a release (about 2 minutes)."""
from __future__ import annotations

import copy
import io
import math
import os
import re
import tempfile
import time
import tomllib
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from mbcontrol.errors import MbcontrolError
from mbcontrol.scene import load_scene, parse_scene
from mbcontrol.scene.load import catalogue_dir, list_models
from mbcontrol.sim.methods import MAX_STEPS
from mbcontrol.textsafe import name_problem

from tests.helpers.reader_data import SPHERE

settings.register_profile("ci", derandomize=True, database=None, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("deep", database=None, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
PROFILE = settings.get_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
SCALE = 10 if os.environ.get("HYPOTHESIS_PROFILE") == "deep" else 1

# A scene parses in milliseconds and a command here in about a second: an example past these
# is a hang (9**9**9**9 never returned), not a slow machine.
SCENE_SECONDS = 2.0
EXIT_STATUSES = {0, 1, 2, 3, 4, 5}

HOSTILE_TEXT = [
    'pto*/\n#include\t"/etc/passwd"\n/*', "*/", "a\nb", "\x00", "\x1b[2J", "\u202e", "$(touch x)",
    "<x a='1'>&", "a" * 5000, "{9**9**9**9}", "{" + "(" * 300 + "}", "{__import__('os')}",
    "1e999 kg", "nan", "-inf m", "{1/0}", "{x}", "", " ", "ground", "a__b", "3 kg", "60 mm",
]
HOSTILE_NUMBERS = [math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0, 1e-300, 1e300, 2 ** 63,
                   -2 ** 63, 1e30, 5e-324]

values = st.recursive(
    st.one_of(st.sampled_from(HOSTILE_TEXT), st.sampled_from(HOSTILE_NUMBERS),
              st.text(max_size=20), st.floats(), st.integers(-2 ** 64, 2 ** 64), st.booleans()),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner,
                                                                 max_size=3),
    max_leaves=6)


def _catalogue() -> dict[str, dict]:
    return {name: tomllib.loads((catalogue_dir() / f"{name}.toml").read_text())
            for name in list_models()}


CATALOGUE = _catalogue()


def _leaves(data, path=()):
    """Every (path, value) of a nested TOML document; lists and tables are leaves too."""
    yield path, data
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _leaves(value, path + (key,))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            yield from _leaves(value, path + (i,))


def _mutated(data, path, action, value):
    """A deep copy of `data` with the node at `path` replaced, deleted, or given a new key."""
    data = copy.deepcopy(data)
    if not path:
        return value if action == "replace" else data
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    key = path[-1]
    if action == "replace":
        parent[key] = value
    elif action == "delete":
        del parent[key]
    elif isinstance(parent[key], dict):
        parent[key]["unexpected_key"] = value
    return data


@st.composite
def scene_mutations(draw):
    name = draw(st.sampled_from(sorted(CATALOGUE)))
    data = CATALOGUE[name]
    leaves = list(_leaves(data))
    path, _ = leaves[draw(st.integers(0, len(leaves) - 1))]
    action = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
    return name, _mutated(data, path, action, draw(values))


def _check_scene(scene) -> None:
    names = [scene.name] + [x.name for group in (scene.bodies, scene.joints, scene.ptos,
                                                 scene.moorings, scene.frictions)
                            for x in group]
    bad = [n for n in names if name_problem(n)]
    assert not bad, f"a scene loaded with names the rule refuses: {bad!r}"


@settings(PROFILE, max_examples=1000 * SCALE)
@given(scene_mutations())
def test_a_mutated_catalogue_scene_loads_or_is_refused_by_its_field(case):
    name, data = case
    start = time.perf_counter()
    try:
        scene = parse_scene(data, catalogue_dir() / f"{name}.toml")
    except MbcontrolError as exc:
        # one line that names the file (a TOML path of this scene) and prints safely
        assert f"{name}.toml" in str(exc)
    else:
        _check_scene(scene)
    assert time.perf_counter() - start < SCENE_SECONDS


@settings(PROFILE, max_examples=500 * SCALE)
@given(st.sampled_from(sorted(CATALOGUE)), st.integers(0, 10 ** 6),
       st.one_of(st.binary(max_size=40), st.sampled_from([s.encode() for s in HOSTILE_TEXT])),
       st.booleans())
def test_a_mutated_scene_file_loads_or_is_refused(name, where, inserted, cut):
    text = (catalogue_dir() / f"{name}.toml").read_bytes()
    where %= len(text) + 1
    mutated = text[:where] + (b"" if cut else inserted + text[where:])
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{name}.toml"
        path.write_bytes(mutated)
        # the hydro files a catalogue scene names are beside it in the catalogue
        for extra in catalogue_dir().glob(f"{name}*"):
            if extra.suffix != ".toml":
                (Path(folder) / extra.name).symlink_to(extra)
        try:
            _check_scene(load_scene(path))
        except MbcontrolError as exc:
            assert str(path) in str(exc)


# ----------------------------------------------------------------------------- BEM files
_NUMBER = re.compile(r"-?\d\.\d+E[+-]\d\d")


@pytest.fixture(scope="module")
def mini_wamit(tmp_path_factory) -> str:
    """sphere.out cut to 10 of its 240 frequencies (reads in 10 ms instead of 0.4 s)."""
    if not SPHERE.exists():
        pytest.skip(f"reference data not found in {SPHERE.parent}")
    lines = SPHERE.read_text().splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if "Wave period (sec)" in line]
    keep = lines[:starts[0]]
    for k in range(0, len(starts), 24):
        keep += lines[starts[k]:starts[k + 1] if k + 1 < len(starts) else len(lines)]
    return "".join(keep)


class Mutation:
    """A mutated file: its text, and a short account of the change (Hypothesis prints the
    account of a failing example, not the 60 kB of text)."""

    def __init__(self, account: str, text: str):
        self.account, self.text = account, text

    def __repr__(self):
        return f"Mutation({self.account!r})"


@st.composite
def wamit_mutations(draw, text: str):
    lines = text.splitlines(keepends=True)
    kind = draw(st.sampled_from(["number", "number", "number", "negate", "delete", "truncate",
                                 "duplicate", "insert"]))
    i = draw(st.integers(0, len(lines) - 1))
    if kind in ("number", "negate"):
        spans = [m.span() for m in _NUMBER.finditer(text)]
        lo, hi = spans[draw(st.integers(0, len(spans) - 1))]
        token = text[lo:hi]
        new = (token[1:] if token.startswith("-") else "-" + token) if kind == "negate" else \
            draw(st.sampled_from(["NaN", "Infinity", "-1.000000E+300", "1.0E+400", "**********",
                                  "", "0.000000E+00", "1.0E-320", "x"]))
        line = text.count("\n", 0, lo) + 1
        return Mutation(f"line {line}: {token} -> {new}", text[:lo] + new + text[hi:])
    if kind == "delete":
        return Mutation(f"line {i + 1} deleted", "".join(lines[:i] + lines[i + 1:]))
    if kind == "truncate":
        return Mutation(f"cut before line {i + 1}", "".join(lines[:i]))
    if kind == "duplicate":
        return Mutation(f"line {i + 1} twice", "".join(lines[:i + 1] + lines[i:]))
    extra = draw(st.sampled_from(HOSTILE_TEXT))
    return Mutation(f"{extra[:30]!r} before line {i + 1}",
                    "".join(lines[:i] + [extra + "\n"] + lines[i:]))


def _physical(ds) -> list[str]:
    """What a dataset a reader returned may not hold (hydro.readers.physical): non-finite
    values; a negative added-mass diagonal that is not reported as a resonance band (a band
    inside the frequency range is physical: gaps, moonpools); an indefinite damping matrix."""
    problems = []
    for var in ("added_mass", "radiation_damping", "excitation_force"):
        if not np.all(np.isfinite(ds[var].values)):
            problems.append(f"{var} not finite")
    measured = ds.attrs["cleaning"]["physical"]
    diag = np.einsum("wii->wi", ds["added_mass"].values)
    if np.any(diag < -1e-3 * np.abs(diag).max()) and not measured["resonance_bands"]:
        problems.append("negative added-mass diagonal, not reported")
    # passivity on B scaled by the largest diagonal of its kind (translations in N s/m,
    # rotations in N m s/rad), as the checks define it, to their tolerance of 2e-2
    B = ds["radiation_damping"].values
    dofs = [str(d) for d in ds["radiating_dof"].values]
    rotation = np.array([d.endswith(("Roll", "Pitch", "Yaw")) for d in dofs])
    largest = np.abs(np.einsum("wii->wi", B)).max(axis=0)
    kind_max = np.where(rotation, largest[rotation].max(initial=0), largest[~rotation].max(initial=0))
    s = np.sqrt(np.maximum(kind_max, 1e-300))
    scaled = 0.5 * (B + np.swapaxes(B, 1, 2)) / np.outer(s, s)
    worst = np.linalg.eigvalsh(scaled).min()
    if worst < -2e-2:
        problems.append(f"damping not passive (scaled eigenvalue {worst:.3g})")
    return problems


def test_bem_mutations(mini_wamit):
    """The mini file reads, and so does every mutation Hypothesis draws, or is refused."""
    from mbcontrol.hydro.readers import read_wamit

    @settings(PROFILE, max_examples=400 * SCALE)
    @given(wamit_mutations(mini_wamit))
    def mutated(case):
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "device.out"
            path.write_text(case.text)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")      # repairs are reported as warnings
                    ds = read_wamit(path)
            except MbcontrolError as exc:
                assert path.name in str(exc), (case, str(exc))
            else:
                assert not _physical(ds), (case, _physical(ds))

    with tempfile.TemporaryDirectory() as folder:
        (Path(folder) / "device.out").write_text(mini_wamit)
        assert not _physical(read_wamit(Path(folder) / "device.out"))
    mutated()


# ---------------------------------------------------------------------------- command line
# Valid command lines, cheap to run (the sphere and the hinged barge, short records at coarse
# steps): each example mutates one of them, so most examples reach deep into the code
BASES = [
    "simulate sphere --wave regular --height 1 --period 8 --duration 20 --dt 0.05 "
    "--controller passive --set damping=4e5",
    "simulate sphere --wave jonswap --hs 1 --tp 8 --duration 20 --dt 0.1 --json",
    "simulate hinged_barge --wave regular --height 0.02 --period 1 --duration 5 --dt 0.01 "
    "--controller reactive --set damping=2 --set stiffness=1 --plot run.png",
    "linearize sphere --json --bode bode.png",
    "hydro sphere --json",
    "models sphere",
    "defaults --json",
    "keys",
]
FLAGS = {"simulate": ["--wave", "--height", "--period", "--hs", "--tp", "--duration", "--dt",
                      "--controller", "--set", "--method", "--seed", "--json", "--allow-invalid",
                      "--from", "--repeat", "--gamma", "--plot", "--param"],
         "linearize": ["--json", "--bode", "--set", "--param"],
         "hydro": ["--json", "--tol"], "models": ["--json"], "defaults": ["--json"],
         "keys": ["--readme"]}
VALUES = ["regular", "jonswap", "passive", "reactive", "mpc", "nope", "damping=1e5",
          "damping=nan", "stiffness=-1e30", "force_max=none", "x=1", "=", "rk4", "exp-rk4",
          "cvodes", "bogus", "last-repeat", "0", "-1", "1e308", "nan", "inf", "-inf", "0.5",
          "2", "8", "20", "3", "0.01", "0.25", "1e-9", "1e9", "\x1b[2J", "a\nb", "--",
          "out*/.png", "../x.png", "/dev/full", "", "pto__damping=1e5", "sphere", "x.toml"]


@st.composite
def command_lines(draw):
    """A base command line with one or two of its values replaced (by an odd value, or text),
    a flag added with a value, or, seldom, a token dropped."""
    argv = draw(st.sampled_from(BASES)).split()
    for _ in range(draw(st.integers(0, 2))):
        values = [i for i, a in enumerate(argv) if i > 0 and not a.startswith("-")]
        action = draw(st.sampled_from(["value"] * 4 + ["flag"] * 2 + ["drop"]))
        if action == "value" and values:
            i = draw(st.sampled_from(values))
            argv[i] = draw(st.sampled_from(VALUES) if draw(st.integers(0, 3)) else
                           st.text(max_size=12))
        elif action == "drop" and len(argv) > 1:
            del argv[draw(st.integers(1, len(argv) - 1))]
        else:
            argv += [draw(st.sampled_from(FLAGS[argv[0]] + ["--help", "-q"])),
                     draw(st.sampled_from(VALUES))]
    return argv


def _too_long(argv) -> bool:
    """A command line that would simulate more than 30 s, at a step below 1e-3 s, or with an
    MPC: valid long jobs, not faults, skipped to bound the test's time (a run beyond the limit
    on steps is refused at once, and kept)."""
    def last(flag, default):
        values = [argv[i + 1] for i, a in enumerate(argv[:-1]) if a == flag]
        try:
            return float(values[-1]) if values else default
        except ValueError:
            return math.nan
    duration = last("--duration", 600.0)          # simulate's sea default
    dt = last("--dt", 0.01)
    if "mpc" in argv or "cvodes" in argv:
        return True
    if not (math.isfinite(duration) and math.isfinite(dt) and duration > 0 and dt > 0):
        return False
    return duration / dt <= MAX_STEPS and (duration > 30 or dt < 1e-3)


@settings(PROFILE, max_examples=150 * SCALE)
@given(command_lines())
# what the fuzzing found, kept: a figure path without a format (matplotlib's ValueError), a
# --readme that is not there (FileNotFoundError), a sea of 1e308 s, a period of 1e308 s
# (OverflowError); and the cases
@example(["linearize", "sphere", "--json", "--bode", "0"])
@example(["keys", "--readme", "regular"])
@example(["simulate", "sphere", "--wave", "regular", "--height", "2", "--period", "8",
          "--dt", "4", "--duration", "5"])
@example(["simulate", "sphere", "--wave", "jonswap", "--hs", "1e6", "--tp", "8"])
@example(["simulate", "sphere", "--duration", "1e9", "--dt", "0.01"])
@example(["simulate", "sphere", "--wave", "jonswap", "--hs", "1", "--tp", "8", "--duration",
          "1e308", "--dt", "0.1"])                     # numpy: maximum allowed size exceeded
@example(["simulate", "sphere", "--wave", "regular", "--height", "1", "--period", "1e308"])
def test_a_random_command_line_exits_with_a_documented_status(argv):
    from mbcontrol.cli import main
    if argv[0] == "simulate" and _too_long(argv):
        return
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as folder:      # files the command writes land here
        os.chdir(folder)
        try:
            with redirect_stdout(out), redirect_stderr(err):
                try:
                    code = main(argv)
                except SystemExit as exc:    # argparse: --help (0) or a bad command line (2)
                    code = exc.code
        finally:
            os.chdir(here)
    event(f"{argv[0]}: exit {code}")     # --hypothesis-show-statistics: how deep they went
    assert code in EXIT_STATUSES, (argv, code, err.getvalue()[-2000:])
    assert "Traceback" not in err.getvalue(), (argv, err.getvalue()[-2000:])
