"""Tests of mbcontrol.hydro.mesh.surface_sums: the panel sums as one never-inlined CasADi call.

References, independent of the block map under test:
- the point-by-point numpy sums of mbcontrol.hydro.mesh.panels.pressure_wrench (same panels,
  same pressure), for wrenches in calm water and in a wave field;
- numpy's max of LocalField.usage over the posed points, for the wrench's `largest` output
  (and the wrench with it must be the wrench without it);
- the box in closed form, rho g A d^2 / 2 (an upright box of waterplane A at draft d), and the
  potential's own derivative: d(potential)/d(sinking) = rho g V_wet = -F_z (a conservation law
  the panel rule must keep with its force).
Frames: NED, water at z > 0. The OSWEC flap's 1,563 points are not a multiple of the block, so
the zero-weight padding is exercised.
"""
from __future__ import annotations

import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mbcontrol.hydro import (body_panels, calm_water_function, hydrostatic_pressure,
                             pressure_wrench, pressure_wrench_function)
from mbcontrol.waves import LocalField

RHO, G = 1025.0, 9.81
MODELS = Path(__file__).resolve().parents[3] / "models"
FLAP = {"type": "mesh", "file": str(MODELS / "oswec_flap.stl"), "center": [0.0, 0.0, 3.9]}
COG = np.array([0.0, 0.0, 3.9])
FIELD = LocalField(0.0, 0.0, 0.0, 10.0, 10.9, 6, 5, 10.9, G)


@pytest.fixture(scope="module")
def flap():
    return body_panels(FLAP, COG)


def _pose(deg: float, axis=(0.0, 1.0, 0.0)):
    return Rotation.from_rotvec(np.radians(deg) * np.asarray(axis)).as_matrix()


def _field_pressure(rows):
    return lambda x, y, z: FIELD.pressure(rows, x, y, z, RHO, G)


@pytest.mark.parametrize("block", [1, 8, 13])
def test_the_wave_wrench_is_the_point_by_point_sum(flap, block):
    assert flap.n % 8 and flap.n % 13                   # padding exercised
    fun = pressure_wrench_function(flap, _field_pressure, FIELD.n_rows, "w", block=block)
    with_usage = pressure_wrench_function(
        flap, lambda rows: lambda x, y, z: FIELD.pressure_and_usage(rows, x, y, z, RHO, G),
        FIELD.n_rows, "wu", block=block, largest=True)
    rng = np.random.default_rng(3)
    for deg in (0.0, 12.0, -25.0):
        rows = rng.normal(size=FIELD.n_rows) * 0.3
        R, r = _pose(deg), COG + [0.4, 0.0, 0.2]
        force, moment = (np.asarray(v).ravel() for v in fun(rows, R, r))
        *wrench, usage = (np.asarray(v).ravel() for v in with_usage(rows, R, r))
        for together, alone in zip(wrench, (force, moment)):
            np.testing.assert_allclose(together, alone, rtol=1e-14, atol=0)
        f_ref, m_ref = pressure_wrench(flap, R, r, _field_pressure(rows))
        scale = np.max(np.abs(f_ref))
        np.testing.assert_allclose(force, f_ref, rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(moment, m_ref, rtol=0, atol=1e-12 * scale * 20.0)
        X = r[:, None] + R @ flap.points
        assert usage[0] == pytest.approx(np.max(FIELD.usage(rows, *X)), rel=1e-13)


def test_the_call_stays_one_node_in_an_sx_graph_and_differentiates(flap):
    fun = pressure_wrench_function(flap, _field_pressure, FIELD.n_rows, "w")
    rows, r = ca.SX.sym("rows", FIELD.n_rows), ca.SX.sym("r", 3)
    force = fun(rows, ca.DM.eye(3), r)[0]
    graph = ca.Function("g", [rows, r], [force])
    assert graph.n_instructions() < 100                 # not thousands of points expanded
    jac = ca.Function("j", [rows, r], [ca.jacobian(force, r)])
    x0, r0 = np.zeros(FIELD.n_rows), COG + [0.0, 0.0, 0.0123]   # no point on the waterline
    step = 1e-5
    numeric = [(np.asarray(graph(x0, r0 + step * e)) - np.asarray(graph(x0, r0 - step * e)))
               .ravel() / (2 * step) for e in np.eye(3)]
    exact = np.asarray(jac(x0, r0))
    np.testing.assert_allclose(exact, np.array(numeric).T, rtol=0,
                               atol=1e-7 * np.max(np.abs(exact)))


def test_calm_water_wrench_matches_the_point_sums_and_the_potential_its_force(flap):
    fun = calm_water_function(flap, RHO, G, "calm")
    for deg in (0.0, 20.0):
        R, r = _pose(deg, (1.0, 0.5, 0.0)), COG + [0.0, 0.0, 0.3]
        force, moment, _ = (np.asarray(v).ravel() for v in fun(R, r))
        f_ref, m_ref = pressure_wrench(flap, R, r, hydrostatic_pressure(RHO, G))
        np.testing.assert_allclose(force, f_ref, rtol=0, atol=1e-12 * np.max(np.abs(f_ref)))
        np.testing.assert_allclose(moment, m_ref, rtol=0, atol=1e-11 * np.max(np.abs(f_ref)))
        # the potential's derivative along sinking is the buoyancy: d U / d z = -F_z
        h = 1e-4
        up, down = (float(fun(R, r + [0.0, 0.0, s])[2]) for s in (h, -h))
        assert (up - down) / (2 * h) == pytest.approx(-force[2], rel=1e-6)


def test_calm_water_potential_of_an_upright_box_is_closed_form():
    size, draft = np.array([4.0, 2.0, 1.0]), 0.3               # m; centre 0.2 m above water
    box = body_panels({"type": "box", "size": size.tolist(), "center": [0.0, 0.0, 0.0]},
                      np.zeros(3))
    fun = calm_water_function(box, RHO, G, "box")
    force, _, potential = fun(np.eye(3), [0.0, 0.0, draft - size[2] / 2])
    area = size[0] * size[1]
    assert float(potential) == pytest.approx(RHO * G * area * draft ** 2 / 2, rel=1e-12)
    assert float(force[2]) == pytest.approx(-RHO * G * area * draft, rel=1e-12)
    assert math.isfinite(float(potential))
