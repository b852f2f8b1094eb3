"""Fixtures of the hydro tests: the third-party BEM files, read once per module."""
import warnings

import pytest

from mbcontrol.hydro.readers import HydroCleaningWarning, read_bemio, read_wamit
from tests.helpers.reader_data import RM3, RM3_FORCE, SPHERE, WAVESTAR


@pytest.fixture(scope="module")
def sphere():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)  # its ω > 11.5 rad/s heave damping tail: tested in test_readers.py
        return read_wamit(SPHERE)


@pytest.fixture(scope="module")
def rm3():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HydroCleaningWarning)
        return read_wamit(RM3, **RM3_FORCE)


@pytest.fixture(scope="module")
def wavestar():
    return read_bemio(WAVESTAR, omega_range=(0.0, 10.0))
