"""A static law's gains as parameters of the compiled closed loop (sim.integrators
law_parameters): the same numbers as the law with its gains as constants (to round-off: with
constants CasADi folds the sign into the gain; measured 4.4e-16 of the signal), and one
compile for any number of gain values, e.g. a sweep that designs its controller per sea."""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers import make
from mbcontrol.plant import build_plant
from mbcontrol.sim import integrators, simulate


@pytest.fixture(scope="module")
def sphere():
    return build_plant("sphere")


class _ConstantGains:
    """The controller with only its plain casadi_law (gains as constants), as before."""

    def __init__(self, inner):
        self.inner = inner
        self.name, self.period = inner.name, inner.period

    def reset(self, plant):
        self.inner.reset(plant)

    def __call__(self, t, y):
        return self.inner(t, y)

    def casadi_law(self, plant):
        return self.inner.casadi_law(plant)

    def describe(self):
        return self.inner.describe()


@pytest.mark.parametrize("name, settings", [
    ("passive", {"damping": 3e5}),
    ("reactive", {"damping": 2e5, "stiffness": -3e5, "force_max": 1.2e6})])
def test_parametric_gains_give_the_same_run(sphere, name, settings):
    sea = waves.irregular(2.0, 8.0, seed=1, duration=100.0, band=(0.5, 3.0))
    runs = [simulate(sphere, sea, duration=100.0, dt=0.05, controller=c)
            for c in (make(name, **settings), _ConstantGains(make(name, **settings)))]
    for key in ("pto__position", "pto__force"):
        a, b = runs[0][key].values, runs[1][key].values
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(b))


def test_new_gains_do_not_compile_anew(sphere, monkeypatch):
    """Three reactive laws, one compiled closed loop; with the gains as constants each law
    was a new structure (rm3: 0.7 s of compiling per sea in a designed sweep)."""
    calls = []
    original = integrators.compile_function

    def counting(fun, *args, **kwargs):
        if fun.name() == "chunk":              # the closed loop (not the output map)
            calls.append(fun.name())
        return original(fun, *args, **kwargs)
    monkeypatch.setattr(integrators, "compile_function", counting)
    plant = build_plant("sphere")                # a plant of its own: nothing cached for it
    sea = waves.irregular(1.5, 9.0, seed=0, duration=60.0, band=(0.5, 3.0))
    for c, k in ((1e5, -2e5), (3e5, 0.0), (6e5, 4e5)):
        simulate(plant, sea, duration=60.0, dt=0.05,
                 controller=make("reactive", damping=c, stiffness=k))
    # and the passive law is the reactive law's form: the demo compiled the same 165 kB
    # chunk three times (no law, passive, reactive), next to "each structure compiles once"
    for c in (1e5, 7e5):
        simulate(plant, sea, duration=60.0, dt=0.05, controller=make("passive", damping=c))
    assert calls == ["chunk"]
    calls.clear()
    for c, k in ((1e5, -2e5), (3e5, 0.0)):
        simulate(plant, sea, duration=60.0, dt=0.05,
                 controller=_ConstantGains(make("reactive", damping=c, stiffness=k)))
    assert calls == ["chunk", "chunk"]           # the old way: one compile per gain pair
