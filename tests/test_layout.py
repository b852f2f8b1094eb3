"""The house's layout, read from the source with `ast`: imports run one way along the flow
(scene < multibody < hydro < plant < sim < analysis < controllers < studies < export < cli), no module
imports itself back through others, another package is entered only by its face (its
__init__), no module and no function is past the size rule, no generated file is committed.
Function-level (lazy) imports count as much as module-level ones."""
import ast
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STAGES = ("scene", "multibody", "hydro", "plant", "sim", "analysis", "controllers", "studies",
          "export", "cli")
# modules every stage may use; they import no stage themselves
COMMON = ("errors", "results", "waves", "plotting", "cache", "console", "atomic", "defaults", "lti", "textsafe",
          "lazy", "checkout")
# top-level programs that drive the whole flow: may import any stage, none may import them
DRIVERS = ("cli", "demo", "models", "__main__", "api")   # __main__: python -m mbcontrol;
# api: the front door behind `import mbcontrol as mbc` (load, simulate, ...)
MAX_LINES = 400          # the house rule: a module past ~400 lines is two modules
SOURCE_DIRS = {"mbcontrol": ROOT / "mbcontrol", "mbcontrol.controllers": ROOT / "controllers",
               "mbcontrol.models": ROOT / "models"}


def _modules() -> dict[str, Path]:
    """Module name -> file, for the package as installed (controllers/ and models/ inside)."""
    found = {}
    for prefix, folder in SOURCE_DIRS.items():
        for path in folder.rglob("*.py"):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            found[".".join([prefix, *parts])] = path
    return found


MODULES = _modules()


def _resolve(module: str, path: Path, node: ast.ImportFrom) -> str:
    if node.level == 0:
        return node.module or ""
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    base = package.split(".")
    if node.level > 1:
        base = base[:-(node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _target(name: str) -> str | None:
    """The longest known module a dotted import name refers to."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def import_graph() -> dict[str, set[str]]:
    """module -> the package modules it imports (with `from X import sub`, X.sub)."""
    graph = {}
    for module, path in MODULES.items():
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom):
                base = _resolve(module, path, node)
                if not base.startswith("mbcontrol"):
                    continue
                for alias in node.names:
                    targets.add(_target(f"{base}.{alias.name}"))
            elif isinstance(node, ast.Import):
                targets |= {_target(a.name) for a in node.names if a.name.startswith("mbcontrol")}
        graph[module] = {t for t in targets if t and t != module}
    return graph


def stage(module: str) -> tuple[int, str]:
    """(rank along the flow, name); common modules rank -1, drivers rank past the last stage."""
    first = module.split(".")[1] if "." in module else ""
    if module == "mbcontrol":
        return len(STAGES) + 1, "mbcontrol (entry points)"
    if first in COMMON:
        return -1, first
    if first in DRIVERS:
        return len(STAGES), first
    return STAGES.index(first), first


def test_every_module_has_a_stage():
    unknown = [m for m in MODULES if m != "mbcontrol" and m.split(".")[1] not in
               STAGES + COMMON + DRIVERS]
    assert not unknown, f"modules outside the flow's packages: {unknown}"


def test_imports_run_one_way_along_the_flow():
    graph = import_graph()
    upstream = []
    for module, targets in graph.items():
        rank, name = stage(module)
        for target in targets:
            target_rank, target_name = stage(target)
            if target == "mbcontrol":
                upstream.append(f"{module} imports the top package mbcontrol (use a stage package)")
            elif target_rank > rank:
                upstream.append(f"{module} ({name}) imports {target} ({target_name}), "
                                f"which is downstream of it")
    assert not upstream, "\n".join(sorted(upstream))


HYDRO_STAGES = ("mesh", "data", ("bem", "readers"), ("fit", "source"), "model")   # issue 37: hydro's rooms


def _hydro_rank(module: str):
    """Rank of a module inside mbcontrol.hydro along HYDRO_STAGES; None for the package itself."""
    parts = module.split(".")
    if parts[:2] != ["mbcontrol", "hydro"] or len(parts) < 3:
        return None
    for rank, names in enumerate(HYDRO_STAGES):
        if parts[2] in ((names,) if isinstance(names, str) else names):
            return rank
    raise AssertionError(f"{module}: not in a stage of mbcontrol.hydro {HYDRO_STAGES}")


def test_hydro_imports_only_go_down_its_stages():
    """Inside mbcontrol.hydro, a module imports only from its own sub-package or earlier stages:
    mesh < data < bem, readers < fit < model (the package's __init__ is its public face)."""
    graph = import_graph()
    bad = []
    for module, targets in graph.items():
        rank = _hydro_rank(module)
        if rank is None:
            continue
        for target in targets:
            target_rank = _hydro_rank(target)
            same_room = target.split(".")[:3] == module.split(".")[:3]
            if target == "mbcontrol.hydro" or (target_rank is not None and target_rank >= rank and not same_room):
                bad.append(f"{module} imports {target}")
    assert not bad, "\n".join(sorted(bad))


def test_common_modules_import_no_stage():
    graph = import_graph()
    bad = [f"{m} imports {t}" for m, targets in graph.items() if stage(m)[0] == -1
           for t in targets if stage(t)[0] != -1]
    assert not bad, bad


def test_no_import_circles():
    """No module reaches itself through its imports (Tarjan's strongly connected components)."""
    graph = import_graph()
    index, low, on_stack, stack, circles = {}, {}, set(), [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    assert not circles, f"import circles: {circles}"


def test_the_graph_sees_known_edges():
    """The checks above are only as good as the graph: it must see relative, absolute,
    lazy (in-function) and submodule imports."""
    graph = import_graph()
    assert "mbcontrol.plant.fidelity" in graph["mbcontrol.plant.build"]          # relative
    assert "mbcontrol.analysis" in graph["mbcontrol.controllers.impedance"]  # lazy, absolute
    assert "mbcontrol.studies.identify.extrapolation" in graph[
        "mbcontrol.studies.identify.setup"]                                       # from X import sub
    assert "mbcontrol.plant.process" in graph["mbcontrol.plant"]                  # a package face


@pytest.mark.parametrize("folder", ["mbcontrol", "controllers", "models", "benchmarks"])
def test_no_module_past_the_size_rule(folder):
    long = {str(p.relative_to(ROOT)): n for p in (ROOT / folder).rglob("*.py")
            if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_no_generated_file_is_committed():
    try:
        files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                               check=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git work tree")
    # Hand-written C lives in one folder, the sources an export copies beside its generated
    # code (mbcontrol/export/csrc/); a C file anywhere else, or one there that CasADi wrote,
    # is generated and belongs in the cache or out/.
    hand_written = "mbcontrol/export/csrc/"
    generated = [f for f in files if f.endswith((".so", ".o", ".pyc"))
                 or (f.endswith(".c") and not f.startswith(hand_written))
                 or (f.endswith(".c") and "automatically generated by CasADi"
                     in (ROOT / f).read_text())]
    assert not generated, generated


def test_every_package_is_installed():
    """pyproject.toml lists packages explicitly: a package left out would import from a source
    checkout (editable install) and be missing from a wheel."""
    import tomllib
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
                 ["packages"])
    packages = {m for m, path in MODULES.items() if path.name == "__init__.py"}
    assert packages == listed, (f"missing from pyproject.toml: {sorted(packages - listed)}; "
                                f"listed but absent: {sorted(listed - packages)}")
    # a folder of data files (C sources, fits) is a package too, or setuptools warns at every
    # install and a wheel may leave it out
    folders = {".".join([prefix, *d.relative_to(folder).parts]) for prefix, folder in
               SOURCE_DIRS.items() for d in [folder, *folder.rglob("*")]
               if d.is_dir() and d.name != "__pycache__" and any(f.is_file() for f in d.iterdir())}
    assert folders <= listed, f"folders with files that are not packages: {sorted(folders - listed)}"


def test_cited_test_files_exist():
    """README, the guide and docstrings point readers at tests as evidence: every cited
    tests/...py path exists (they moved once, and five citations went stale; they moved again
    when the tests came to mirror the source)."""
    import re
    cited = {}
    for path in [ROOT / "README.md", ROOT / "notebooks" / "guide.md", *MODULES.values(),
                 *(ROOT / "benchmarks").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]:
        for name in re.findall(r"tests/[A-Za-z0-9_/]+\.py", path.read_text()):
            cited.setdefault(name, str(path.relative_to(ROOT)))
    missing = {name: where for name, where in cited.items() if not (ROOT / name).exists()}
    assert not missing, missing


def _package(module: str) -> str:
    """The stage (or common module) a module belongs to: mbcontrol.hydro.bem.solve -> hydro."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def test_no_private_name_is_imported_across_packages():
    """A `_name` is its package's own business: another package importing it couples to
    internals that may change without notice (issue 22 found `_PLANTS` and `_band`)."""
    crossing = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.ImportFrom):
                target = _resolve(module, path, node)
                if not target.startswith("mbcontrol"):
                    continue
                crossing += [f"{module} imports {target}.{a.name}" for a in node.names
                             if a.name.startswith("_") and not a.name.startswith("__")
                             and _package(target) != _package(module)]
    assert not crossing, crossing


def _is_package(name: str) -> bool:
    return name in MODULES and MODULES[name].name == "__init__.py"


def _face(package: str) -> set[str]:
    """The names a package's `__init__` binds at its top level."""
    names = set()
    for node in ast.parse(MODULES[package].read_text()).body:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names |= {t.id for t in node.targets if isinstance(t, ast.Name)}
    return names


def _reached(module: str, path: Path, node) -> list[str]:
    """The modules inside another package that an import statement reaches past its face."""
    if isinstance(node, ast.Import):
        targets = [a.name for a in node.names]
    else:
        base = _resolve(module, path, node)
        if _is_package(base):   # from package import name: a module unless the face binds it
            face = _face(base)
            targets = [f"{base}.{a.name}" for a in node.names if a.name not in face]
        else:
            targets = [base]
    return [t for t in targets if t.count(".") >= 2 and t in MODULES and not _is_package(t)
            and _package(t) != _package(module)]


def test_packages_are_entered_by_their_face():
    """Another package is used through its `__init__` (its face: what it promises others),
    never by reaching into one of its modules: `from mbcontrol.analysis import
    envelope_bound`, not `from mbcontrol.analysis.envelope import envelope_bound`. A stage
    made of sub-packages (hydro's readers, studies' sweep) may be entered at a sub-package's
    face. Inside a package, modules import each other freely; a common module that is one
    file (errors, lti) is its own face."""
    reaching = [f"{module}:{node.lineno} imports {target}"
                for module, path in MODULES.items()
                for node in ast.walk(ast.parse(path.read_text(), str(path)))
                if isinstance(node, (ast.Import, ast.ImportFrom))
                for target in _reached(module, path, node)]
    assert not reaching, "\n".join(reaching)


@pytest.mark.parametrize("statement, reaches", [
    ("from mbcontrol.analysis.envelope import envelope_bound", ["mbcontrol.analysis.envelope"]),
    ("from mbcontrol.analysis import envelope_bound", []),
    ("from mbcontrol.sim import integrators", ["mbcontrol.sim.integrators"]),
    ("from mbcontrol.sim import simulate", []),           # the face binds the function
    ("import mbcontrol.hydro.fit.ssforms", ["mbcontrol.hydro.fit.ssforms"]),
    ("from ...errors import InputError", []),              # a one-file common module
    ("from .process import ProcessPlant", []),             # inside its own package
])
def test_the_face_rule_sees_reaching_imports(statement, reaches):
    module = "mbcontrol.studies.sweep.runner"
    node = ast.parse(statement).body[0]
    if statement.startswith("from ."):
        module = "mbcontrol.plant.build"
    assert _reached(module, MODULES[module], node) == reaches


MAX_FUNCTION_LINES = 80      # a function's code past its docstring; past that it is two steps
MAX_POSITIONAL = 10          # past that a call site cannot be read without the signature


def _function_sizes():
    """(where, code lines, positional parameters) of every function in the package."""
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            body = node.body
            if (len(body) > 1 and isinstance(body[0], ast.Expr)
                    and isinstance(body[0].value, ast.Constant)
                    and isinstance(body[0].value.value, str)):
                body = body[1:]
            args = node.args
            positional = [a.arg for a in args.posonlyargs + args.args if a.arg not in ("self", "cls")]
            yield (f"{path.relative_to(ROOT)}:{node.lineno} {node.name}",
                   node.end_lineno - body[0].lineno + 1, len(positional))


def test_no_function_past_the_size_rule():
    """The module rule one level down: a function over ~80 lines of code does several things,
    and one with over ~10 positional parameters is called by position (issue 39 found one of
    107 lines and 17)."""
    long = [f"{where}: {n} lines" for where, n, _ in _function_sizes() if n > MAX_FUNCTION_LINES]
    many = [f"{where}: {p} positional parameters" for where, _, p in _function_sizes()
            if p > MAX_POSITIONAL]
    assert not long + many, "\n".join(long + many)


# Module state (issue 59): what a module-level container mutated by its functions may hold.
# A cache of pure lookups or a said-once set of messages is not state; anything else (a
# result, an object carried from one call to the next) is passed or owned by the caller.
DOCUMENTED_STATE = {
    "mbcontrol/defaults.py:_set": "the registry's set() layer, by design",
    "mbcontrol/cache.py:_usable": "cache: configured folder -> the folder this process uses",
    "mbcontrol/cache.py:_private": "cache: this process's private cache folder, made once",
    "mbcontrol/hydro/source.py:_SAID": "said-once messages",
    "mbcontrol/plant/rest.py:_SAID": "said-once messages",
    "mbcontrol/sim/compiled.py:_FAILED": "said-once messages",
    "mbcontrol/sim/compiled.py:_warned": "said-once messages",
    "mbcontrol/sim/compiled.py:_warned_cc": "said-once messages",
    "mbcontrol/sim/compiled.py:_TAGS": "cache: a compiler's version line",
    "mbcontrol/plant/provenance.py:_CACHE": "cache: an immutable plant's content hashes (weak)",
    "mbcontrol/sim/record.py:_VERSIONS": "cache: package versions",
    "mbcontrol/sim/run.py:_VERSIONS": "cache: package versions",
}
MUTATORS = {"append", "add", "update", "pop", "clear", "setdefault", "extend", "insert",
            "remove", "discard", "popitem"}


def _mutated_module_state(path: Path) -> set[str]:
    """Module-level names bound to a container (or declared global) that a function changes."""
    tree = ast.parse(path.read_text())
    names = {t.id for n in tree.body if isinstance(n, (ast.Assign, ast.AnnAssign))
             and isinstance(n.value, (ast.Dict, ast.List, ast.Set, ast.Call))
             for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
             if isinstance(t, ast.Name)}
    found = set()
    for f in ast.walk(tree):
        if not isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for n in ast.walk(f):
            if isinstance(n, ast.Global):
                found.update(n.names)
            elif (isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
                  and n.func.attr in MUTATORS and isinstance(n.func.value, ast.Name)):
                found.add(n.func.value.id)
            elif isinstance(n, (ast.Assign, ast.AugAssign, ast.Delete)):
                for t in getattr(n, "targets", None) or [n.target]:
                    if isinstance(t, ast.Subscript) and isinstance(t.value, ast.Name):
                        found.add(t.value.id)
    return {name for name in found if name in names or name.startswith("_warned")}


def test_no_module_state_carries_results_between_calls():
    """Every module-level container a function mutates is a documented cache or message set
    (DOCUMENTED_STATE); the sweep's plants live in a PlantCache the run owns."""
    found = {f"{path.relative_to(ROOT)}:{name}" for folder in ("mbcontrol", "controllers")
             for path in (ROOT / folder).rglob("*.py") for name in _mutated_module_state(path)}
    assert found - set(DOCUMENTED_STATE) == set()
    assert "mbcontrol/studies/sweep/case_run.py:_PLANTS" not in found


def test_the_state_scan_sees_a_module_cache(tmp_path):
    path = tmp_path / "m.py"
    path.write_text("_PLANTS = {}\nSAID = set()\n\ndef f(k):\n    _PLANTS[k] = 1\n"
                    "    SAID.add(k)\n")
    assert _mutated_module_state(path) == {"_PLANTS", "SAID"}


def _environment_reads(path: Path) -> list[int]:
    """Lines of `path` that read or write the process environment (os.environ, os.getenv,
    os.putenv, os.unsetenv)."""
    lines = []
    for n in ast.walk(ast.parse(path.read_text())):
        if isinstance(n, ast.Attribute) and n.attr in ("environ", "getenv", "putenv", "unsetenv") \
                and isinstance(n.value, ast.Name) and n.value.id == "os":
            lines.append(n.lineno)
        elif isinstance(n, ast.ImportFrom) and n.module == "os" and any(
                a.name in ("environ", "getenv", "putenv", "unsetenv") for a in n.names):
            lines.append(n.lineno)
    return lines


def test_no_environment_variable_is_a_switch_inside_the_library():
    """Only the defaults registry reads the environment (its documented layer, the cache
    folder's MBCONTROL_CACHE and the compiler's CC included); every switch is a default
    (`mbcontrol defaults`) or an argument."""
    found = {f"{path.relative_to(ROOT)}:{line}" for folder in ("mbcontrol", "controllers")
             for path in (ROOT / folder).rglob("*.py") if path.name != "defaults.py"
             or path.parent.name != "mbcontrol" for line in _environment_reads(path)}
    assert found == set()
    assert _environment_reads(ROOT / "mbcontrol" / "defaults.py")     # the scan sees it there


# Tests mirror the source (issue 59): tests/<package>/.../test_<module>.py tests
# mbcontrol/<package>/.../<module>.py, or the subpackage <module>/ (controllers/ for
# tests/controllers/); tests/test_<name>.py a top-level module or package of mbcontrol.
# A test of a feature across modules sits in tests/features/ (its folders mirror the package it
# mostly exercises); shared helpers sit in tests/helpers/, imported as tests.helpers.<name>.
TESTS = ROOT / "tests"
NOT_NAMED_BY_A_MODULE = {
    "tests/test_layout.py": "the repository's layout, read from every module: no one module",
    "tests/controllers/test_mpc_causal.py": "the Mpc's causal preview; named by its module once "
                                            "the Mpc split (issue 59, item 2) settles",
    "tests/controllers/test_mpc_device.py": "the Mpc on a device model; as above",
    "tests/controllers/test_mpc_parts.py": "the Mpc's settings/setup/log parts; as above",
    "tests/controllers/test_mpc_qp_fast.py": "the Mpc's fast QP path; as above",
}
NOT_A_TEST_OR_HELPER = {   # .py files under tests/ that are neither tests, conftest nor helpers
    "tests/waves/make_mhkit_reference.py": "the script that computed test_mhkit_reference.py's "
                                           "values (needs MHKiT, run by hand)",
}


def _tested_module(test: Path) -> Path | None:
    """The source a module test names, or None: tests/<a>/<b>/test_<c>.py -> mbcontrol/<a>/<b>/<c>.py
    or the subpackage mbcontrol/<a>/<b>/<c>/."""
    parts = test.relative_to(TESTS).parts
    name = parts[-1].removeprefix("test_").removesuffix(".py")
    base = ROOT / "controllers" if parts[0] == "controllers" else ROOT / "mbcontrol" / parts[0]
    folder = base.joinpath(*parts[1:-1]) if len(parts) > 1 else ROOT / "mbcontrol"
    for source in (folder / f"{name}.py", folder / name / "__init__.py"):
        if source.exists():
            return source
    return None


def test_tests_mirror_the_source():
    """Every test outside tests/features/ is named by the module (or subpackage) it tests, in
    the folder that mirrors the module's; the rest is listed above with its reason."""
    misplaced = []
    for test in sorted(TESTS.rglob("test_*.py")):
        where = str(test.relative_to(ROOT))
        if test.relative_to(TESTS).parts[0] in ("features", "helpers") \
                or where in NOT_NAMED_BY_A_MODULE:
            continue
        if _tested_module(test) is None:
            misplaced.append(where)
    assert misplaced == [], "name each by its module, or move it to tests/features/"
    stale = [name for name in NOT_NAMED_BY_A_MODULE if not (ROOT / name).exists()
             or _tested_module(ROOT / name) is not None]
    assert stale == []          # the list only shrinks: a listed test that moved leaves it


def test_helpers_are_a_package_and_no_test_touches_sys_path():
    """Shared code lives in tests/helpers/ (imported as tests.helpers.<name>); no file under
    tests/ puts a folder on sys.path (strings, such as a script a test writes, do not count)."""
    loose = [str(p.relative_to(ROOT)) for p in TESTS.rglob("*.py")
             if not p.name.startswith("test_") and p.name != "conftest.py"
             and p.relative_to(TESTS).parts[0] != "helpers"
             and str(p.relative_to(ROOT)) not in NOT_A_TEST_OR_HELPER]
    assert loose == []
    assert (TESTS / "helpers" / "__init__.py").exists()
    touching = []
    for path in TESTS.rglob("*.py"):
        for n in ast.walk(ast.parse(path.read_text())):
            if isinstance(n, ast.Attribute) and n.attr == "path" and isinstance(n.value, ast.Name) \
                    and n.value.id == "sys":
                touching.append(f"{path.relative_to(ROOT)}:{n.lineno}")
            elif isinstance(n, ast.ImportFrom) and n.module == "sys" and any(
                    a.name == "path" for a in n.names):
                touching.append(f"{path.relative_to(ROOT)}:{n.lineno}")
    assert touching == []
