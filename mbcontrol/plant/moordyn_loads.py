"""Where MoorDyn's lines act on the plant: the forces at each Coupled point.

MoorDyn has its own state and time step, so it is not part of the symbolic plant
(../shared/DESIGN.md). The plant holds the lines' quasi-static part, F_lin = F_0 + J (P - P_0)
at the points' positions P (plant.moordyn_statics: the pull and stiffness of the lines at rest
at the scene's pose P_0), and takes the rest of MoorDyn's force on each Coupled point
(n-frame, N) as three rows of the disturbance w ("w__moordyn_<mooring>_<point id>_<x|y|z>",
after the excitation and the wave field's rows). It applies both at the point on its body and
reports their power ("mooring_power", W, for the energy audit). `mbcontrol.sim.moordyn_run`
steps MoorDyn with the points' positions and velocities (`kinematics_function`) and fills those
rows with F_MoorDyn - F_lin. In the symbolic plant they are inputs like the excitation: zero in
linearisation and frequency analysis, which so see the lines' pull and stiffness.

The lines' pull moves rest: `moored_rest` finds where the plant's loads balance with it (a
plate held by chains sits lower), and the plant starts there (ProcessPlant.x0).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..scene import TO_MOORDYN, read_moordyn
from .moordyn_statics import mooring_statics
from .rest import say_once

REST_TOL = 1e-10          # m/s^2 (rad/s^2): the moored rest's largest acceleration


@dataclass(frozen=True)
class CoupledPoints:
    """The Coupled points of one MoorDyn mooring, in file order."""
    mooring: str
    body: str
    ids: tuple[int, ...]
    rest: np.ndarray            # (3, n) n-frame positions at rest, m
    local: np.ndarray           # (3, n) the same from the body's frame origin, body axes, m
    pull: np.ndarray            # (3, n) the lines' forces on them at rest there, n-frame, N
    stiffness: np.ndarray       # (3n, 3n) dF/dP there, [x1 y1 z1 x2 ...], N/m

    @property
    def rows(self) -> int:
        return 3 * len(self.ids)


def coupled_points(scene, topo) -> tuple[CoupledPoints, ...]:
    """The Coupled points of the scene's MoorDyn moorings. With coupled = "body" the file's
    coordinates are in the body's frame (MoorDyn's axes, origin at its CoG at rest), else
    global (MoorDyn's frame: z up, origin on the still-water level above the scene's)."""
    out = []
    for m in (m for m in scene.moorings if m.kind == "moordyn"):
        data = read_moordyn(m.file, f"{scene.path}: mooring '{m.name}'.file")
        points = np.array([p.position for p in data.coupled]).T * TO_MOORDYN[:, None]
        if m.coupled == "body":
            points = points + np.asarray(scene.body(m.body).cog, float)[:, None]
        local = points - np.asarray(topo.origin(m.body), float)[:, None]
        statics = mooring_statics(scene, m, points)
        out.append(CoupledPoints(m.name, m.body, tuple(p.id for p in data.coupled), points,
                                 local, statics.force, statics.stiffness))
    return tuple(out)


def moordyn_names(groups) -> list[str]:
    """Disturbance names of the MoorDyn rows, in w's order."""
    return [f"w__moordyn_{g.mooring}_{i}_{axis}" for g in groups for i in g.ids for axis in "xyz"]


def moordyn_loads(topo, q, s, rows, groups):
    """(generalised force of the lines' quasi-static part F_lin, that of the point forces in
    `rows` (MoorDyn's remainder), power of both into the bodies (W))."""
    tree, power, start = topo.tree, 0, 0
    static, remainder = ca.SX.zeros(tree.n_s), ca.SX.zeros(tree.n_s)
    for g in groups:
        k = topo.body_index(g.body)
        points = [tree.point(q, k, g.local[:, j]) for j in range(len(g.ids))]
        moved = ca.vertcat(*points) - ca.DM(g.rest.T.ravel())
        linear = ca.DM(g.pull.T.ravel()) + ca.mtimes(ca.DM(g.stiffness), moved)
        for j in range(len(g.ids)):
            quasi_static, force = linear[3 * j:3 * j + 3], rows[start:start + 3]
            start += 3
            static += tree.point_force(q, k, g.local[:, j], quasi_static)
            remainder += tree.point_force(q, k, g.local[:, j], force)
            power += ca.dot(quasi_static + force, tree.point_velocity(q, s, k, g.local[:, j]))
    return static, remainder, power


def moored_rest(scene, f, sizes, p0) -> np.ndarray:
    """The state where the plant's loads balance with the lines' pull (s = chi = u = w = 0),
    by Newton's method on the accelerations over q from the scene's pose; said, and SceneError
    when it does not converge. sizes = (n_q, n_s, nx, nu, nw); f the plant's f."""
    from ..errors import SceneError
    n_q, n_s, nx, nu, nw = sizes
    q = ca.MX.sym("q", n_q)
    x = ca.vertcat(q, ca.DM.zeros(nx - n_q))
    acceleration = f(x, ca.DM.zeros(nu), ca.DM.zeros(nw), ca.DM(p0))[n_q:n_q + n_s]
    newton = ca.Function("newton", [q], [acceleration, ca.jacobian(acceleration, q)])
    rest = np.zeros(nx)
    for _ in range(30):
        a, J = (np.asarray(v) for v in newton(rest[:n_q]))
        if np.max(np.abs(a), initial=0.0) <= REST_TOL:
            return rest
        rest[:n_q] -= np.linalg.lstsq(J, a.ravel(), rcond=None)[0]
    raise SceneError(f"{scene.path}: no rest with the MoorDyn lines' pull: Newton's method "
                     f"leaves accelerations of {np.max(np.abs(a)):.3g} (m/s^2 or rad/s^2) "
                     f"after 30 steps; the lines may pull the body over (check the fairleads' "
                     f"positions and the lines' lengths)")


def say_moored_rest(scene, names, rest) -> dict:
    """{coordinate: its value at the moored rest (m or rad)} for those it moves, said once."""
    moved = {n: float(v) for n, v in zip(names, rest) if abs(v) > 1e-9}
    if moved:
        turning = ("Roll", "Pitch", "Yaw")
        said = ", ".join(f"{n} {math.degrees(v):+.3g} deg" if n.endswith(turning)
                         or _revolute(scene, n) else f"{n} {v:+.3g} m" for n, v in moved.items())
        say_once(f"{scene.name}: the MoorDyn lines' pull moves rest from the scene's pose to "
                 f"{said}; runs start there, and linear models are taken there")
    return moved


def _revolute(scene, coordinate: str) -> bool:
    return any(j.name == coordinate.split("__")[0] and j.type == "revolute"
               for j in scene.joints)


def kinematics_function(plant) -> ca.Function:
    """Function x -> (P, V): the Coupled points' n-frame positions (m) and velocities (m/s),
    (3, n) each, all moorings in w's order."""
    tree, topo = plant.topology.tree, plant.topology
    x = ca.SX.sym("x", plant.nx)
    q, s = x[:tree.n_q], x[tree.n_q:tree.n_q + tree.n_s]
    positions, velocities = [], []
    for g in plant.moordyn:
        k = topo.body_index(g.body)
        for j in range(len(g.ids)):
            positions.append(tree.point(q, k, g.local[:, j]))
            velocities.append(tree.point_velocity(q, s, k, g.local[:, j]))
    return ca.Function("moordyn_points", [x], [ca.horzcat(*positions), ca.horzcat(*velocities)],
                       ["x"], ["P", "V"])
