"""A quick answer needs none of the heavy libraries: `mbcontrol --help`, `--version` and
`models` run in a fresh process without importing CasADi, xarray, pandas, python-control,
Capytaine or Dask (the package faces of sim and controllers load what they export on first
use). Their times are measured in `benchmarks/startup.py` (make bench), not here."""
import subprocess
import sys

import pytest

HEAVY = ("casadi", "xarray", "pandas", "control", "capytaine", "dask")


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["models"], ["simulate", "--help"]])
def test_a_quick_answer_imports_no_heavy_library(argv):
    probe = (f"import sys\nfrom mbcontrol.cli import main\ntry:\n    main({argv!r})\n"
             f"except SystemExit:\n    pass\n"
             f"print('HEAVY', *[m for m in {HEAVY!r} if m in sys.modules], file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip().splitlines()[-1] == "HEAVY"


def test_the_lazy_faces_still_give_every_name():
    """Each name a face exports resolves to the object its module defines."""
    import mbcontrol.controllers as controllers
    import mbcontrol.sim as sim
    for face in (sim, controllers):
        for name in getattr(face, "__all__", face._WHERE):
            assert getattr(face, name) is not None, (face.__name__, name)
    assert sim.simulate.__module__ == "mbcontrol.sim.run"          # the function, not a module
    assert controllers.REGISTRY["mpc"] is controllers.Mpc
    assert list(controllers.REGISTRY) == ["passive", "reactive", "latching", "declutching",
                                          "mpc", "nmpc"]
