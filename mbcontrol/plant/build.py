"""build_plant: the process plant of a scene, full or at a chosen fidelity."""
from __future__ import annotations

from ..hydro import HydroModel
from ..scene import Scene
from .fidelity import Fidelity, FidelityError, plant_for
from .process import ProcessPlant, assemble_plant


def build_plant(scene: Scene | str, hydro: HydroModel | None = None, *,
                radiation_tol: float | None = None, radiation: bool = True,
                fidelity: Fidelity | None = None, hydro_corrections: bool = False) -> ProcessPlant:
    """Assemble the process plant of a scene (a Scene, a scene file or a catalogue name).

    Hydrodynamics come from `hydro` or the scene's hydro.file; the radiation model is fitted
    to `radiation_tol` (default: the scene's) on the DOFs the joints can move. With
    radiation=False the plant has no radiation states: w is then the whole wave load on the
    hydro DOFs (excitation minus radiation memory), as a direct-convolution reference needs.
    fidelity: a mbcontrol.plant.Fidelity (simplified models, e.g.
    mbcontrol.studies.fidelity_auto.auto(...).fidelity); freeze="auto" needs the waves: use
    mbcontrol.plant.plant_for for it. hydro_corrections: scale factors of added mass,
    radiation and excitation per hydro DOF as parameters (see `assemble_plant`).
    """
    if fidelity is None:
        return assemble_plant(scene, hydro, radiation_tol=radiation_tol, radiation=radiation,
                              hydro_corrections=hydro_corrections)
    if radiation_tol is not None or not radiation:
        raise FidelityError("build_plant: give the radiation tolerance as "
                            "Fidelity.radiation_tol, and radiation=False without a fidelity")
    if not isinstance(fidelity, Fidelity):
        raise FidelityError(f"build_plant: fidelity: expected a mbcontrol.plant.Fidelity, "
                            f"got {type(fidelity).__name__}")
    return plant_for(scene, fidelity, hydro=hydro, hydro_corrections=hydro_corrections)
