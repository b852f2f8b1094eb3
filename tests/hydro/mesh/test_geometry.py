"""Mesh files as body geometry: a mesh drawn in its body's own frame is placed by its centre,
clipped at the free surface (WEC-Sim's OSWEC flap STL, about its CoG)."""
from pathlib import Path

import capytaine as cpt
import pytest

from mbcontrol.hydro import BemBody, hull_mesh

FLAP = Path(__file__).resolve().parents[3] / "models" / "oswec_flap.stl"


@pytest.mark.parametrize("depth_of_origin", [0.0, 3.9])
def test_mesh_is_placed_by_its_centre_then_clipped(depth_of_origin):
    body = BemBody(name="flap", geometry={"type": "mesh", "file": str(FLAP),
                                          "center": [0.0, 0.0, depth_of_origin]},
                   cog=(0.0, 0.0, depth_of_origin), mass=127000.0, panel_size=1.0,
                   dofs=("Surge", "Pitch"))
    hull, _, _ = hull_mesh(body)
    # the STL spans -5.5..+6.0 m about its origin (z up): placed 3.9 m deep, -9.4..+2.1 m,
    # so the hull runs from 9.4 m deep to the surface
    assert hull.vertices[:, 2].max() == pytest.approx(0.0, abs=1e-9)
    assert hull.vertices[:, 2].min() == pytest.approx(-5.5 - depth_of_origin, abs=1e-6)
    # the same as clipping the raw mesh at the waterline's height in its own frame
    raw = cpt.load_mesh(str(FLAP)).merged()
    below = raw.translated_z(-depth_of_origin).immersed_part()
    assert abs(hull.volume) == pytest.approx(abs(below.volume), rel=1e-9)
