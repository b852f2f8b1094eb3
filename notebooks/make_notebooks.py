"""Write the example notebooks from the cells below (keeps them reviewable as Python).

Run: python notebooks/make_notebooks.py   (tests execute the .ipynb files top to bottom)
"""
from pathlib import Path

import nbformat

TOUR = [
    ("md", "# Tour: the seed's hinged barge\n\nScene file → BEM data in body frames → "
           "radiation state-space model → nonlinear process plant → linear control plant → "
           "closed loop. Every number below is computed when the notebook runs."),
    ("code", "import numpy as np\nfrom mbcontrol import waves\nfrom mbcontrol.scene import "
             "load_scene\nfrom mbcontrol.plant import build_plant\nfrom mbcontrol.linearize "
             "import linearize\nfrom mbcontrol.simulate import simulate\nfrom "
             "mbcontrol.analysis import frequency_domain_response, statespace_response\n"
             "from mbcontrol.controllers import make"),
    ("md", "## The scene\nTwo 0.6 m barges: barge 1 pivots on a fixed post, barge 2 is hinged "
           "to it with a PTO damper (`models/hinged_barge.toml`)."),
    ("code", "scene = load_scene('hinged_barge')\n[(j.name, j.type, j.parent, j.child, j.point)"
             " for j in scene.joints]"),
    ("md", "## The process plant\nStates are the joint angles and rates plus the radiation "
           "states; the hydro DOFs are only those the joints can move."),
    ("code", "plant = build_plant(scene)\nprint(plant.states[:4], '+', plant.nx - 4, "
             "'radiation states')\nprint('hydro DOFs:', plant.hydro.dofs)\nprint('radiation fit "
             "error: %.2f %%' % (100 * plant.hydro.radiation.fit_error))"),
    ("md", "## Linear control plant\nExact Jacobians at rest into a named python-control "
           "`StateSpace`. Coulomb friction is left out of the linear model (its smoothed slope "
           "at zero velocity is not a useful linear damping)."),
    ("code", "sys = linearize(plant, params={'hinge_friction__coulomb': 0.0})\nprint(sys.nstates,"
             " 'states; stable:', bool(np.all(np.linalg.eigvals(sys.A).real < 0)))\n"
             "omega = np.array([4.0, 6.0, 8.0, 10.0])\nfd = frequency_domain_response(plant, "
             "omega, params={'hinge_friction__coulomb': 0.0}, outputs=['hinge'])[:, 0]\n"
             "ss = statespace_response(sys, plant, omega, outputs=['hinge'])[:, 0]\n"
             "print('hinge RAO (rad/m), BEM-direct:', np.round(abs(fd), 4))\n"
             "print('hinge RAO (rad/m), state space:', np.round(abs(ss), 4))\n"
             "assert np.allclose(abs(ss), abs(fd), rtol=0.02)"),
    ("md", "## Closed loop on the nonlinear plant\nA passive damper added to the PTO, sampled "
           "every step (zero-order hold), in a regular wave."),
    ("code", "wave = waves.regular(0.02, 1.0)\nfor c in (0.0, 1.0, 3.0):\n    ds = simulate(plant,"
             " wave, duration=20.0, dt=0.005, controller=make('passive', damping=c))\n"
             "    last = ds.time > 10\n    print(f'added damping {c:3.1f} N m s/rad: mean PTO "
             "power {1e3 * float(ds.hinge_pto__power[last].mean()):.3f} mW')"),
    ("code", "import matplotlib\nmatplotlib.use('Agg')\nfrom mbcontrol.plotting import "
             "time_series\nfig = time_series(ds.sel(time=slice(10, 20)), ['eta', 'hinge', "
             "'hinge_pto__power'])"),
]


def build(cells):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell(src) if kind == "md" else
                nbformat.v4.new_code_cell(src) for kind, src in cells]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    return nb


if __name__ == "__main__":
    here = Path(__file__).parent
    nbformat.write(build(TOUR), here / "tour_hinged_barge.ipynb")
    print("wrote", here / "tour_hinged_barge.ipynb")
