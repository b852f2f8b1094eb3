"""BEM of arrays on the layout's mirror planes (mbcontrol.hydro.bem.array_bem): the same numbers as the
plain coupled solve, and used only where the symmetry is exact. Coarse meshes, few frequencies."""
import numpy as np
import pytest

from mbcontrol.hydro import BemBody
from mbcontrol.hydro.bem import solve as bem
from mbcontrol.hydro.bem.array_bem import symmetric_array_body

OMEGAS = np.array([2.0, 5.0, 9.0])


def _grid(n, panel=0.1, shift=(0.0, 0.0), dofs=("Heave",), radius=0.2):
    out = []
    for i in range(n * n):
        c = ((i % n - (n - 1) / 2) + shift[0], (i // n - (n - 1) / 2) + shift[1], 0.05)
        out.append(BemBody(name=f"f{i + 1}", geometry={"type": "cylinder", "radius": radius, "length": 0.3,
                                                       "axis": "z", "center": list(c)},
                           cog=c, mass=25.0, panel_size=panel, dofs=dofs))
    return out


def test_the_planes_found_are_the_layouts():
    assert symmetric_array_body(_grid(2), lid=True)[1] == ["xOz", "yOz"]
    assert symmetric_array_body(_grid(2, shift=(0.3, 0.0)), lid=True)[1] == ["xOz"]   # x = 0 lost
    assert symmetric_array_body(_grid(2, shift=(0.3, 0.2)), lid=True) is None
    one_bigger = _grid(2)
    one_bigger[3] = _grid(2, radius=0.25)[3]
    assert symmetric_array_body(one_bigger, lid=True) is None      # no mirror image for it
    assert symmetric_array_body(_grid(1), lid=True) is None        # one body: nothing to gain


@pytest.mark.parametrize("shift, dofs", [((0.0, 0.0), ("Heave",)),
                                         ((0.3, 0.0), ("Surge", "Heave", "Pitch"))])
def test_symmetric_solve_equals_the_plain_coupled_solve(monkeypatch, shift, dofs):
    bodies = _grid(2, shift=shift, dofs=dofs)
    kw = dict(rho=1000.0, g=9.81, depth=np.inf, omegas=OMEGAS, headings=[0.0, 0.6], progress=False)
    sym = bem.compute(bodies, **kw)
    assert sym.attrs["mirror_symmetry_used"] and sym.attrs["array_symmetry_planes"]
    monkeypatch.setattr(bem, "symmetric_array_body", lambda b, lid: None)
    plain = bem.compute(bodies, **kw)
    assert not plain.attrs["mirror_symmetry_used"]
    for var in ("added_mass", "radiation_damping", "added_mass_inf", "excitation_force",
                "hydrostatic_stiffness"):
        a, b = sym[var].values, plain[var].values
        assert np.abs(a - b).max() <= 1e-6 * np.abs(b).max(), var
