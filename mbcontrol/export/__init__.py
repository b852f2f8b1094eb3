"""Controllers and plants leaving Python: generated C and FMI 2.0 co-simulation FMUs.

`export_controller(controller, plant, DIR)` writes the controller as self-contained C (DIR/c/:
sources, a documented header, a Makefile, the built library) and as an FMU; `export_plant`
writes the plant (with its wave) as an FMU; `CController` runs an exported library from
Python as a Controller; `checks` closes the loop with both and times the C step.
"""
from .checks import closed_loop_check, footprint, step_timing
from .controller import ExportedController, export_controller
from .plant import export_plant
from .runtime import CController, force_error, step_statistics
from .spec import ControllerSpec, controller_spec

__all__ = ["ExportedController", "export_controller", "CController", "force_error",
           "step_statistics", "ControllerSpec", "controller_spec", "closed_loop_check", "footprint",
           "step_timing", "export_plant"]
