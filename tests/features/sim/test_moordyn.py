"""MoorDyn moorings coupled to the plant (mbcontrol.sim.moordyn_run, moordyn_system,
mbcontrol.plant.moordyn_loads, mbcontrol.scene.moordyn_file), on the catalogue sphere held by
three catenary chains (moordyn/sphere_moored.toml, moordyn/sphere_lines.txt).

References, independent of the code under test:
- MoorDyn run alone (its own Python API, no mbcontrol code in the loop) with the same motion
  of the fairleads, computed here from the recorded heave in MoorDyn's frame by hand: the
  coupled run's tensions must be MoorDyn's to round-off;
- the elastic catenary with seabed contact (mbcontrol.plant.solve_catenary, itself checked
  against MoorPy to 1e-9 in tests/plant/test_catenary.py) for the static fairlead tension;
- hydrostatics: the lines' vertical pull sinks the sphere until rho g pi R^2 dz balances it;
- MoorDyn's v2 reading of the same system written in its v1 format (WEC-Sim's examples).
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from mbcontrol import sim, waves
from mbcontrol.errors import InputError, SceneError, SimulationError
from mbcontrol.plant import build_plant, solve_catenary
from mbcontrol.scene import TO_MOORDYN
from mbcontrol.scene.moordyn_file import read_moordyn, run_text

moordyn = pytest.importorskip("moordyn")

HERE = Path(__file__).resolve().parents[2] / "sim" / "moordyn"
SCENE, LINES = HERE / "sphere_moored.toml", HERE / "sphere_lines.txt"
RHO_LINES, G_LINES = 1025.0, 9.80665          # the file's water, MoorDyn's gravity
DIAMETER, MASS_PER_M, EA, LENGTH = 0.08, 40.0, 3.0e8, 160.0
FAIRLEAD_Z, ANCHOR, DEPTH = -5.0, np.array([150.0, 0.0, -50.0]), 50.0   # MoorDyn frame, m


def _variant(tmp_path, *edits, settle: bool = True) -> str:
    """The moored sphere's scene and lines in tmp_path, the lines file edited: its path."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    scene = tmp_path / SCENE.name
    scene.write_text(SCENE.read_text().replace('"../../../../shared', f'"{HERE.parents[3]}/shared')
                     .replace('"../../../', f'"{HERE.parents[2]}/')
                     + ("" if settle else "settle = false\n"))
    text = LINES.read_text()
    for old, new in edits:
        assert old in text
        text = text.replace(old, new)
    (tmp_path / LINES.name).write_text(text)
    return str(scene)


@pytest.fixture(scope="module")
def plant():
    return build_plant(str(SCENE))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """40 s in waves from MoorDyn's own initial condition (settle = false), so that MoorDyn
    alone, started the same way, must give the same tensions."""
    plant = build_plant(_variant(tmp_path_factory.mktemp("unsettled"), settle=False))
    sea = waves.irregular(1.5, 8.0, seed=2, duration=40.0)
    return sim.simulate(plant, sea, duration=40.0, dt=0.01)


def _submerged_weight() -> float:
    return (MASS_PER_M - RHO_LINES * math.pi * DIAMETER ** 2 / 4) * G_LINES


def test_the_static_tensions_are_the_elastic_catenarys(tmp_path):
    """At rest, 40 segments a line (MoorDyn alone: 10 segments 3.1 % low, 40 0.6 %, 80 0.3 %
    at the fairlead; the lumped masses' discretisation). The lines alone, settled with the
    sphere held at its scene pose: a plant of them would spend a minute on their stiffness."""
    from mbcontrol.plant import MoorDynSystem
    from mbcontrol.scene import load_scene
    scene = load_scene(_variant(tmp_path, ("160.0     10", "160.0     40"),
                                ("0.002         dtM", "0.0005         dtM")))   # 4 m segments
    fairleads = np.array([p.position for p in read_moordyn(LINES).coupled]).T \
        * TO_MOORDYN[:, None] + np.array(scene.body("sphere").cog)[:, None]
    system = MoorDynSystem(scene, scene.moorings[0], fairleads, np.zeros_like(fairleads))
    tensions = system.tensions()                       # (anchor, fairlead) x line
    system.close()
    XF, ZF = ANCHOR[0] - 1.0, FAIRLEAD_Z - ANCHOR[2]           # line 1: fairlead at x = 1 m
    exact = solve_catenary(XF, ZF, LENGTH, EA, _submerged_weight())
    for k in range(3):                                         # the three lines are alike
        assert tensions[1, k] == pytest.approx(math.hypot(exact.H, exact.V), rel=0.01)
        # 34 m of each line lies on the bed: the anchor sees H alone; measured 0.03 %
        assert tensions[0, k] == pytest.approx(exact.H_anchor, rel=0.005)


def test_the_coupled_run_feeds_moordyn_the_spheres_motion(run, tmp_path):
    """MoorDyn alone, stepped with fairleads that move with the recorded heave (NED, down):
    in MoorDyn's frame z = FAIRLEAD_Z - heave. Its tensions must be the coupled run's."""
    data = read_moordyn(LINES)
    rest = np.array([p.position for p in data.coupled]) + [0.0, 0.0, -2.0]   # CoG 2 m down
    (tmp_path / "lines.txt").write_text(run_text(data, rest, {}))
    system = moordyn.Create(str(tmp_path / "lines.txt"))
    heave, velocity = run["heave"].values, run["heave__vel"].values
    t, dt = run["time"].values, float(run.attrs["dt_s"])
    down = np.tile([0.0, 0.0, -1.0], 3)
    moordyn.Init(system, rest.ravel() + heave[0] * down, velocity[0] * down)
    line = moordyn.GetLine(system, 1)
    last = moordyn.GetLineNumberNodes(line) - 1
    alone = [np.linalg.norm(moordyn.GetLineNodeTen(line, last))]
    for i in range(len(t) - 1):
        moordyn.Step(system, rest.ravel() + heave[i] * down, velocity[i] * down, t[i], dt)
        alone.append(np.linalg.norm(moordyn.GetLineNodeTen(line, last)))
    moordyn.Close(system)
    coupled = run["chains__line1__fairlead_tension"].values
    assert np.ptp(coupled) > 0.05 * np.mean(coupled)           # the line does work
    np.testing.assert_allclose(coupled, alone, rtol=1e-9)
    assert run.attrs["moordyn"]["chains"]["depth_m"] == DEPTH
    assert run.attrs["moordyn"]["chains"]["source"] == "file"


def test_the_lines_pull_sink_the_sphere_by_their_weight_over_its_waterplane(plant):
    ds = sim.simulate(plant, None, duration=150.0, dt=0.02)
    pull = sum(ds[f"chains__line{k}__fairlead_tension"].values[-1] for k in (1, 2, 3))
    # the vertical part of each fairlead tension, from the catenary at the settled pose
    settled = float(ds["heave"].values[-500:].mean())
    XF, ZF = ANCHOR[0] - 1.0, FAIRLEAD_Z - settled - ANCHOR[2]
    exact = solve_catenary(XF, ZF, LENGTH, EA, _submerged_weight())
    vertical = 3 * exact.V
    stiffness = 1000.0 * 9.81 * math.pi * 5.0 ** 2                # the scene's water, R = 5 m
    # 0.17 m down: the waterplane shrinks by (dz / R)^2 = 0.1 %, the catenary is 10 lumped
    # segments (3 % low in tension, less in its vertical part); measured 0.24 %
    assert settled == pytest.approx(vertical / stiffness, rel=0.01)
    assert pull > vertical


def test_rm3s_lines_start_at_rest():
    """models/rm3_moored: MoorDyn's own relaxation stops short (its subsurface buoys leave the
    fairleads at 4 kN, 168 kN once at rest). Settled, the points' forces must stay put when
    the plate is held at its pose for 20 s; from MoorDyn's own start they grow 40x."""
    from mbcontrol.plant.process import assemble_plant
    from mbcontrol.sim.moordyn_run import MooredRun
    plant = assemble_plant("rm3_moored", radiation=False)        # no fit: only the lines run
    for settle in (True, False):
        scene = dataclasses.replace(plant.scene, moorings=tuple(
            dataclasses.replace(m, settle=settle) for m in plant.scene.moorings))
        moored = MooredRun(dataclasses.replace(plant, scene=scene), plant.x0())
        try:
            start = moored.forces(plant.x0(), 0.0, 0.0)
            later = moored.forces(plant.x0(), 0.0, 20.0)
        finally:
            moored.close()
        change = np.max(np.abs(later - start)) / np.max(np.abs(later))
        # settled: measured 0.2 %; from MoorDyn's own start the horizontal pull goes 4 -> 168 kN
        assert (change < 0.01) == settle, change


def test_a_v1_file_reads_as_the_same_system(tmp_path):
    v2 = read_moordyn(LINES)
    rows = ["v1 file", "---------------------- LINE DICTIONARY ---------------------",
            "LineType Diam MassDenInAir EA BA/-zeta Can Cat Cdn Cdt", "(-) (m) (kg/m) (N) (-) "
            "(-) (-) (-) (-)", f"chain {DIAMETER} {MASS_PER_M} {EA} -0.8 1.0 0.0 1.6 0.05",
            "---------------------- NODE PROPERTIES ---------------------",
            "Node Type X Y Z M V FX FY FZ CdA CA", "(-) (-) (m) (m) (m) (kg) (m^3) (kN) (kN) "
            "(kN) (m^2) (-)"]
    for p in v2.points:
        kind = {"coupled": "Vessel", "fixed": "Fix", "free": "Connect"}[p.kind]
        rows.append(f"{p.id} {kind} {p.position[0]} {p.position[1]} {p.position[2]} 0 0 0 0 0 0 0")
    rows += ["---------------------- LINE PROPERTIES ---------------------",
             "Line LineType UnstrLen NumSegs NodeAnch NodeFair Flags/Outputs",
             "(-) (-) (m) (-) (-) (-) (-)"]
    rows += [f"{l.id} chain {l.length} {l.segments} {l.attach_a} {l.attach_b} p" for l in v2.lines]
    rows += ["---------------------- SOLVER OPTIONS ---------------------", "0.002 dtM",
             "3.0e6 kBot", "3.0e5 cBot", "1025.0 WtrDnsty", "50 WtrDpth",
             "--------------------- need this line ------------------"]
    (tmp_path / "v1.txt").write_text("\n".join(rows) + "\n")
    v1 = read_moordyn(tmp_path / "v1.txt")
    assert v1.version == 1 and v2.version == 2
    rest = np.zeros((3, 3))
    assert run_text(v1, rest, {}).split("\n")[2:] == run_text(v2, rest, {}).split("\n")[2:]


@pytest.mark.parametrize("edit, match", [
    (("chain      4        1", "chain      9        1"), r"sphere_lines.txt:\d+: line 1: point 9"),
    (("3.0e8", "lots"), r"sphere_lines.txt:\d+: column 4 \(EA \(N\)\): expected a number"),
    (("chain      0.08", "ch;ain      0.08"), r"line type name: expected a plain word"),
    (("---------------------- LINES", "---------------------- RODS"), r"rods and failures"),
    (("1     Coupled", "1     Body1  "), r"point 1: type 'Body1'"),
])
def test_bad_files_are_refused_naming_the_file_line_and_field(tmp_path, edit, match):
    text = LINES.read_text().replace(*edit)
    assert text != LINES.read_text()
    (tmp_path / LINES.name).write_text(text)
    with pytest.raises(SceneError, match=match):
        read_moordyn(tmp_path / LINES.name)


def test_runners_that_step_the_plant_alone_refuse_it(plant):
    """Adaptive methods (MoorDyn has no Jacobian for them), and the light and batch runners,
    which step the plant without MoorDyn: they would drop the lines' forces."""
    with pytest.raises(InputError, match="fixed-step method"):
        sim.simulate(plant, None, duration=1.0, dt=0.01, method="cvodes")
    assert not sim.can_run_light(plant, None, "rk4")
    with pytest.raises(InputError, match="MoorDyn moorings"):
        sim.simulate_arrays(plant, None, duration=1.0, dt=0.01)
    with pytest.raises(InputError, match="MoorDyn moorings"):
        sim.simulate_batch(plant, [None], duration=1.0, dt=0.01)


def test_a_failing_moordyn_is_a_simulation_error_with_the_time_and_a_remedy(tmp_path):
    """dtM 6 ms: its damped twin (dtM / 2) brings the lines to rest for the linear model, the
    run fails at 0.3 s; dtM 0.2 s fails already there, when the plant is built."""
    plant = build_plant(_variant(tmp_path / "run", ("0.002         dtM", "0.006         dtM")))
    with pytest.raises(SimulationError, match=r"mooring 'chains': MoorDyn failed between "
                                              r"t = [\d.]+ s.*dtM"):
        sim.simulate(plant, waves.regular(2.0, 8.0), duration=20.0, dt=0.01)
    with pytest.raises(SceneError, match=r"sphere_lines.txt: MoorDyn failed while bringing the "
                                         r"lines to rest.*dtM, now 0.2 s"):
        build_plant(_variant(tmp_path / "build", ("0.002         dtM", "0.2         dtM")))


def test_a_moored_plant_is_not_exported_without_its_lines(plant, tmp_path):
    from mbcontrol.export.plant import export_plant
    with pytest.raises(InputError, match="MoorDyn moorings run beside the plant"):
        export_plant(plant, None, tmp_path, dt=0.01)


def test_the_cli_reports_tensions_in_json_and_netcdf(tmp_path, capsys):
    """`mbcontrol simulate ... --json --out`: per line and end the statistics a designer reads
    (the 3-hour most probable maximum: mean + std sqrt(2 ln(3 h / Tz)), checked here from the
    record itself), and one netCDF variable per line end whose name holds "tension", in N."""
    import json

    import xarray as xr

    from mbcontrol.cli import main
    out = tmp_path / "run.nc"
    assert main(["simulate", str(SCENE), "--wave", "jonswap", "--hs", "1.5", "--tp", "8",
                 "--duration", "100", "--json", "--out", str(out)]) == 0   # 10 periods
    result = json.loads(capsys.readouterr().out)
    stats = result["moorings"]["chains"]["line1"]["fairlead"]
    ds = xr.open_dataset(out)
    names = [v for v in ds.data_vars if "tension" in v]
    assert names == [f"chains__line{k}__{end}_tension" for end in ("anchor", "fairlead")
                     for k in (1, 2, 3)]
    assert ds["chains__line1__fairlead_tension"].attrs["units"] == "N"
    record = ds["chains__line1__fairlead_tension"].values
    start = result["window_start_s"]
    window = record[ds["time"].values >= start - 1e-9]
    assert stats["max_N"] == pytest.approx(window.max(), rel=1e-6)      # float32 store: 1e-7
    assert stats["mean_N"] == pytest.approx(window.mean(), rel=1e-6)
    crossings = 3 * 3600.0 / stats["tz_s"]
    assert stats["mpm_3h_N"] == pytest.approx(
        stats["mean_N"] + stats["std_N"] * math.sqrt(2 * math.log(crossings)), rel=1e-12)
    assert stats["mpm_3h_N"] > stats["max_N"]                  # 3 h hold more than 100 s
    ds.close()


def test_rm3s_settled_lines_are_moorpys_static_equilibrium(monkeypatch, tmp_path):
    """The whole RM3 system at rest (three chains, three buoys, their lines to the spar)
    against MoorPy's quasi-static equilibrium of the same MoorDyn file, solved independently
    (elastic catenaries with seabed contact, buoy positions free). MoorDyn's end-node tension
    is that of the segment beside it: the lower chains' 16 m segments, steep at the buoy, put
    that end 2.8 % low (its weight over half a segment); measured: lower lines' anchors 0.33 %,
    upper lines' ends 0.50 % and 0.72 %, the buoy within 3 cm."""
    moorpy = pytest.importorskip("moorpy")
    monkeypatch.setenv("PYTHONBREAKPOINT", "0")       # MoorPy calls breakpoint() on odd input
    from mbcontrol.plant.process import assemble_plant
    from mbcontrol.sim.moordyn_run import MooredRun
    plant = assemble_plant("rm3_moored", radiation=False)
    moored = MooredRun(plant, plant.x0())            # the moored rest: the plate 0.3 m down
    try:
        ours = dict(zip(moored.names, moored.tensions()))
        system = moored.systems[0]
        buoy = np.array(system.md.GetPointPos(system.md.GetPoint(system.handle, 7)))
        fairleads = moored.points(plant.x0())[0].T * TO_MOORDYN
    finally:
        moored.close()
    data = read_moordyn(HERE.parents[2] / "models" / "rm3_moored_lines.txt")
    text = run_text(data, fairleads, {})
    path = tmp_path / "rm3.txt"
    path.write_text(text)
    ms = moorpy.System(file=str(path))
    ms.initialize()
    assert ms.solveEquilibrium(tol=1e-4)
    for k, line in enumerate(ms.lineList, start=1):
        anchor, fairlead = (float(np.linalg.norm(np.atleast_1d(T))) for T in (line.TA, line.TB))
        assert ours[f"lines__line{k}__anchor_tension"] == pytest.approx(anchor, rel=0.008)
        assert ours[f"lines__line{k}__fairlead_tension"] == pytest.approx(fairlead, rel=0.035)
    # the buoy of line 1 (point 7): where MoorPy puts it, to 0.1 m (it sits 1.6 m below its
    # file position, pulled 2.9 m outward)
    np.testing.assert_allclose(buoy, ms.pointList[6].r, atol=0.1)


def test_a_sweep_gives_the_mooring_loads_beside_the_power(capsys, tmp_path):
    """`mbcontrol sweep` on a moored scene: per sea the design loads over its fairleads
    ("mooring_max_N", "mooring_mpm_3h_N"), in the JSON and as a table beside the power
    matrix; the max is the record's own, checked against a plain `simulate` of the same case
    (same sea, seed and window: studies.sweep.case_run.sea_wave)."""
    import json

    from mbcontrol.analysis import analysis_window
    from mbcontrol.cli import main
    from mbcontrol.studies.sweep.case_run import sea_wave
    from mbcontrol.waves.sites import SeaState
    argv = ["sweep", str(SCENE), "--hs", "1", "2", "--tp", "8", "--duration", "100",
            "--dt", "0.01", "--workers", "0"]
    assert main(argv + ["--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["seas"]
    assert [sorted(k for k in r if k.startswith("mooring")) for r in rows] == \
        [["mooring_max_N", "mooring_mpm_3h_N"]] * 2
    plant = build_plant(str(SCENE))
    wave = sea_wave(plant, SeaState(hs=2.0, tp=8.0), 100.0)
    ds = sim.simulate(plant, wave, duration=100.0, dt=0.01)
    window = analysis_window(ds)
    fairleads = [ds[f"chains__line{k}__fairlead_tension"].values[window].max() for k in (1, 2, 3)]
    assert rows[1]["mooring_max_N"] == pytest.approx(max(fairleads), rel=1e-9)
    assert rows[1]["mooring_max_N"] > rows[0]["mooring_max_N"]       # a higher sea pulls more
    assert main(argv + ["--plot", str(tmp_path / "sweep.png")]) == 0    # a loads panel too
    assert "mooring loads, the most loaded fairlead" in capsys.readouterr().out
    assert (tmp_path / "sweep.png").stat().st_size > 10_000


def test_snap_loads_are_flagged_where_the_gaussian_estimate_fails():
    """A narrow-band Gaussian tension (a random-phase sum about 0.1 Hz, 600 s) stays below its
    3-hour most probable maximum; the same record with one snap (a line going slack and taut:
    five times the mean for 0.1 s) does not, and is flagged."""
    from mbcontrol.analysis import tension_statistics
    from mbcontrol.analysis.mooring_stats import slack_lines
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 600.0, 0.05)
    f = rng.uniform(0.08, 0.12, 40)
    x = 2e5 + 1e4 * np.sum(np.cos(2 * np.pi * f[:, None] * t + rng.uniform(0, 6.3, 40)[:, None]),
                           axis=0) / np.sqrt(20)
    calm = tension_statistics(t, x)
    assert calm["gaussian"] and calm["max_N"] < calm["mpm_3h_N"]
    x[6000:6002] = 1e6
    snap = tension_statistics(t, x)
    assert not snap["gaussian"]
    summary = {"lines": {"line1": {"fairlead": snap, "anchor": calm}}}
    assert any("snap loads" in note for note in slack_lines(summary))


def test_the_linear_model_with_the_lines_predicts_small_motions_of_the_coupled_run():
    """RM3 released from 2 deg pitch, then from 0.25 m surge, off its moored rest, no waves:
    the run (MoorDyn's lines beside the nonlinear plant) against the linear model taken at
    that rest, x(t) = expm(A t) x(0). Pitch (hydrostatics and lines): measured 0.6 % RMS of
    its swing over 100 s. Surge is the lines' alone (hydrostatics give none): its 66 s period
    comes from their stiffness in the linear model; the lines' own mass and drag, which it
    leaves out, lengthen it (measured: zero crossings at 17.3, 52.5, 87.3 s against 16.5,
    49.5, 82.5 s: 5.3-5.9 % later)."""
    from scipy.linalg import expm

    from mbcontrol.analysis import linearize
    plant = build_plant("rm3_moored")
    rest, step = plant.x0(), expm(linearize(plant).A * 0.01)

    def released(coordinate, offset, duration):
        j = plant.states.index(f"plate_motion__{coordinate}")
        start = rest.copy()
        start[j] += offset
        ds = sim.simulate(plant, None, duration=duration, dt=0.01, x0=start)
        X = np.empty((len(ds["time"]), plant.nx))
        X[0] = start - rest
        for k in range(1, len(X)):
            X[k] = step @ X[k - 1]
        return ds["time"].values, ds[plant.states[j]].values - rest[j], X[:, j]
    _, run, linear = released("Pitch", math.radians(2.0), 100.0)
    assert np.sqrt(np.mean((run - linear) ** 2)) < 0.02 * math.radians(2.0)
    t, run, linear = released("Surge", 0.25, 100.0)
    ours, theirs = (t[np.flatnonzero(np.diff(np.sign(y)) != 0)][:3] for y in (run, linear))
    assert len(ours) == len(theirs) == 3                     # it swings: the lines restore it
    np.testing.assert_allclose(ours, theirs, rtol=0.08)
    assert np.all(ours >= theirs)                             # the lines' mass slows it
