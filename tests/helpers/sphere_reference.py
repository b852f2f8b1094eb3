"""The heaving sphere's impedance written by hand from its BEM arrays: a reference for tests
that does not go through the code under test."""
import numpy as np


def heave_impedance(plant, omega):
    """(Z_i, F per unit amplitude) of the heaving body from the hydro data, exp(+i w t)."""
    hyd = plant.hydro
    w = hyd.omega
    A = np.interp(omega, w, hyd.added_mass()[:, 0, 0])
    B = np.interp(omega, w, hyd.radiation_damping()[:, 0, 0])
    F = hyd.excitation_coefficients(0.0)[:, 0]
    F = np.interp(omega, w, F.real) + 1j * np.interp(omega, w, F.imag)
    m, K = plant.scene.bodies[0].mass, hyd.hydrostatic_stiffness()[0, 0]
    return B + 1j * (omega * (m + A) - K / omega), F
