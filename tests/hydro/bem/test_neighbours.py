"""Interaction cut at a radius (mbcontrol.hydro.bem.neighbours) against the plain coupled solve and
the isolated one (two independent paths through Capytaine). Coarse meshes, few frequencies."""
import numpy as np
import pytest

from mbcontrol.errors import HydroError, SceneError
from mbcontrol.hydro import BemBody
from mbcontrol.hydro.bem import solve as bem
from mbcontrol.hydro.bem.isolated import compute_isolated
from mbcontrol.hydro.bem.neighbours import compute_within, cut_error
from mbcontrol.scene import load_scene

KW = dict(rho=1000.0, g=9.81, depth=np.inf, omegas=np.array([2.0, 5.0, 9.0]), headings=[0.0, 0.6],
          progress=False)
VARS = ("added_mass", "radiation_damping", "added_mass_inf", "excitation_force", "hydrostatic_stiffness")


def _row(n, spacing=1.0, y=0.0, dofs=("Heave",)):
    """n cylinders in a line along x from x = 2 m (so every cluster is moved to solve it), on
    y = 0: each solve then meshes on the same mirror plane (a mesh reflected about y = 0 differs
    from the plain one by ~0.1 %)."""
    out = []
    for i in range(n):
        c = (2.0 + i * spacing, y, 0.05)
        out.append(BemBody(name=f"f{i + 1}", geometry={"type": "cylinder", "radius": 0.2, "length": 0.3,
                                                       "axis": "z", "center": list(c)},
                           cog=c, mass=25.0, panel_size=0.1, dofs=dofs))
    return out


def _close(a, b, var, rel=1e-8):
    """a[var] equals b[var], whose radiation matrices are first made symmetric as the cut's are
    (Capytaine's are to ~1e-5)."""
    x, y = a[var].transpose(*b[var].dims).values, b[var].values
    if var != "hydrostatic_stiffness" and b[var].dims[-2:] == ("radiating_dof", "influenced_dof"):
        y = 0.5 * (y + np.swapaxes(y, -1, -2))
    assert np.abs(x - y).max() <= rel * np.abs(y).max(), var


@pytest.mark.parametrize("dofs", [("Heave",), ("Surge", "Heave", "Pitch")])
def test_a_radius_over_the_whole_layout_is_the_coupled_solve(dofs):
    bodies = _row(3, dofs=dofs)
    full = bem.compute(bodies, **KW)
    cut = compute_within(bodies, radius=5.0, **KW)
    assert cut.attrs["distinct_clusters"] == 3 and cut.attrs["largest_cluster"] == 3
    for var in VARS:        # moved to the origin, renamed, phase restored: the same numbers
        _close(cut, full, var, rel=1e-6)
    assert cut_error(full, cut)["kernel"] < 1e-6
    assert cut.attrs["hull_panels"] == full.attrs["hull_panels"]      # each float's own count


def test_a_radius_below_the_spacing_is_the_isolated_solve():
    bodies = _row(3)
    alone = compute_isolated(bodies, **KW)
    cut = compute_within(bodies, radius=0.5, **KW)
    for var in VARS:
        _close(cut, alone, var)


def test_neighbours_only_couple_and_the_error_shrinks_with_the_radius():
    bodies = _row(5)
    full = bem.compute(bodies, **KW)
    near = compute_within(bodies, radius=1.0, **KW)
    assert near.attrs["distinct_clusters"] == 3          # two ends, and one interior shape for three
    B = near["radiation_damping"].sel(omega=5.0).values
    assert B[0, 1] != 0 and B[0, 2] == 0 and np.allclose(B, B.T)
    # (a cluster is solved per distinct relative layout: at 2 m, five of three to five floats,
    # 12 s; at 3 m another 14 s, so the test stops at 2 m)
    cuts = {r: near if r == 1.0 else compute_within(bodies, radius=r, **KW) for r in (0.5, 1.0, 2.0)}
    errors = [cut_error(full, cut)["kernel"] for cut in cuts.values()]
    assert errors[0] > errors[1] > errors[2] > 0, errors
    # radiated waves reach far: B_1j of the full solve does not fall off with distance here (kd
    # = 10 at 4 m), so even nearest neighbours leave a large error (the README's table)
    assert errors[1] > 0.1
    assert np.isfinite(cuts[1.0].attrs["cut_min_damping_eig"])


def test_obstacles_and_contradictory_settings_are_refused(tmp_path):
    obstacle = BemBody(name="wall", geometry={"type": "box", "size": [0.2, 2.0, 0.5], "center": [0, 0, 0]},
                       cog=(0, 0, 0), mass=0.0, panel_size=0.2, dofs=())
    with pytest.raises(HydroError, match="obstacles"):
        compute_within(_row(2) + [obstacle], radius=1.0, **KW)
    with pytest.raises(HydroError, match="positive"):
        compute_within(_row(2), radius=0.0, **KW)
    assert load_scene("array_grid").hydro.interaction_radius == np.inf
    assert load_scene("array_grid", {"cutoff": 1.5, "scale": 4.0}).hydro.interaction_radius == 6.0
    scene = tmp_path / "cut.toml"
    scene.write_text(open(load_scene("array_grid").path).read().replace(
        'radiation_fit = "columns"', 'radiation_fit = "columns"\ninteraction = false'))
    load_scene(scene)                                   # no radius: no contradiction
    with pytest.raises(SceneError, match="interaction_radius"):
        load_scene(scene, {"cutoff": 1.5})


def test_a_scene_with_a_cutoff_solves_each_float_within_its_radius(monkeypatch):
    from mbcontrol.hydro import model
    from mbcontrol.hydro.bem import neighbours        # model imports it when it solves
    seen = {}

    def solve(bodies, radius, **kwargs):
        seen.update(radius=radius, bodies=len(bodies))
        raise RuntimeError("stop: what the scene asked for is recorded")
    monkeypatch.setattr(neighbours, "compute_within", solve)
    scene = load_scene("array_grid", {"n": 3, "cutoff": 1.5})
    with pytest.raises(RuntimeError, match="stop"):
        model.load_hydro_data(scene, [f"float{i + 1}__Heave" for i in range(9)])
    assert seen == {"radius": 1.5, "bodies": 9}
