"""From a Scene's joints to the multibody core's links, in parents-first order.

Every body frame has its origin at the body's joint point and is aligned with the n-frame at
q = 0. A free joint restricted to some DOFs becomes a composite joint: translations along the
n-frame axes, then rotations in yaw-pitch-roll order (ZYX, as the Euler angles of a 6-DOF
free joint), one coordinate each.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import DOF_NAMES, Scene
from .tree import Link, Motion, Tree

_UNIT = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_TRANSLATIONS = (("Surge", "x"), ("Sway", "y"), ("Heave", "z"))
_ROTATIONS = (("Yaw", "z"), ("Pitch", "y"), ("Roll", "x"))


@dataclass(frozen=True)
class Topology:
    """The tree of a scene, with index maps used when assembling loads."""
    tree: Tree
    bodies: tuple[str, ...]              # scene body names in tree (parents-first) order
    joint_of_body: dict                  # body name -> scene Joint
    coordinate_of_joint: dict            # one-coordinate joint name -> index into q (and s)

    def body_index(self, name: str) -> int:
        return self.bodies.index(name)

    def origin(self, name: str) -> np.ndarray:
        """n-frame position at rest of the body frame's origin (its joint point), m."""
        return np.asarray(self.joint_of_body[name].point, dtype=float)


def build_topology(scene: Scene) -> Topology:
    joint_of = {j.child: j for j in scene.joints}
    order = _parents_first(scene, joint_of)
    links, coordinate_of_joint, n_coords = [], {}, 0
    for name in order:
        joint, body = joint_of[name], scene.body(name)
        parent_origin = np.zeros(3) if joint.parent == "ground" else \
            np.asarray(joint_of[joint.parent].point, dtype=float)
        motions, free, coord_names = _motions(joint)
        if len(coord_names) == 1:
            coordinate_of_joint[joint.name] = n_coords
        n_coords += 6 if free else len(coord_names)
        links.append(Link(
            name=name,
            parent=-1 if joint.parent == "ground" else order.index(joint.parent),
            joint_point=tuple(np.asarray(joint.point) - parent_origin),
            cog=tuple(np.asarray(body.cog) - np.asarray(joint.point)),
            mass=body.mass, inertia=np.array(body.inertia),
            motions=motions, free=free, coordinate_names=coord_names))
    return Topology(Tree(links), tuple(order), joint_of, coordinate_of_joint)


def _motions(joint):
    if joint.type in ("revolute", "prismatic"):
        return (Motion(joint.type, joint.axis),), False, (joint.name,)
    if joint.type == "fixed":
        return (), False, ()
    names = tuple(f"{joint.name}__{dof}" for dof in DOF_NAMES if dof in joint.dofs)
    if len(joint.dofs) == 6:
        return (), True, names
    motions = [Motion("prismatic", _UNIT[a]) for d, a in _TRANSLATIONS if d in joint.dofs]
    motions += [Motion("revolute", _UNIT[a]) for d, a in _ROTATIONS if d in joint.dofs]
    ordered = [f"{joint.name}__{d}" for d, _ in _TRANSLATIONS + _ROTATIONS if d in joint.dofs]
    if len(ordered) == 1:
        ordered = [joint.name]          # a one-DOF free joint is named after the joint
    return tuple(motions), False, tuple(ordered)


def _parents_first(scene: Scene, joint_of: dict) -> list[str]:
    order: list[str] = []
    pending = [b.name for b in scene.bodies]
    while pending:
        for name in list(pending):
            parent = joint_of[name].parent
            if parent == "ground" or parent in order:
                order.append(name)
                pending.remove(name)
    return order
