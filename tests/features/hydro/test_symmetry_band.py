"""BEM data that break reciprocity (A != A^T) where the radiation fit never looks, or by no more
than a panel solution's own error (BEM_ASYM_TOL, 1 %), are repaired with a warning; larger ones
where the fit looks are refused, naming the scene key that accepts them
(mbcontrol.hydro.readers.checks, issue 58). WEC-Sim's rm3.out in heave: the float/spar pair of
its damping is 0.12 % apart at 0.82 rad/s (inside any sea's band, over the 0.1 % tolerance), of
its added mass 0.42 % at 5.18 rad/s; in roll, float/spar added mass 2.1 % at 0.78 rad/s.
Reciprocity is the independent reference (a linear body's radiation matrices are symmetric)."""
import warnings
from pathlib import Path

import numpy as np
import pytest

from mbcontrol.errors import HydroError
from mbcontrol.hydro.readers import read_hydro
from mbcontrol.hydro.readers.checks import HydroCleaningWarning

RM3 = Path(__file__).resolve().parents[4] / "shared" / "data" / "wamit" / "rm3.out"
HEAVE = ["float__Heave", "spar__Heave"]


def test_asymmetry_over_the_bem_error_inside_the_band_is_refused_naming_the_scene_key():
    with pytest.raises(HydroError, match=r"added_mass is not symmetric: relative asymmetry 0.0208 > 0.001 at "
                                         r"float__Roll / spar__Roll at ω = 0.78 rad/s.*set \[hydro\] "
                                         r"source_options = \{ force_symmetric = true \}"):
        read_hydro(RM3, band_max=3.0)


def test_asymmetry_within_the_bem_error_is_repaired_with_a_warning_naming_size_and_key():
    """0.12 % at 0.82 rad/s: inside the band, within 1 %: symmetrised, said with the key that
    accepts it silently; with that key above every asymmetry (0.0044, which the added mass's
    warning names) only noted (below 5 rad/s: no damping to repair)."""
    with pytest.warns(HydroCleaningWarning, match=r"radiation_damping is not symmetric: relative asymmetry "
                                                  r"0.00122 > 0.001 at float__Heave / spar__Heave at ω = 0.82 "
                                                  r"rad/s.*within the BEM's discretisation error.*source_options "
                                                  r"= \{ asym_tol = 0.0013 \}"):
        ds = read_hydro(RM3, dofs=HEAVE, band_max=3.0)
    B = ds["radiation_damping"].values
    np.testing.assert_array_equal(B, np.swapaxes(B, -1, -2))
    with warnings.catch_warnings():
        warnings.simplefilter("error", HydroCleaningWarning)
        quiet = read_hydro(RM3, dofs=HEAVE, omega_range=(0.0, 5.0), asym_tol=0.0044)
    assert quiet.attrs["cleaning"]["symmetrised"]["radiation_damping"]["max_relative_asymmetry"] == \
        pytest.approx(0.00122, rel=0.01)


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
