"""Workers started by the fork server: the records the serial run gives, the defaults this
process has now (its environment and set(), not what the server started with), and no state
kept between sweeps: a scene edited on disk between two sweeps on such workers gives the
edited scene's numbers."""
import numpy as np

from mbcontrol import defaults
from mbcontrol.studies.sweep import grid, runner, sweep
from mbcontrol.studies.sweep.cases import build_cases
from mbcontrol.studies.sweep.store import CaseStore
from tests.helpers.drivetrain_scenes import catalogue_copy

SEAS = grid([1.0, 2.0], [8.0, 11.0])
PARAMETERS = "\n[parameters]\nc = 2.0e5                            # N s/m\n"


def _scene(folder, suffix: str, damping: str):
    path = catalogue_copy(folder, "sphere", suffix, PARAMETERS, kernel_judged=True)
    path.write_text(path.read_text().replace("damping = 2.0e5", f'damping = "{damping}"', 1))
    return path


def _defaults(dask_worker=None):
    from mbcontrol import defaults
    return defaults.get("sweep.dt"), defaults.get("stats.min_periods"), defaults.get("log.quiet")


def test_forkserver_workers_agree_with_serial_and_see_the_environment_now(monkeypatch):
    monkeypatch.setenv("MBCONTROL_SWEEP_START", "forkserver")
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")
    cases = build_cases("sphere", SEAS, seeds=2, duration=140.0, dt=0.1)
    serial, clustered = CaseStore(None), CaseStore(None)
    runner.execute(cases, serial, workers=0, progress=False)
    result = runner.execute(cases, clustered, workers=2, progress=False)
    assert result["where"] == "cluster" and result["computed"] == len(cases)
    for c in cases:
        assert clustered.read(c.key)["metrics"] == serial.read(c.key)["metrics"]
    # the fork server runs on with the environment it started with; workers get this
    # process's defaults as they are now, from its environment or set()
    monkeypatch.setenv("MBCONTROL_SWEEP_DT", "0.025")
    monkeypatch.setenv("MBCONTROL_QUIET", "yes")
    defaults.set("stats.min_periods", 12)
    starter = runner._ClusterStarter(1, ("sphere", (), 1400, "rk4", False), "forkserver")
    starter.start()
    starter.join()
    try:
        assert starter.error is None
        here = _defaults()
        assert here == (0.025, 12, True)
        assert list(starter.client.run(_defaults).values()) == [here]
    finally:
        defaults.reset("stats.min_periods")
        starter.close()


def test_a_scene_edited_between_two_forkserver_sweeps_gives_the_edited_numbers(
        tmp_path, monkeypatch):
    short = dict(duration=140.0, dt=0.1, progress=False)
    path = _scene(tmp_path, "state", "{c}")
    monkeypatch.setenv("MBCONTROL_SWEEP_START", "forkserver")
    monkeypatch.setenv("MBCONTROL_SWEEP_CLUSTER", "always")
    before, _ = sweep(str(path), SEAS, seeds=2, workers=2, **short)
    _scene(tmp_path, "state", "{3 * c}")                   # the same file, edited
    after, _ = sweep(str(path), SEAS, seeds=2, workers=2, **short)
    fresh, _ = sweep(str(_scene(tmp_path, "fresh", "{3 * c}")), SEAS, seeds=2, workers=0,
                     **short)
    b, a = before["mean_power_W"].values, after["mean_power_W"].values
    assert np.all(np.isfinite(b)) and not np.allclose(b, a, rtol=1e-3)
    np.testing.assert_array_equal(a, fresh["mean_power_W"].values)
