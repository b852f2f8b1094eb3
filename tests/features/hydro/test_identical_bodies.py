"""Identical isolated bodies solved once (issue 20 item 4), against a direct BEM solve of the
displaced body as the independent reference, and by counting the BEM runs.

The box is dyadic (0.5 x 0.25 x 0.25 m, 0.125 m panels) and so are the moves, so every mesh
coordinate, and every distance between panels, is exact wherever the box sits: Capytaine
then solves the same numbers and the two ways agree to round-off. On a box of decimal sizes
Capytaine's own results move by ~1e-6 under a translation (measured 2e-6 in heave added mass
for a 1 mm move: its near/far-field switch flips on distances equal to round-off), which the
shortcut does not inherit.
"""
import numpy as np
import pytest

import mbcontrol.hydro.bem.solve as bem
from mbcontrol.hydro import BemBody, compute
from mbcontrol.hydro.bem.isolated import canonical_body, compute_isolated

OMEGAS = np.array([3.0, 6.0, 9.0])
HEADINGS = (0.0, 0.6, -2.0)            # rad, NED: +x, towards starboard, from starboard aft
DOFS = ("Surge", "Sway", "Heave", "Pitch")


def _box(name, x, y, mass=15.625, size=(0.5, 0.25, 0.25)):
    return BemBody(name=name, geometry={"type": "box", "size": list(size), "center": [x, y, 0.0]},
                   cog=(x, y, 0.0), mass=mass, panel_size=0.125, dofs=DOFS)


def _kw(depth=np.inf, **extra):
    return dict(rho=1000.0, g=9.81, depth=depth, omegas=OMEGAS, headings=HEADINGS,
                progress=False, **extra)


@pytest.fixture
def count_solves(monkeypatch):
    calls = []
    solve = bem._solve

    def counting(*args, **kwargs):
        calls.append(1)
        return solve(*args, **kwargs)
    monkeypatch.setattr(bem, "_solve", counting)
    return calls


def test_shifted_solve_is_a_direct_solve_of_the_displaced_body(count_solves):
    body = _box("a", 2.0, 1.0)                 # off the symmetry plane: solved without it
    shifted, direct = compute_isolated([body], **_kw()), compute([body], **_kw())
    assert len(count_solves) == 2
    for var in ("excitation_force", "froude_krylov_force", "diffraction_force", "added_mass",
                "radiation_damping", "hydrostatic_stiffness", "center_of_buoyancy", "cog"):
        a, b = shifted[var], direct[var]
        assert a.dims == b.dims, var
        # measured 4e-16 of the largest entry (excitation, deep water)
        assert np.max(np.abs(a.values - b.values)) <= 1e-6 * np.max(np.abs(b.values)), var
    assert list(shifted["radiating_dof"].values) == [f"a__{d}" for d in DOFS]
    # the phase convention itself: the incident wave at (2, 1) m leads the origin's by
    # k (x cos b + y sin b) (exp(-i w t)), seen on the Froude-Krylov force of the heave
    fk = shifted["froude_krylov_force"].sel(influenced_dof="a__Heave")
    at_origin = compute_isolated([_box("a", 0.0, 0.0)], **_kw())["froude_krylov_force"].sel(
        influenced_dof="a__Heave")
    k, beta = OMEGAS**2 / 9.81, np.asarray(HEADINGS)[:, None]
    expected = np.exp(1j * k[None, :] * (2.0 * np.cos(beta) + 1.0 * np.sin(beta)))
    np.testing.assert_allclose((fk / at_origin).sel(wave_direction=list(HEADINGS)).values,
                               expected, rtol=1e-10)


def test_finite_depth_phase_uses_its_wavenumber():
    """In 2 m of water the Froude-Krylov force (the incident wave alone, no BEM solve) of
    the shifted solve is the direct one's. Its diffraction and radiation are not compared
    at 1e-6: Capytaine 3.0's finite-depth Green function changes by ~1e-3 under a
    translation (measured 6e-4 in added mass for this box moved by 2 m)."""
    body = _box("a", 2.0, -1.0)
    shifted, direct = compute_isolated([body], **_kw(2.0)), compute([body], **_kw(2.0))
    a, b = shifted["froude_krylov_force"].values, direct["froude_krylov_force"].values
    assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b))


def test_n_identical_bodies_are_solved_once(count_solves, tmp_path):
    bodies = [_box(f"b{i}", 0.75 * i, 0.0) for i in range(4)]
    ds = compute_isolated(bodies, **_kw(cache_dir=tmp_path))
    assert len(count_solves) == 1 and ds.attrs["distinct_shapes"] == 1
    assert len(list(tmp_path.glob("bem_*.nc"))) == 1       # one cache entry: the shape's
    assert list(ds["body"].values) == ["b0", "b1", "b2", "b3"]
    np.testing.assert_array_equal(ds["cog"].values[:, 0], [0.0, 0.75, 1.5, 2.25])
    # elsewhere, and in another scene's names: the cache answers, no solve
    compute_isolated([_box("other", -3.0, 5.0)], **_kw(cache_dir=tmp_path))
    assert len(count_solves) == 1
    # another mass, another size: other bodies (mass enters the hydrostatic stiffness)
    compute_isolated(bodies + [_box("heavy", 9.0, 0.0, mass=20.0),
                               _box("long", 12.0, 0.0, size=(0.75, 0.25, 0.25))],
                     **_kw(cache_dir=tmp_path))
    assert len(count_solves) == 3


def test_shape_key_ignores_place_and_name_only():
    key = canonical_body(_box("a", 1.0, 2.0))[0]
    assert canonical_body(_box("zz", -4.0, 0.5))[0] == key
    assert canonical_body(_box("a", 1.0, 2.0, mass=16.0))[0] != key
    turned = BemBody(name="c", geometry={"type": "cylinder", "radius": 0.1, "length": 0.5,
                                         "center": [0.0, 0.0, 0.0], "axis": "x"},
                     cog=(0.0, 0.0, 0.0), mass=1.0, panel_size=0.125, dofs=DOFS)
    along_y = BemBody(name="c", geometry={**turned.geometry, "axis": "y"}, cog=(0.0, 0.0, 0.0),
                      mass=1.0, panel_size=0.125, dofs=DOFS)
    assert canonical_body(turned)[0] != canonical_body(along_y)[0]
    # a CoG moved on the body is another body (the rotation centre of every result)
    off = BemBody(name="a", geometry=_box("a", 1.0, 2.0).geometry, cog=(1.1, 2.0, 0.0),
                  mass=15.625, panel_size=0.125, dofs=DOFS)
    assert canonical_body(off)[0] != key
