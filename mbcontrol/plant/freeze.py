"""Frozen DOFs: a scene with DOFs removed (as a rig blocks them, or as the waves cannot excite
them) and the evidence for freezing a free joint's DOFs in given waves."""
from __future__ import annotations

import dataclasses

import numpy as np

from .. import defaults
from ..errors import FidelityError
from ..lti import frequency_response, phasor
from ..scene import DOF_NAMES, Scene
from ..waves import Wave
from .jacobians import jacobians
from .process import ProcessPlant

# FREEZE_THRESHOLD: the default "fidelity.freeze_threshold" (1e-3: excitation and linear
# response below this share of the largest of their unit class: the DOF contributes < 0.1 %
# to any compared signal)
ROTATIONS = ("Roll", "Pitch", "Yaw")


def frozen_scene(scene: Scene, dofs) -> Scene:
    """The scene with DOFs removed: "<body>__<Dof>" from free/composite joints, or a one-DOF
    (revolute or prismatic) joint by its name, as a test rig blocks a DOF.

    A joint left with no DOF becomes a fixed joint. Raises FidelityError for a DOF that no
    free joint moves, or whose removal would leave a PTO, friction or end stop without its joint.
    """
    if not dofs:
        return scene
    joints = {j.child: j for j in scene.joints}
    by_name = {j.name: j for j in scene.joints}
    removed = set()
    for dof in dofs:
        if "__" not in dof and dof in by_name and by_name[dof].type in ("revolute", "prismatic"):
            removed.add(f"{by_name[dof].child}__{by_name[dof].name}")
            continue
        body, _, name = dof.partition("__")
        joint = joints.get(body)
        if joint is None or joint.type != "free" or name not in joint.dofs:
            have = [f"{j.child}__{d}" for j in scene.joints if j.type == "free" for d in j.dofs]
            have += [j.name for j in scene.joints if j.type in ("revolute", "prismatic")]
            raise FidelityError(f"{scene.path}: Fidelity.freeze: {dof!r} is not a DOF of a free "
                                f"or composite joint nor a revolute or prismatic joint; expected "
                                f"some of {have or 'none (the scene has no movable joint)'}")
        removed.add(dof)
    users = {j.name: [x.name for x in (*scene.ptos, *scene.frictions, *scene.end_stops)
                      if getattr(x, "joint", None) == j.name] for j in scene.joints}
    friction_names = {fr.name for fr in scene.frictions}    # a blocked joint's friction goes
    new = []
    for joint in scene.joints:
        if joint.type in ("revolute", "prismatic"):
            gone = f"{joint.child}__{joint.name}" in removed
            keep = () if gone else None
        else:
            keep = tuple(d for d in joint.dofs if f"{joint.child}__{d}" not in removed)
            keep = None if keep == joint.dofs else keep
        if keep is None:
            new.append(joint)
        elif not keep:
            acting = [n for n in users[joint.name]
                      if joint.type == "free" or n not in friction_names]
            if acting:
                raise FidelityError(f"{scene.path}: Fidelity.freeze removes every DOF of joint "
                                    f"'{joint.name}', which {acting} act on")
            new.append(dataclasses.replace(joint, type="fixed", dofs=()))
        else:
            new.append(dataclasses.replace(joint, dofs=keep))
    frictions = tuple(fr for fr in scene.frictions
                      if not any(j.name == fr.joint and j.type == "fixed" for j in new))
    return dataclasses.replace(scene, joints=tuple(new), frictions=frictions)


def freeze_report(plant: ProcessPlant, waves, threshold: float | None = None) -> dict:
    """Which free-joint DOFs the waves cannot move, with the evidence, per body DOF.

    For each DOF of a free/composite joint: `excitation`, the RMS wave load on it (N or N m)
    over the waves' components relative to the largest of the same unit class (forces or
    moments) on any hydro DOF; and `response`, the RMS of its linear response (the plant
    linearised at rest, driven by the whole excitation, so DOFs moved through coupling count)
    relative to the largest body motion of its class (m or rad). frozen = both < threshold
    (left out: the default "fidelity.freeze_threshold", 1e-3).
    The largest over the waves is kept. A DOF excited only parametrically (nonlinearly) is not
    caught here: `auto` checks the frozen model against the full one in simulation.
    """
    waves = as_wave_list(waves)
    threshold = defaults.resolve("fidelity.freeze_threshold", threshold)
    dofs = [(f"{j.child}__{d}") for j in plant.scene.joints if j.type == "free" for d in j.dofs]
    bodies = [f"{b}__{d}" for b in plant.topology.bodies for d in DOF_NAMES]
    excitation, response = np.zeros(len(dofs)), np.zeros(len(dofs))
    for wave in waves:
        rms_w, rms_y = _linear_rms(plant, wave, bodies)
        hydro = list(plant.hydro.dofs) if plant.hydro else []
        for k, dof in enumerate(dofs):
            force = rms_w[hydro.index(dof)] if dof in hydro else 0.0
            excitation[k] = max(excitation[k], _relative(force, dof, dict(zip(hydro, rms_w))))
            response[k] = max(response[k], _relative(rms_y[bodies.index(dof)], dof,
                                                     dict(zip(bodies, rms_y))))
    return {d: {"excitation": float(e), "response": float(r),
                "frozen": bool(e < threshold and r < threshold), "threshold": threshold}
            for d, e, r in zip(dofs, excitation, response)}


def _relative(value, dof, table) -> float:
    """value over the largest entry of the same unit class (rotation or not) in table."""
    rotation = dof.split("__")[1] in ROTATIONS
    scale = max((v for d, v in table.items() if (d.split("__")[1] in ROTATIONS) == rotation),
                default=0.0)
    return float(value / scale) if scale > 0 else 0.0


def _linear_rms(plant, wave, outputs):
    """RMS excitation per hydro DOF, and RMS linear response of `outputs`, to one wave."""
    n_w = len(plant.disturbances)
    if n_w == 0:
        return np.zeros(0), np.zeros(len(outputs))
    hydro = plant.hydro
    F = hydro.excitation_at(wave.omega, wave.direction) * wave.amplitude[:, None]           # (m, n_w)
    rms_w = np.sqrt(0.5 * np.sum(np.abs(F) ** 2, axis=0))
    A, _, Bw, C, _, Dw = (np.asarray(M) for M in jacobians(plant)(
        plant.x0(), np.zeros(len(plant.inputs)), np.zeros(n_w), plant.p0))
    rows = [plant.outputs.index(o) for o in outputs]
    G = frequency_response(A, Bw, C[rows], Dw[rows], wave.omega)    # exp(+i w t) phasors
    y = np.einsum("omw,wm->wo", G, phasor(F))
    return rms_w, np.sqrt(np.sum(0.5 * np.abs(y) ** 2, axis=0))


def as_wave_list(waves) -> list[Wave]:
    if waves is None:
        return []
    return [waves] if isinstance(waves, Wave) else list(waves)
