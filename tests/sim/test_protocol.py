"""The Controller protocol (mbcontrol.sim.protocol) declares everything the simulator and the
exporters use of a controller: a user's controller with only the required members runs, and
no module reads an undeclared member behind the protocol's back."""
import re
from pathlib import Path

import numpy as np

from mbcontrol import waves
from mbcontrol.plant import build_plant
from mbcontrol.sim import CONTROLLER_OPTIONAL, Controller, simulate
from mbcontrol.sim.protocol import estimation_report, parametric_law, period_of, uses_state

ROOT = Path(__file__).resolve().parents[2]


class Damper:
    """A user's controller: the required members only (no optional ones)."""
    name, period = "user damper", 0.1

    def reset(self, plant):
        self.index = plant.outputs.index("pto__velocity")

    def __call__(self, t, y):
        return np.array([-2e5 * y[self.index]])

    def casadi_law(self, plant):
        return None

    def describe(self):
        return {"name": self.name, "damping": 2e5}


def test_a_controller_with_the_required_members_only_runs():
    c = Damper()
    assert isinstance(c, Controller)
    assert not uses_state(c) and estimation_report(c) is None and parametric_law(c) is None
    assert period_of(c) == 0.1 and period_of(None) is None
    plant = build_plant("sphere")
    ds = simulate(plant, waves.regular(1.0, 8.0, ramp_time=8.0), duration=16.0, dt=0.05,
                  controller=c)
    force, velocity = ds["pto__force"].values, ds["pto__velocity"].values
    # the held damper: each 0.1 s the force is -c times the velocity sampled then
    held = np.abs(force[::2][1:-1] + 2e5 * velocity[::2][1:-1])
    assert held.max() <= 1e-9 * np.abs(force).max()
    assert ds.attrs["controller"] == c.describe()


def test_no_module_reads_an_undeclared_controller_member():
    """getattr(controller, "member", ...) only in the protocol module, for declared members."""
    reads = {}
    for path in [*(ROOT / "mbcontrol").rglob("*.py"), *(ROOT / "controllers").rglob("*.py")]:
        for member in re.findall(r'getattr\(controller, "(\w+)"', path.read_text()):
            reads.setdefault(member, set()).add(path.relative_to(ROOT).as_posix())
    outside = {m: sorted(p - {"mbcontrol/sim/protocol.py"}) for m, p in reads.items()
               if p - {"mbcontrol/sim/protocol.py"}}
    assert not outside, f"controller members read outside mbcontrol.sim.protocol: {outside}"
    assert set(reads) <= set(CONTROLLER_OPTIONAL) | {"period", "name"}
