"""The README and the guide it points to (notebooks/guide.md) are tested: the README stays a
front door (at most 300 lines), their commands parse and name files that exist, the cheap ones
run, the Python example runs, the walkthrough runs pasted in an empty folder outside the
checkout, the demo prints what the guide shows, every module, file and make target they name
exists, and each table is either read by a test (the numbers checked against a computation) or
marked as a measurement with the command that remakes it.

The numbers of the identification and annual-energy tables are checked where they are
computed (tests/features/studies/identify/test_flume_data.py, tests/features/waves/test_annual_energy_pins.py),
which read them from the README through tests/helpers/readme.py.
"""
from __future__ import annotations

import glob
import importlib
import json
import os
import re
import subprocess
import sys

import pytest

from tests.helpers import readme
from mbcontrol.cli import build_parser, main
from mbcontrol.scene import list_models, load_scene

ROOT = readme.ROOT

# Each table of the README, by its first header cell, and what stands behind its numbers:
# ("test", path): a test reads the table and checks it against a computation;
# ("measured", command): timings and studies remade by a command the README names beside it;
# ("reference", why): a list of names, no figures to check.
TABLES = {
    "model": None,      # two tables share this header: resolved by line below
    "N barges": ("measured", "benchmarks/scaling.py"),
    "case": ("reference", "which pressure model applies when (mbcontrol.plant.nonlinear)"),
    "sphere, H 2.5 m, T 9.67 s": ("measured", "notebooks/controllers_sphere.ipynb"),
    "QP path": ("measured", "benchmarks/mpc.py"),
    "sea (Hs m, Tp s, γ)": ("measured", "benchmarks/wecccomp.py"),
    "": ("test", "tests/features/studies/identify/test_flume_data.py"),
    "key": ("reference", "the scene keys, generated (tests/scene/test_reference.py)"),
    "candidate (added to the previous set: quadratic + linear roll damping, roll added mass, "
    "heave and sway rig damping)": ("measured", "--cross-validate"),
    "rm3, scene PTO, 1 h at dt 0.05 s": ("measured", "benchmarks/sweep_light.py"),
    "benchmark case": ("measured", "benchmarks/rtf_table.py"),
    "blocks": ("measured", "benchmarks/export_step.py"),
    "rm3 at PacWave South, reactive, 32 seas × 600 s": ("measured",
                                                        "benchmarks/sweep_design.py"),
    "PacWave, 32 seas × 200 s, causal MPC": ("measured", "--controller mpc"),
    "rm3 at Humboldt Bay, 127 seas × 600 s, designed per sea": ("measured", "--design"),
    "site": ("test", "tests/features/waves/test_annual_energy_pins.py"),
    "device": ("test", "tests/features/controllers/test_electrical.py"),
    "optimum": ("measured", "benchmarks/wecopttool_electrical.py"),
    "keel radius r2 (m)": ("measured", "benchmarks/wecopttool_codesign.py"),
    "drivetrain": ("measured", "benchmarks/wecopttool_tste.py"),
    "r2 \\ J (kg m², scale 1)": ("measured", "notebooks/codesign.ipynb"),
    "data": ("measured", "benchmarks/radiation_fit.py"),
    "catalogue fit": ("test", "tests/features/test_catalogue.py"),
    "method": ("reference", "the integration methods by name"),
    "scenario": ("measured", "--stability"),
    "model, sea, tol": ("measured", "fidelity_auto"),
    "solver": ("measured", "benchmarks/export_qp.py"),
    "model, controller": ("measured", "benchmarks/export_step.py"),
    "floats": ("measured", "benchmarks/array_scaling.py"),
    "farm at PacWave South, 32 seas": ("measured", "--isolated n=1"),
    "R": ("measured", "benchmarks/interaction_cutoff.py"),
    "rm3 at PacWave South, reactive, designed per sea": ("measured", "--amplitudes random"),
    "PacWave South, 32 seas × 600 s, passive designed per sea": ("measured", "--spread 30"),
    "segments (lower/upper)": ("measured", "benchmarks/moordyn_rm3.py"),
    "RM3 in WEC-Sim's record, 40-360 s": ("measured", "tests/features/sim/test_moordyn_wecsim.py"),
}
MODEL_TABLES = {"mbcontrol (method, dt, radiation tol)": ("measured", "benchmarks/speed.py"),
                "C step median / p99 / max (us)": ("measured", "benchmarks/export_step.py"),
                "C step median / p99 / max (us), wall": ("measured",
                                                         "benchmarks/export_step.py"),
                "components x nodes": ("measured", "benchmarks/stepping.py"),
                "what it is": ("reference", "the catalogue (tests/features/test_catalogue.py builds each)"),
                "real-time factor": ("measured", "benchmarks/nonlinear_fk.py")}


def _mbcontrol_commands():
    """Every `mbcontrol ...` command line (as pasted after activation, or by its path)."""
    return [words[1:] for words in readme.commands()
            if words[0] in ("mbcontrol", ".venv/bin/mbcontrol")]


def test_the_readme_is_a_front_door():
    """Issue 40: 1,408 lines, the first device at line ~965. Now: what it is, the two commands,
    your own device, a first controller and sweep, trust, Python, where next."""
    text = readme.README.read_text()
    assert len(text.splitlines()) <= 300
    headings = [line for line in text.splitlines() if line.startswith("## ")]
    assert headings[:2] == ["## Install: the two commands", "## Your own device in five minutes"]
    assert "notebooks/guide.md" in text and "make docs" in text


def test_every_table_is_checked_or_says_how_it_was_measured():
    lines = readme.text().splitlines()
    for start, rows in readme.tables():
        header = rows[0]
        kind = TABLES.get(header[0]) if header[0] != "model" else MODEL_TABLES.get(header[2],
                                                                                  MODEL_TABLES.get(header[1]))
        assert kind is not None, f"{readme.where(start)}: table {header[0]!r} is not classified"
        what, where = kind
        if what == "test":                     # the test exists and reads this very table
            source = (ROOT / where).read_text()
            assert "readme.table(" in source or "readme.row(" in source, where
        elif what == "measured":               # the command that remakes it is named nearby
            context = "\n".join(lines[max(0, start - 40):start + len(rows) + 3])
            assert where in context, f"{readme.where(start)}: {where} not named near the table"


def test_commands_parse_and_name_what_exists():
    """Every `.venv/bin/mbcontrol ...` line parses with the real parser; the models it names
    are in the catalogue, the data files it reads exist (../shared beside the clone)."""
    commands = _mbcontrol_commands()
    assert len(commands) >= 10
    for words in commands:
        expanded = []
        for word in words:
            if any(c in word for c in "*?["):
                matches = sorted(glob.glob(str(ROOT / word)))
                assert matches, f"README: {' '.join(words)}: {word} matches no file"
                expanded += matches
            else:
                expanded.append(word)
        if expanded[:1] in (["--version"], ["--help"]):
            continue
        args = build_parser().parse_args(expanded)        # SystemExit (fails) on a bad flag
        model = getattr(args, "model", None) or getattr(args, "name", None)
        if model and model.endswith(".toml"):          # a scene the walkthrough writes
            assert f"cat > {model} <<" in readme.text(), words
        elif model:
            assert model in list_models(), words
        for option in ("seas", "data"):
            for path in (getattr(args, option, None) or []) if option == "data" else \
                    [getattr(args, option, None)] if getattr(args, option, None) else []:
                assert (ROOT / path).exists(), f"README: {' '.join(words)}: {path} not found"


def test_make_targets_files_and_modules_named_in_the_readme_exist():
    text = readme.text()
    makefile = (ROOT / "Makefile").read_text()
    for target in set(re.findall(r"`make (\w+)`", text)) | {"demo", "test", "bench", "docs"}:
        assert re.search(rf"^{target}:", makefile, re.M), f"README names make {target}"
    for path in set(re.findall(r"(?<![\w/.])((?:models|notebooks|benchmarks|controllers|"
                               r"mbcontrol|tests)/[\w/.-]+\.(?:py|toml|ipynb|png|md|nc))", text)):
        assert (ROOT / path).exists(), f"README names {path}, which does not exist"
    for dotted in set(re.findall(r"`(mbcontrol(?:\.\w+)+)", text)):
        parts = dotted.split(".")
        for cut in range(len(parts), 0, -1):          # the longest importable module ...
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
            except ImportError:
                continue
            for attr in parts[cut:]:                   # ... and the rest as attributes
                assert hasattr(obj, attr), f"README names {dotted}: no {attr}"
                obj = getattr(obj, attr)
            break


@pytest.mark.parametrize("words", [
    ["--version"], ["models"], ["models", "sphere"], ["defaults"], ["hydro", "hinged_barge"],
    ["simulate", "hinged_barge", "--wave", "regular", "--height", "0.02", "--period", "1.0",
     "--json"],
    ["linearize", "hinged_barge", "--bode", "out/bode.png", "--json"],
    ["simulate", "sphere", "--wave", "none", "--initial", "heave=0.5", "--duration", "40"],
    ["--help"],
    ["design", "sphere", "--controller", "reactive", "--wave", "jonswap", "--hs", "2", "--tp", "8"],
    ["sweep", "sphere", "--hs", "1", "2", "3", "--tp", "7", "9", "11", "--controller", "passive",
     "--set", "damping=4e5", "--duration", "300", "--plot", "out/sphere_sweep.png"],
], ids=lambda w: " ".join(w[:2]))
def test_cheap_commands_run_as_printed(words, tmp_path, monkeypatch, capsys):
    assert words in _mbcontrol_commands(), "the README no longer shows this command"
    monkeypatch.chdir(tmp_path)                       # its out/ files land in a scratch folder
    if words[0] in ("--version", "--help"):
        with pytest.raises(SystemExit) as stop:
            main(words)
        out = capsys.readouterr().out
        assert stop.value.code == 0 and re.search(r"mbcontrol \d|Exit status: 0", out)
        return
    assert main(words) == 0


def test_python_example_runs():
    (block,) = readme.code_blocks("python")
    done = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    power, unit, verdict = done.stdout.split()[:3]
    assert unit == "W" and float(power) > 0 and verdict == "valid", done.stdout


TIMING = re.compile(r"(built in [\d.]+ s|[\d,]+x real time)")


def _skeleton(line: str) -> str:
    return readme.NUMBER.sub("#", TIMING.sub("T", line)).strip()


def _agree(quoted: str, measured: float) -> bool:
    """A quoted figure holds when the measurement rounds to it, give or take one unit of its
    last digit or 0.5 % (the MPC runs vary by about 0.1 % between machines)."""
    decimals = len(quoted.split(".")[1]) if "." in quoted else 0
    value = float(quoted.replace(",", ""))
    return abs(measured - value) <= max(1.0 * 10.0 ** -decimals, 0.005 * abs(value))


@pytest.mark.slow
def test_demo_prints_what_the_readme_shows(tmp_path):
    """`make demo`'s output, as the README quotes it, line for line; timings and real-time
    factors are the machine's and are not compared."""
    shown = [b for b in readme.code_blocks("") if b.startswith("[demo] 1/6")]
    assert len(shown) == 1, "README: the demo's output block is missing"
    done = subprocess.run([sys.executable, "-m", "mbcontrol.demo", "--out", str(tmp_path)],
                          capture_output=True, text=True, cwd=ROOT, timeout=900)
    assert done.returncode == 0, done.stderr[-2000:]
    printed = {_skeleton(line): line for line in done.stdout.splitlines()}
    for line in shown[0].splitlines():
        if line.startswith("  wrote "):
            continue
        key = _skeleton(line)
        assert key in printed, f"README demo line not printed any more: {line!r}"
        quoted = readme.NUMBER.findall(TIMING.sub("T", line))
        measured = [float(n.replace(",", "")) for n in
                    readme.NUMBER.findall(TIMING.sub("T", printed[key]))]
        for q, m in zip(quoted, measured):
            assert _agree(q, m), f"README: {line.strip()!r}\n  demo: {printed[key].strip()!r}"


@pytest.mark.slow
def test_the_walkthrough_runs_as_written(tmp_path):
    """"Your own device in five minutes", pasted into a shell in an empty folder: the scene
    written, its BEM data computed by Capytaine, the fit, the design and the simulation, with
    limits in N and mm. At most one message on stderr besides progress: the note that part of
    the sea lies above the BEM data."""
    (block,) = [b for b in readme.code_blocks("bash") if "cat > my_buoy/buoy.toml" in b]
    # as the README's set-up leaves a shell: .venv/bin on the PATH (source .venv/bin/activate),
    # the commands pasted as they stand in an empty folder outside the checkout
    path = f"{os.path.dirname(sys.executable)}{os.pathsep}{os.environ.get('PATH', '')}"
    assert not tmp_path.is_relative_to(ROOT)
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", block], capture_output=True,
                          text=True, cwd=tmp_path, timeout=900,
                          env={**os.environ, "TQDM_DISABLE": "1", "PATH": path})
    assert done.returncode == 0, done.stderr[-3000:]
    assert (tmp_path / "my_buoy" / "run.png").stat().st_size > 10_000
    summary = json.loads(done.stdout[done.stdout.index("{"):])
    pto = summary["ptos"]["generator"]
    assert summary["valid"] and pto["force_max"] == 150.0 and pto["stroke_max"] == 0.08
    assert 0.13 < pto["mean_power_W"] < 0.15, pto              # the README's "about 142 mW"
    messages = {line for line in done.stderr.splitlines() if line.startswith("mbcontrol:")}
    assert all("lies outside the hydro data" in m for m in messages), messages


def test_every_relative_link_of_the_documents_resolves():
    """The link check of the front door and the guide: each relative link names a file that
    exists, read from the document's own folder (the site is built from the same files)."""
    broken = []
    for path in readme.DOCUMENTS:
        for target in re.findall(r"\]\(([^)\s]+)\)", path.read_text()):
            if re.match(r"[a-z]+://|#|mailto:", target):
                continue
            if not (path.parent / target.split("#")[0]).exists():
                broken.append(f"{path.relative_to(ROOT)}: {target}")
    assert not broken, broken
