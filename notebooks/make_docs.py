"""Build the documentation site (`make docs`): Sphinx, every page generated from its source.

Writes a Sphinx source tree into OUT/src and the HTML into OUT/html, warnings as errors:
- the first page (README.md) and the guide (notebooks/guide.md), figures copied in;
- the scene-key reference (`mbcontrol.scene.reference`, the parser's own account), the
  defaults (`mbcontrol.defaults`) and every command's `--help` (the real parser);
- the tutorials: the notebooks with their outputs and figures. The test suite executes each
  notebook and keeps the executed copy in out/notebooks (tests/test_notebooks.py); one newer
  than its source is used as it is, any other is executed here first;
- the API reference: first the public API, `mbcontrol.__all__` (what ``import mbcontrol as
  mbc`` gives) with each name's docstring; then autodoc of every module of mbcontrol and
  mbcontrol.controllers (numpy-style docstrings through napoleon).

Run: python notebooks/make_docs.py [--out out/docs]   (needs the [docs] extra)
"""
from __future__ import annotations

import argparse
import io
import os
import pkgutil
import re
import shutil
import sys
from contextlib import redirect_stdout
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
EXECUTED = ROOT / "out" / "notebooks"

CONF = '''project = "mbcontrol"
author = "the mbcontrol developers"
release = "{version}"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.viewcode",
              "sphinx.ext.mathjax", "myst_nb"]
source_suffix = {{".md": "myst-nb", ".ipynb": "myst-nb", ".rst": "restructuredtext"}}
nb_execution_mode = "off"          # the notebooks arrive executed (see make_docs.py)
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3
autodoc_member_order = "bysource"
autodoc_typehints = "none"
autodoc_default_options = {{"members": True, "undoc-members": False}}
napoleon_numpy_docstring = True
napoleon_google_docstring = False
html_theme = "furo"
html_title = "mbcontrol {version}"
exclude_patterns = ["_build"]
suppress_warnings = ["myst.header", "myst.xref_missing"]

import sys
sys.path.insert(0, "{notebooks}")
from make_docs import setup  # noqa: E402,F401  (docstrings that are not reST: preformatted)

'''


def _plain_when_not_rst(app, what, name, obj, options, lines):
    """The house docstrings are plain text with `code`; most are valid reStructuredText, and
    those that are not (|F|, x_k, free indentation) are shown as written, preformatted."""
    import docutils.core
    import docutils.utils
    text = "\n".join(lines)
    try:
        docutils.core.publish_doctree(text, settings_overrides={
            "report_level": 5, "halt_level": 2, "warning_stream": False})
    except (docutils.utils.SystemMessage, Exception):
        lines[:] = ["::", ""] + ["    " + line for line in text.splitlines()] + [""]


def _plain_source_pages(app, pagename, templatename, context, doctree):
    """viewcode's highlighted-source pages without the theme's whole navigation tree: furo
    renders it for each page, and over the 160 module pages that was half the build (64 s
    against 30 s); their sidebar keeps the search box and the link home."""
    if pagename.startswith("_modules/"):
        context.pop("toctree", None)


def setup(app):
    app.connect("autodoc-process-docstring", _plain_when_not_rst, priority=600)
    app.connect("html-page-context", _plain_source_pages, priority=400)   # before furo's (500)


INDEX = '''# mbcontrol

Control design for multibody marine systems, wave-energy converters first: scene files, BEM
hydrodynamics, a symbolic process plant, exact linearisation, compiled simulation with
measured accuracy, controllers with their bounds, identification and sweeps.

```{{toctree}}
:maxdepth: 2
:caption: Guide

start
guide
scene_keys
defaults
cli
```

```{{toctree}}
:maxdepth: 1
:caption: Tutorials

{tutorials}
```

```{{toctree}}
:maxdepth: 1
:caption: API reference

{api}
```
'''


def guide(src: Path) -> None:
    """README.md as the first page, notebooks/guide.md as the guide, their figures copied in."""
    figures = src / "figures"
    figures.mkdir(exist_ok=True)
    for png in (NOTEBOOKS / "figures").glob("*.png"):
        shutil.copy2(png, figures / png.name)
    start = (ROOT / "README.md").read_text().replace("](notebooks/guide.md)", "](guide.md)")
    (src / "start.md").write_text(start.replace("](notebooks/figures/", "](figures/"))
    text = (NOTEBOOKS / "guide.md").read_text().replace("](../README.md)", "](start.md)")
    (src / "guide.md").write_text(text)


def scene_keys(src: Path) -> None:
    from mbcontrol.scene import reference
    (src / "scene_keys.md").write_text(
        "# Scene keys\n\nWhat a scene file (TOML) may hold, section by section, generated from "
        "the parser (`mbcontrol.scene.reference`). Numbers are SI unless given as a unit string "
        "(\"25 mm\", \"5 deg\", \"2 MN\").\n\n" + reference.markdown())


def defaults_page(src: Path) -> None:
    from mbcontrol import defaults
    rows = ["| key | built-in value | unit | environment variable | meaning |",
            "|---|---|---|---|---|"]
    for row in defaults.table():
        rows.append(f"| `{row['key']}` | `{row['value']}` | {row['unit']} | `{row['env']}` | "
                    f"{row['doc']} |")
    (src / "defaults.md").write_text(
        "# Defaults\n\n" + (defaults.__doc__ or "").split("\n\n", 1)[1].replace(
            "``", "`") + "\n\n" + "\n".join(rows) + "\n")


def cli_page(src: Path) -> None:
    """Each command's --help, from the parser itself."""
    from mbcontrol.cli import build_parser
    parser = build_parser()
    parts = ["# Command line\n", "```text\n" + parser.format_help() + "```\n"]
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, command in sub.choices.items():
        parts += [f"## mbcontrol {name}\n", "```text\n" + command.format_help() + "```\n"]
    (src / "cli.md").write_text("\n".join(parts))


def api(src: Path) -> list[str]:
    """The API reference: the public API first (`public_api`), then one page per package of
    mbcontrol (and the controllers), automodule per module."""
    import mbcontrol
    import mbcontrol.controllers
    folder = src / "api"
    folder.mkdir(exist_ok=True)
    (folder / "public.rst").write_text("\n".join(public_api()))
    groups: dict[str, list[str]] = {}
    packages = set()
    for package in (mbcontrol, mbcontrol.controllers):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if info.name.endswith("__main__") or ".models." in info.name + ".":
                continue
            if info.ispkg:
                packages.add(info.name)
            parts = info.name.split(".")
            group = ".".join(parts[:2]) if len(parts) > 2 or info.ispkg else "mbcontrol"
            groups.setdefault(group, []).append(info.name)
    pages = ["api/public"]
    for group, modules in sorted(groups.items()):
        title = group if group != "mbcontrol" else "mbcontrol (top-level modules)"
        lines = [title, "=" * len(title), ""]
        if group != "mbcontrol":            # a package: its docstring; members on their pages
            lines += [f".. automodule:: {group}", "   :no-members:", ""]
        for module in sorted(set(modules) - {group}):
            lines += [module, "-" * len(module), "", f".. automodule:: {module}"]
            lines += ["   :no-members:", ""] if module in packages else [""]
        (folder / f"{group}.rst").write_text("\n".join(lines))
        pages.append(f"api/{group}")
    return pages


# the order a user learns in: the tour first
TUTORIALS = ("tour_hinged_barge", "controllers_sphere", "electrical_sphere", "power_matrix",
             "work_precision_rm3", "identification_flume", "export_fmu", "farm_layouts",
             "codesign")
# a warning as Python prints it: "/path/to/module.py:123: SomeWarning: message", then the
# source line that warned, indented
_WARNING = re.compile(r"^\S*?([\w.]+\.py):\d+: (\w+(?:Warning|Error)): ")


def tidy(nb):
    """A tutorial as a reader should see it: results, not logs. Status lines ("mbcontrol:
    compiling ..."), progress bars, tqdm's own warnings and the source lines warnings echo are
    dropped; a warning keeps its category and message, once per notebook, without the build
    machine's paths; the checkout's path is left out of any output (paths relative to the
    repository)."""
    root = str(ROOT) + "/"
    seen: set = set()
    for cell in nb.cells:
        if cell.get("cell_type") != "code":
            continue
        kept = []
        for out in cell.get("outputs", []):
            if out.get("output_type") == "stream" and out.get("name") == "stderr":
                out["text"] = _tidy_stderr(out["text"], seen)
                if not out["text"].strip():
                    continue
            for key in ("text",):
                if isinstance(out.get(key), str):
                    out[key] = out[key].replace(root, "")
            for mime, value in (out.get("data") or {}).items():
                if mime.startswith("text/") and isinstance(value, str):
                    out["data"][mime] = value.replace(root, "")
            kept.append(out)
        cell["outputs"] = kept
    return nb


def _tidy_stderr(text: str, seen: set) -> str:
    lines, skip_source = [], False
    for line in text.replace("\r", "\n").splitlines():
        if skip_source and line.startswith("  "):
            skip_source = False
            continue
        skip_source = False
        if line.startswith("mbcontrol: ") or "█" in line or re.search(r"\d+/\d+ \[", line):
            continue                               # a status line or a progress bar
        match = _WARNING.match(line)
        if match:
            line, skip_source = f"{match.group(2)}: {line[match.end():]}", True
            if match.group(2) == "TqdmWarning" or line in seen:
                continue                           # the kernel's widgets; said once already
            seen.add(line)
        if line.strip():
            lines.append(line)
    return "\n".join(lines) + ("\n" if lines else "")


def public_api() -> list[str]:
    """The first page of the API reference: the curated public API, `mbcontrol.__all__` in its
    order (what ``import mbcontrol as mbc`` gives), each name with its docstring; the
    submodules' pages follow it."""
    import inspect

    import mbcontrol
    title = "The public API: import mbcontrol as mbc"
    lines = [title, "=" * len(title), "", ".. automodule:: mbcontrol", "   :no-members:",
             "   :no-index:", ""]
    for name in mbcontrol.__all__:
        value = getattr(mbcontrol, name)
        if inspect.ismodule(value):
            heading = f"mbcontrol.{name} (module)"
            lines += [heading, "-" * len(heading), "", f".. automodule:: {value.__name__}",
                      "   :no-members:", "   :no-index:", ""]
            continue
        kind = "autoclass" if inspect.isclass(value) else "autofunction"
        lines += [f"mbcontrol.{name}", "-" * len(f"mbcontrol.{name}"), "",
                  f".. {kind}:: mbcontrol.{name}", "   :no-index:", ""]
    return lines


def tutorials(src: Path) -> list[str]:
    """The notebooks, executed: the test suite's copies when newer than the source, else run
    here (nbclient, as the tests do); tidied (`tidy`), in TUTORIALS' order."""
    import nbformat
    from nbclient import NotebookClient
    folder = src / "tutorials"
    folder.mkdir(exist_ok=True)
    pages = []
    order = {name: k for k, name in enumerate(TUTORIALS)}
    for path in sorted(NOTEBOOKS.glob("*.ipynb"), key=lambda p: (order.get(p.stem, 99), p.stem)):
        done = EXECUTED / path.name
        if done.exists() and done.stat().st_mtime >= path.stat().st_mtime:
            nb = nbformat.read(done, as_version=4)
        else:
            print(f"[docs] executing {path.name} (no executed copy from the tests)", flush=True)
            os.environ["MBCONTROL_QUIET"] = "1"        # no status lines or bars in a tutorial
            nb = nbformat.read(path, as_version=4)
            NotebookClient(nb, timeout=900, kernel_name="python3",
                           resources={"metadata": {"path": str(NOTEBOOKS)}}).execute()
        nbformat.write(tidy(nb), folder / path.name)
        pages.append(f"tutorials/{path.stem}")
    return pages


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(ROOT / "out" / "docs"),
                        help="folder for src/ and html/ (default out/docs)")
    args = parser.parse_args(argv)
    from sphinx.cmd.build import build_main

    import mbcontrol
    out = Path(args.out)
    src = out / "src"
    shutil.rmtree(src, ignore_errors=True)
    src.mkdir(parents=True)
    version = re.sub(r"[^\w.+-]", "", getattr(mbcontrol, "__version__", "") or "0")
    (src / "conf.py").write_text(CONF.format(version=version, notebooks=NOTEBOOKS))
    guide(src)
    scene_keys(src)
    defaults_page(src)
    cli_page(src)
    api_pages = api(src)
    tutorial_pages = tutorials(src)
    (src / "index.md").write_text(INDEX.format(tutorials="\n".join(tutorial_pages),
                                               api="\n".join(api_pages)))
    log = io.StringIO()
    with redirect_stdout(log):
        status = build_main(["-W", "--keep-going", "-q", "-b", "html", str(src),
                             str(out / "html")])
    print(log.getvalue(), end="")
    if status:
        print("[docs] failed: Sphinx reported warnings or errors (above)", file=sys.stderr)
        return status
    print(f"[docs] {out / 'html' / 'index.html'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
