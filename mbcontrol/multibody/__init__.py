"""Multibody core: joint tree -> P(q), Pdot^T s, M^g, C^g s, generalised forces (ERRATA section 4),
and the topology of a scene (which joint moves which body, the tree's coordinates)."""
from .rotations import H, R_zyx, Rot, S, T_zyx, as_casadi
from .topology import Topology, build_topology
from .tree import FREE_DOF_NAMES, Link, Motion, Tree

__all__ = ["FREE_DOF_NAMES", "H", "Link", "Motion", "R_zyx", "Rot", "S", "T_zyx", "Tree", "as_casadi",
           "Topology", "build_topology"]
