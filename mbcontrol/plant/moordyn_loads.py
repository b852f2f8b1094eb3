"""Where MoorDyn's lines act on the plant: the forces at each Coupled point, as rows of w.

MoorDyn has its own state and time step, so it is not part of the symbolic plant
(../shared/DESIGN.md): the plant takes the force on each Coupled point (n-frame, N) as three
rows of the disturbance w ("w__moordyn_<mooring>_<point id>_<x|y|z>", after the excitation and
the wave field's rows), applies it at the point on its body, and reports its power
("mooring_power", W, for the energy audit). `mbcontrol.sim.moordyn` steps MoorDyn with the
points' positions and velocities (`kinematics_function`) and fills those rows. In the symbolic
plant they are inputs like the excitation: zero in linearisation and frequency analysis.
"""
from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ..scene import TO_MOORDYN, read_moordyn


@dataclass(frozen=True)
class CoupledPoints:
    """The Coupled points of one MoorDyn mooring, in file order."""
    mooring: str
    body: str
    ids: tuple[int, ...]
    rest: np.ndarray            # (3, n) n-frame positions at rest, m
    local: np.ndarray           # (3, n) the same from the body's frame origin, body axes, m

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
        out.append(CoupledPoints(m.name, m.body, tuple(p.id for p in data.coupled), points,
                                 local))
    return tuple(out)


def moordyn_names(groups) -> list[str]:
    """Disturbance names of the MoorDyn rows, in w's order."""
    return [f"w__moordyn_{g.mooring}_{i}_{axis}" for g in groups for i in g.ids for axis in "xyz"]


def moordyn_loads(topo, q, s, rows, groups):
    """(generalised force, power into the bodies (W)) of the point forces in `rows`."""
    tree, tau, power, start = topo.tree, ca.SX.zeros(topo.tree.n_s), 0, 0
    for g in groups:
        k = topo.body_index(g.body)
        for j in range(len(g.ids)):
            force = rows[start:start + 3]
            start += 3
            tau += tree.point_force(q, k, g.local[:, j], force)
            power += ca.dot(force, tree.point_velocity(q, s, k, g.local[:, j]))
    return tau, power


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
