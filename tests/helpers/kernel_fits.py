"""Catalogue scenes with their radiation fit judged by the kernel's own error instead of the
device's response (``[hydro] fit_judged_by = "kernel"``): for tests whose subject needs the
kernel-judged fit itself (the kernel measure, or a fit with a fast pole to make an integrator
fail where its stability polynomial says), not the catalogue's default."""
from __future__ import annotations

import dataclasses

from mbcontrol.scene import Scene, load_scene


def judged_by_kernel(name: str) -> Scene:
    """The catalogue scene ``name`` with ``[hydro] fit_judged_by = "kernel"``."""
    scene = load_scene(name)
    return dataclasses.replace(scene, hydro=dataclasses.replace(scene.hydro, fit_judged_by="kernel"))
