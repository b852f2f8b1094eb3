"""BEM data that break reciprocity (A != A^T) where the radiation fit never looks are repaired
with a warning; where it does, they are refused, naming the scene key that accepts them
(mbcontrol.hydro.readers.checks, issue 58). WEC-Sim's rm3.out in heave: the float/spar pair of
its damping is 0.12 % apart at 0.82 rad/s (inside any sea's band, over the 0.1 % tolerance), of
its added mass 0.42 % at 5.18 rad/s; reciprocity is the independent reference (a linear
body's radiation matrices are symmetric)."""
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import HydroError
from mbcontrol.hydro.readers import read_hydro
from mbcontrol.hydro.readers.checks import HydroCleaningWarning

RM3 = Path(__file__).resolve().parents[3] / "shared" / "data" / "wamit" / "rm3.out"
HEAVE = ["float__Heave", "spar__Heave"]


def test_asymmetry_inside_the_band_is_refused_naming_the_scene_key():
    with pytest.raises(HydroError, match=r"radiation_damping is not symmetric.*0.82 rad/s.*set \[hydro\] "
                                         r"source_options = \{ force_symmetric = true \}"):
        read_hydro(RM3, dofs=HEAVE, band_max=3.0)


def test_asymmetry_above_the_band_is_repaired_with_a_warning():
    with pytest.warns(HydroCleaningWarning, match=r"above the radiation fit's band \(\[hydro\] "
                                                  r"fit_omega_max = 0.6 rad/s"):
        ds = read_hydro(RM3, dofs=HEAVE, band_max=0.6)
    A = ds["added_mass"].values
    np.testing.assert_allclose(A, np.swapaxes(A, -1, -2), rtol=0, atol=0)     # symmetrised
    with warnings.catch_warnings():                 # forced, the same matrices
        warnings.simplefilter("ignore", HydroCleaningWarning)
        forced = read_hydro(RM3, dofs=HEAVE, force_symmetric=True)
    np.testing.assert_array_equal(A, forced["added_mass"].values)
