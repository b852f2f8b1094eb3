"""Large-angle hydrostatics (mbcontrol.hydro.mesh.large_angle) as a potential: its small-angle
stiffness against closed-form waterplane integrals, the wrench as minus the gradient of the
potential, zero work round closed loops, and the CasADi builds against numpy.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.large_angle_reference import (ALL, BOX, HCYL, RHO, G, evaluate, pose, reference, size,
                                   sphere_reference, total_volume)
from mbcontrol.hydro.mesh.large_angle import buoyancy, potential


# ------------------------------------------------------------------ small-angle consistency
def sym_pose():
    """SX symbols q = (heave, roll, pitch) and R = Ry(pitch) Rx(roll): rotation about the CoG."""
    q = ca.SX.sym("q", 3)
    cr, sr, cp, sp = ca.cos(q[1]), ca.sin(q[1]), ca.cos(q[2]), ca.sin(q[2])
    Rx = ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, cr, -sr), ca.horzcat(0, sr, cr))
    Ry = ca.vertcat(ca.horzcat(cp, 0, sp), ca.horzcat(0, 1, 0), ca.horzcat(-sp, 0, cp))
    return q, ca.mtimes(Ry, Rx)


def linear_stiffness(A, x0, y0, ixx, iyy, V, zB, cog):
    """Buoyancy-only stiffness K = -d(F_z, M_x, M_y)/d(heave, roll, pitch) at rest, NED, about the CoG.

    Waterplane of area A, centroid (x0, y0), central second moments ixx = ∫(x-x0)^2 dA,
    iyy = ∫(y-y0)^2 dA (no product term for these symmetric shapes). Derivation: a waterplane
    point moves down by dz + roll (y - yG) - pitch (x - xG), adding that much wet volume; the
    wet volume already there turns with the body (roll: y -> y - roll (z - zG)). Hence
    K33 = rho g A, K34 = rho g A (y0 - yG), K35 = -rho g A (x0 - xG),
    K44 = rho g [iyy + A (y0 - yG)^2 + V (zG - zB)], K55 = rho g [ixx + A (x0 - xG)^2 + V (zG - zB)],
    K45 = -rho g A (x0 - xG)(y0 - yG); in z-up terms K44 = rho g (I_wp + V (z_B - z_G)), as usual.
    """
    dx, dy, dz = x0 - cog[0], y0 - cog[1], cog[2] - zB
    return RHO * G * np.array([[A, A * dy, -A * dx],
                               [A * dy, iyy + A * dy**2 + V * dz, -A * dx * dy],
                               [-A * dx, -A * dx * dy, ixx + A * dx**2 + V * dz]])


def stiffness_cases():
    box = {"type": "box", "size": [2.0, 1.0, 1.0], "center": [0.3, -0.2, 0.1]}
    vcyl = {"type": "cylinder", "radius": 1.0, "length": 2.0, "center": [0.2, 0.1, 0.3], "axis": "z"}
    sph = {"type": "sphere", "radius": 1.0, "center": [0.1, 0.2, 0.3]}
    out = [("box", box, [0.1, 0.05, -0.2], 4 * 1.0 * 0.5, (0.3, -0.2), 2.0**3 * 1.0 / 12, 2.0 * 1.0**3 / 12)]
    out.append(("vcyl", vcyl, [0.0, 0.0, 0.0], math.pi, (0.2, 0.1), math.pi / 4, math.pi / 4))
    b = math.sqrt(1 - 0.4**2)                              # half-width of the waterline
    for axis in ("x", "y"):
        h = {**HCYL, "center": [0.0, 0.1, 0.4], "axis": axis}
        lx, ly = (3.0, 2 * b) if axis == "x" else (2 * b, 3.0)
        out.append((f"hcyl-{axis}", h, [0.2, 0.0, 0.0], lx * ly, (0.0, 0.1), ly * lx**3 / 12, lx * ly**3 / 12))
    a = math.sqrt(1 - 0.3**2)
    out.append(("sphere", sph, [0.0, 0.0, 0.5], math.pi * a * a, (0.1, 0.2), math.pi * a**4 / 4, math.pi * a**4 / 4))
    return out


@pytest.mark.parametrize("case", stiffness_cases(), ids=lambda c: c[0])
def test_small_angle_stiffness(case):
    name, geo, cog, A, (x0, y0), ixx, iyy = case
    cog = np.asarray(cog, float)
    if geo["type"] == "sphere":
        V, zB = sphere_reference(1.0, geo["center"][2])
    else:
        V, cB = reference(geo, cog, np.eye(3), cog)
        zB = cB[2]
    K = linear_stiffness(A, x0, y0, ixx, iyy, V, zB, cog)
    q, R = sym_pose()
    out = buoyancy(geo, cog, R, cog + ca.vertcat(0, 0, q[0]), RHO, G)
    wrench = ca.vertcat(out["force"], out["moment"])
    J = ca.Function("J", [q], [ca.jacobian(wrench, q)])(np.zeros(3)).full()
    scale = RHO * G * max(A * size(geo) ** 2, V * size(geo))
    # at rest every fibre crosses the waterline (slices and cap are exact): the Jacobian is exact,
    # measured |K + J|/scale <= 2.0e-16 over the five cases
    assert np.abs(-J[[2, 3, 4], :] - K).max() < 1e-12 * scale, (-J[[2, 3, 4], :], K)
    assert np.abs(J[[0, 1, 5], :]).max() == 0.0            # no surge/sway force or yaw moment


# ------------------------------------------------------------------ conservativeness
def skew(v):
    return ca.vertcat(ca.horzcat(0, -v[2], v[1]), ca.horzcat(v[2], 0, -v[0]), ca.horzcat(-v[1], v[0], 0))



@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_wrench_is_minus_gradient_of_potential(geometry):
    """(force, moment) = -dU/d(translation, small rotation about n-frame axes through the CoG)."""
    cog = np.asarray(geometry["center"], float) + np.array([0.1, -0.1, 0.05])
    r, eps = ca.SX.sym("r", 3), ca.SX.sym("eps", 3)
    rng = np.random.default_rng(7)
    for heel in (0.0, 0.3, 0.8, 1.3, math.pi / 2):
        R0 = pose(heel * rng.uniform(-1, 1), heel * rng.uniform(-1, 1), rng.uniform(-3, 3))
        R = ca.mtimes(ca.DM.eye(3) + skew(eps), ca.DM(R0))
        U = potential(geometry, cog, R, r, RHO, G)
        grad = ca.Function("g", [r, eps], [ca.gradient(U, ca.vertcat(r, eps))])
        r0 = np.array([0.5, -0.3, rng.uniform(-0.3, 0.3)])
        out = evaluate(geometry, cog, R0, r0)
        g = grad(r0, np.zeros(3)).full().ravel()
        scale = RHO * G * total_volume(geometry) * size(geometry)
        # exact identity of the discrete model: measured |dU + wrench| / scale <= 4.1e-16
        assert np.abs(g + np.concatenate([out["force"], out["moment"]])).max() < 1e-12 * scale, heel
        assert out["potential"] == pytest.approx(float(potential(geometry, cog, R0, r0, RHO, G)), rel=1e-14)


@pytest.mark.parametrize("geometry", [BOX, HCYL], ids=["box", "hcyl"])
def test_closed_loop_work_vanishes(geometry):
    """Work of the wrench around a large closed loop in (heave, roll, pitch) is ~0."""
    cog = np.asarray(geometry["center"], float) + np.array([0.0, 0.0, 0.1])
    N = 1500
    t = np.linspace(0.0, 2 * math.pi, N + 1)
    z, roll, pitch = 0.2 * np.sin(t), 0.7 * np.sin(t + 1.0), 0.5 * np.sin(2 * t)
    Rs = [pose(a, b) for a, b in zip(roll, pitch)]
    work = total = 0.0
    for k in range(N):
        # midpoint rule; the rotation increment as a rotation vector in the n-frame
        Rm = Rotation.from_matrix(Rs[k]) * Rotation.from_rotvec(0.5 * (Rotation.from_matrix(Rs[k]).inv()
                                                                      * Rotation.from_matrix(Rs[k + 1])).as_rotvec())
        dtheta = (Rotation.from_matrix(Rs[k + 1]) * Rotation.from_matrix(Rs[k]).inv()).as_rotvec()
        out = evaluate(geometry, cog, Rm.as_matrix(), [0.0, 0.0, 0.5 * (z[k] + z[k + 1])])
        dw = out["force"][2] * (z[k + 1] - z[k]) + out["moment"] @ dtheta
        work += dw
        total += abs(dw)
    # midpoint rule, 1500 steps: measured |loop work| / sum |dW| 3.5e-8 (box) and 1.1e-9 (hcyl),
    # falling with the step (2.1e-7 and 6.9e-9 at 500 steps): truncation error, not a leak
    assert abs(work) < 2e-6 * total, (work, total)


# ------------------------------------------------------------------ CasADi builds
@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_casadi_function_matches_numpy(geometry):
    cog = np.asarray(geometry["center"], float) + np.array([0.05, 0.1, -0.1])
    for kind in (ca.SX, ca.MX):
        R, r, rho, g = kind.sym("R", 3, 3), kind.sym("r", 3), kind.sym("rho"), kind.sym("g")
        out = buoyancy(geometry, cog, R, r, rho, g)
        names = ["force", "moment", "volume", "centre", "potential"]
        f = ca.Function("f", [R, r, rho, g], [out[k] for k in names])
        assert not f.has_free()
        for R0, r0 in ((pose(0.2, -0.4, 0.7), [1.0, 2.0, 0.1]), (pose(1.4, 0.1, 0.0), [0.0, 0.0, -0.2]),
                       (np.eye(3), [0.0, 0.0, 5.0]), (pose(0.0, math.pi / 2, 0.0), [0.0, 0.0, 0.0])):
            ref = evaluate(geometry, cog, R0, r0)
            got = f(R0, r0, RHO, G)
            for k, v in zip(names, got):
                # same arithmetic in another order: measured relative difference <= 5.7e-15
                assert np.asarray(v.full()).ravel() == pytest.approx(np.ravel(ref[k]), rel=1e-12, abs=1e-9), k


@pytest.mark.parametrize("geometry", ALL, ids=["box", "vcyl", "hcyl-x", "hcyl-y", "sphere", "barge"])
def test_jacobian_is_finite_everywhere(geometry):
    """No inf * 0 in AD: dry, wet, horizontal fibres (90 deg heel), an upright horizontal-cylinder axis."""
    q, R = sym_pose()
    cog = np.asarray(geometry["center"], float)
    x = ca.SX.sym("x", 3)
    out = buoyancy(geometry, cog, R, x, RHO, G)
    J = ca.Function("J", [q, x], [ca.jacobian(ca.vertcat(out["force"], out["moment"]), ca.vertcat(q, x))])
    for angles in ((0, 0, 0), (0, math.pi / 2, 0), (0, 0, math.pi / 2), (0, 0.3, 0.2)):
        for depth in (-5.0, 0.0, 0.05, 5.0):
            assert np.all(np.isfinite(J(angles, [0.0, 0.0, depth]).full()))
