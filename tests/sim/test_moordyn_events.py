"""A line that reaches its breaking load or the sea bed is reported with time and line
(mbcontrol.sim.moordyn_events): the moored sphere (moordyn/sphere_moored.toml) with a second
mooring, a tether from a pile 40 m down (moordyn/tether_lines.txt), whose breaking load is below
its pull at rest.

References: the tether's geometry (its lowest point is the pile's end, 10 m above the 50 m
bed: it rises from there to the sphere); the chains lie on the bed (34 m each, the elastic
catenary of tests/features/sim/test_moordyn.py).
"""
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mbcontrol import sim
from mbcontrol.plant import build_plant
from mbcontrol.sim.moordyn_events import BED_EVERY_STEPS, LineEvents

pytest.importorskip("moordyn")
HERE = Path(__file__).with_name("moordyn")


@pytest.fixture(scope="module")
def tethered(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tether")
    text = (HERE / "sphere_moored.toml").read_text()
    text = text.replace('"../../../../shared', f'"{HERE.parents[3]}/shared').replace(
        '"../../../', f'"{HERE.parents[2]}/').replace(
        'file = "sphere_lines.txt"', f'file = "{HERE / "sphere_lines.txt"}"')
    text += (f'\n[[mooring]]\nname = "tether"\ntype = "moordyn"\n'
             f'file = "{HERE / "tether_lines.txt"}"\nbody = "sphere"\nbreaking_load = 1000.0\n')
    (folder / "tethered.toml").write_text(text)
    return build_plant(str(folder / "tethered.toml"))


def test_a_line_at_its_breaking_load_is_reported_once_with_time_and_end(tethered):
    with pytest.warns(RuntimeWarning, match=r"mooring 'tether': line 1 reached its breaking load "
                                            r"1000 N at its fairlead at t = 0.01 s"):
        ds = sim.simulate(tethered, None, duration=2.0, dt=0.01)
    events = ds.attrs["moordyn_events"]
    assert set(events) == {"tether"}                     # the chains have no breaking load
    reached = events["tether"]["line1"]
    assert reached["breaking_load_at_s"] == pytest.approx(0.01) and reached["end"] == "fairlead"
    tension = ds["tether__line1__fairlead_tension"].values
    assert reached["tension_N"] == pytest.approx(tension[1], rel=1e-12)
    assert tension.min() > 1000.0                        # it stays over it: reported once
    # in the summary, JSON-ready, and among its warnings
    from mbcontrol.analysis import summary
    said = json.loads(json.dumps(summary(ds, tethered)))
    assert said["mooring_events"] == json.loads(json.dumps(events))
    assert any("'tether' line1 reached its breaking load at its fairlead at t = 0.01 s" in w
               for w in said["validity_warnings"])


def test_bed_clearance_is_the_lines_lowest_node_above_the_bed(tethered):
    from mbcontrol.sim.moordyn_run import MooredRun
    moored = MooredRun(tethered, tethered.x0())
    try:
        chains, tether = moored.systems
        # the chains lie on the bed (MoorDyn's bed pushes back as nodes sink in: mm)
        assert all(abs(chains.bed_clearance(j)) < 0.05 for j in range(3))
        assert tether.bed_clearance(0) == pytest.approx(10.0, abs=1e-6)   # the pile's end
        events = LineEvents(tethered, moored)
        assert [(s.name, j) for s, j in events.clear] == [("tether", 0)]  # watched: clear of it
    finally:
        moored.close()


def test_a_line_reaching_the_bed_is_reported_once():
    """The bed check itself, on a stand-in system whose line falls 4 m per check."""
    heights = iter([3.0, 3.0, -1.0, -5.0])              # at the start, then per check
    line = SimpleNamespace(id=7)
    system = SimpleNamespace(name="m", lines=[object()], data=SimpleNamespace(lines=[line]),
                             bed_clearance=lambda j: next(heights))
    plant = SimpleNamespace(scene=SimpleNamespace(moorings=[SimpleNamespace(
        name="m", breaking_load=None)]))
    events = LineEvents(plant, SimpleNamespace(systems=[system]))
    tensions = np.zeros(2)
    for i in range(1, 4 * BED_EVERY_STEPS + 1):
        events.after_step(i, 0.01 * i, tensions)          # checks at 10, 20, 30 (then done)
    assert events.record == {"m": {"line7": {"bed_contact_at_s": pytest.approx(0.2)}}}
