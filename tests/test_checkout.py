"""From a checkout, not installed (issue 59): run from the repository's root, `mbcontrol`
finds its laws and catalogue beside it (controllers/, models/) as `mbcontrol.controllers` and
`mbcontrol.models`, and the models/ scripts find the package. The editable install's finder
is taken out of the child interpreter, so only the checkout can serve these imports."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NO_INSTALL = ("import sys\n"
              "sys.meta_path[:] = [f for f in sys.meta_path if 'editable' not in repr(f)]\n"
              "for name in [m for m in sys.modules if m.split('.')[0] == 'mbcontrol']:\n"
              "    del sys.modules[name]\n")


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", NO_INSTALL + code], cwd=ROOT, text=True,
                          capture_output=True, timeout=300)


def test_the_laws_and_the_catalogue_import_from_a_checkout():
    done = _run("import mbcontrol, mbcontrol.controllers as c, mbcontrol.models as m\n"
                "print(mbcontrol.__file__, c.__file__, m.__file__, 'reactive' in c.REGISTRY)\n"
                "print(mbcontrol.load_scene('sphere').path)\n")
    assert done.returncode == 0, done.stderr
    files, scene = done.stdout.splitlines()
    assert files.split() == [str(ROOT / "mbcontrol" / "__init__.py"),
                             str(ROOT / "controllers" / "__init__.py"),
                             str(ROOT / "models" / "__init__.py"), "True"]
    assert scene == str(ROOT / "models" / "sphere.toml")


def test_without_the_checkout_finder_the_laws_are_missing():
    """The check above can fail: with the finder removed too, nothing serves the names."""
    done = _run("import mbcontrol, sys\n"
                "sys.meta_path[:] = [f for f in sys.meta_path if '_Beside' not in repr(f)]\n"
                "import mbcontrol.controllers\n")
    assert done.returncode != 0 and "No module named 'mbcontrol.controllers'" in done.stderr


def test_a_models_script_finds_the_package():
    """Run as `python models/generate_hydro.py` (its folder first on sys.path, as Python
    puts it): the package it then imports is the checkout's."""
    script = ROOT / "models" / "generate_hydro.py"
    done = _run("import runpy\n"
                f"sys.path[0] = {str(script.parent)!r}\n"
                f"sys.argv = [{str(script)!r}, '--help']\n"
                "try:\n"
                f"    runpy.run_path({str(script)!r}, run_name='__main__')\n"
                "except SystemExit:\n"
                "    pass\n"
                "import mbcontrol.hydro\n"
                "print(mbcontrol.hydro.__file__)\n")
    assert done.returncode == 0, done.stderr
    assert "--ship-fits" in done.stdout
    assert done.stdout.splitlines()[-1] == str(ROOT / "mbcontrol" / "hydro" / "__init__.py")
