"""A quick answer needs none of the heavy libraries: `mbcontrol --help`, `--version` and
`models` run in a fresh process without importing CasADi, xarray, pandas, python-control,
Capytaine or Dask (the package faces of sim and controllers load what they export on first
use). Their times are measured in `benchmarks/startup.py` (make bench), not here.

`simulate ... --json` imports only what a run needs: no plotting, BEM solver, python-control,
spline or site-file code (the faces of analysis, waves, hydro and hydro.readers are lazy too),
and its faces still give every name they export."""
import importlib
import json
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


# What the simulate path leaves out. xarray, pandas and dask it still imports: the hydro data
# (HydroModel.data) and the run's record are xarray Datasets, and any xarray Dataset imports
# dask when dask is installed (xarray's duck-array check); see benchmarks/startup.py.
NOT_ON_SIMULATE = ("matplotlib", "capytaine", "control", "scipy.interpolate",
                   "mbcontrol.waves.sites", "mbcontrol.analysis.bounds",
                   "mbcontrol.hydro.bem.solve", "mbcontrol.hydro.readers.wamit")
SIMULATE = ["simulate", "sphere", "--wave", "jonswap", "--hs", "2", "--tp", "8",
            "--duration", "600", "--json"]


def test_simulate_imports_only_what_a_run_needs():
    probe = (f"import sys\nfrom mbcontrol.cli import main\nstatus = main({SIMULATE!r})\n"
             f"print('STATUS', status, *[m for m in {NOT_ON_SIMULATE!r} if m in sys.modules], "
             f"file=sys.stderr)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip().splitlines()[-1] == "STATUS 0"
    result = json.loads(done.stdout)            # the run itself, not only its imports
    assert result["model"] == "sphere" and result["valid"]
    assert result["ptos"]["pto"]["mean_power_W"] > 0


def test_the_lazy_faces_still_give_every_name():
    """Each name a face exports resolves to the object its module defines (imported here
    directly, the reference), and a name shared with a submodule is the function."""
    import mbcontrol.analysis as analysis
    import mbcontrol.controllers as controllers
    import mbcontrol.hydro as hydro
    import mbcontrol.hydro.readers as readers
    import mbcontrol.sim as sim
    import mbcontrol.waves as waves
    for face in (sim, controllers):
        for name in getattr(face, "__all__", face._WHERE):
            assert getattr(face, name) is not None, (face.__name__, name)
    for face in (analysis, waves, hydro, readers):
        for name, (module, attr) in face._WHERE.items():
            defined = getattr(importlib.import_module(f"{face.__name__}.{module}"), attr)
            assert getattr(face, name) is defined, (face.__name__, name)
        assert set(face.__all__) <= set(dir(face)), face.__name__
    assert analysis.linearize.__module__ == "mbcontrol.analysis.linearize"    # not the module
    assert analysis.summary.__module__ == "mbcontrol.analysis.summary"
    assert waves.spreading_from_settings is importlib.import_module(
        "mbcontrol.waves.spreading").from_settings
    assert sim.simulate.__module__ == "mbcontrol.sim.run"          # the function, not a module
    assert controllers.REGISTRY["mpc"] is controllers.Mpc
    assert list(controllers.REGISTRY) == ["passive", "reactive", "latching", "declutching",
                                          "mpc", "nmpc"]
