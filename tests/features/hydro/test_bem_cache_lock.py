"""Two processes asking for one BEM solve on a cold cache (two test workers, two sweep workers)
solve it once: the second waits on the entry's lock (mbcontrol.cache.exclusive) and loads the
first's file. Without the lock both solve (checked: 2 solves)."""
import os
import subprocess
import sys

CODE = """
import sys, numpy as np
from mbcontrol.hydro import BemBody
from mbcontrol.hydro.bem import solve as bem
real = bem._solve_bem
def counted(*args, **kwargs):
    print("solved", flush=True)
    return real(*args, **kwargs)
bem._solve_bem = counted
body = BemBody(name="hemi", geometry={"type": "sphere", "radius": 1.0, "center": [0, 0, 0]},
               cog=(0, 0, 0), mass=2094.4, panel_size=0.25, dofs=("Heave",))
ds = bem.compute([body], rho=1000.0, g=9.81, depth=np.inf, omegas=np.linspace(0.5, 3.0, 6),
                 cache_dir=sys.argv[1], progress=False)
print("damping", float(ds["radiation_damping"].values.sum()))
"""


def test_two_processes_needing_the_same_solve_solve_it_once(tmp_path):
    runs = [subprocess.Popen([sys.executable, "-c", CODE, str(tmp_path)], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, env=dict(os.environ))
            for _ in range(2)]
    outputs = [r.communicate(timeout=300)[0] for r in runs]
    assert all(r.returncode == 0 for r in runs), outputs
    assert sum(out.count("solved") for out in outputs) == 1, outputs
    values = {line for out in outputs for line in out.splitlines() if line.startswith("damping")}
    assert len(values) == 1, outputs                 # both read the one dataset
    assert len(list(tmp_path.glob("bem_*.nc"))) == 1
