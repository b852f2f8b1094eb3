"""No hidden state between sweeps (issue 59): each sweep() call keeps its plants in a
PlantCache of its own, so a scene edited on disk between two sweeps in one process gives the
edited scene's numbers, also for the plants of varied scene parameters (built by the cases)."""
import numpy as np

from tests.helpers.drivetrain_scenes import catalogue_copy
from mbcontrol.studies.sweep import grid, sweep

SEAS = grid([1.0, 2.0], [8.0, 11.0])
SHORT = dict(duration=140.0, dt=0.1, progress=False, workers=0)
PARAMETERS = "\n[parameters]\nc = 2.0e5                            # N s/m\n"


def _scene(folder, suffix: str, damping: str):
    path = catalogue_copy(folder, "sphere", suffix, PARAMETERS, kernel_judged=True)
    text = path.read_text().replace("damping = 2.0e5", f'damping = "{damping}"', 1)
    assert f'damping = "{damping}"' in text
    path.write_text(text)
    return path


def _powers(path) -> np.ndarray:
    ds, _ = sweep(str(path), SEAS, vary={"c": [2.0e5, 6.0e5]}, **SHORT)
    return ds["mean_power_W"].values


def test_a_scene_edited_between_two_sweeps_gives_the_edited_numbers(tmp_path):
    path = _scene(tmp_path, "state", "{c}")
    before = _powers(path)
    _scene(tmp_path, "state", "{3 * c}")                    # the same file, edited
    after = _powers(path)
    fresh = _powers(_scene(tmp_path, "fresh", "{3 * c}"))    # never swept in this process
    assert np.all(np.isfinite(before)) and not np.allclose(before, after, rtol=1e-3)
    np.testing.assert_array_equal(after, fresh)
