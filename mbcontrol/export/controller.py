"""Export a controller: C sources and library (DIR/c/), and an FMI 2.0 co-simulation FMU."""
from __future__ import annotations

import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..sim import period_of
from .build import (FMU_FILES, compile_library, csrc, guid, identifier, model_description,
                    platform_folder, variable, write_sources, zip_fmu)
from .spec import ControllerSpec, controller_spec


@dataclass
class ExportedController:
    """Where an export went: the C folder, its shared library, the FMU; and its spec."""
    ident: str
    c_folder: Path
    library: Path
    fmu: Path
    spec: ControllerSpec


def export_controller(controller, plant, out_dir, *, model: str | None = None,
                      step: float | None = None) -> ExportedController:
    """Write `controller` (bound to `plant`) as C (out_dir/c/, replacing an earlier export's)
    and as an FMU (out_dir/<model>_<controller>.fmu). step: the FMU's default communication
    step, s (the controller's period, or 0.01 s)."""
    spec = controller_spec(controller, plant)
    ident = identifier(model or plant.name, spec.name)
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    c_final = out_dir / "c"
    staging = Path(tempfile.mkdtemp(prefix=".export.", dir=out_dir))
    try:
        c_dir = staging / "c"
        sources = write_sources(spec, ident, c_dir)
        compile_library(sources, c_dir / f"lib{ident}.so")
        fmu_root = staging / "fmu"
        src = fmu_root / "sources"
        shutil.copytree(c_dir, src, ignore=shutil.ignore_patterns("*.so", "Makefile"))
        for name in FMU_FILES + ["fmu_controller.c"]:
            (src / name).write_text(csrc(name))
        binaries = fmu_root / "binaries" / platform_folder()
        binaries.mkdir(parents=True)
        fmu_sources = [src / s.name for s in sources if s.name != "mbc_bench.c"] + \
            [src / "fmu_controller.c"]
        compile_library(fmu_sources, binaries / f"{ident}.so", ("-fvisibility=hidden",))
        period = period_of(controller)
        (fmu_root / "modelDescription.xml").write_text(
            controller_description(spec, ident, step or period or 0.01, period))
        fmu = out_dir / f"{ident}.fmu"
        zip_fmu(fmu_root, fmu)
        if c_final.exists():
            shutil.rmtree(c_final)
        c_dir.rename(c_final)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return ExportedController(ident, c_final, c_final / f"lib{ident}.so", fmu, spec)


def controller_description(spec: ControllerSpec, ident: str, step: float,
                           period: float | None = None) -> str:
    """The FMU's model description. A controller with a sample `period` (s) states it as the
    constant `sample_period` and in the text; `step` is the DefaultExperiment's stepSize."""
    variables, vr = [], 0
    for name in spec.inputs:
        variables.append(variable(name, vr, "input", "continuous",
                                  "measured signal (SI units)", start=0.0))
        vr += 1
    first_output = len(variables) + 1
    for name in spec.outputs:
        variables.append(variable(name, vr, "output", "discrete",
                                  "PTO force command, N or N m", initial="calculated"))
        vr += 1
    for p in spec.parameters:
        variables.append(variable(p.name, vr, "parameter", "fixed",
                                  f"{p.description} ({p.unit})", start=p.value))
        vr += 1
    if period:
        variables.append(variable("sample_period", vr, "local", "constant",
                                  "the controller's sample period, s: it samples at start + k "
                                  "sample_period (at the first communication point at or after "
                                  "each) and holds its command in between", start=period))
    outputs = list(range(first_output, first_output + len(spec.outputs)))
    timing = (f"It samples every {period!r} s on the grid start + k {period!r} s, at the first "
              f"communication point at or after each sample time, and holds the command in "
              f"between. Use a communication step that divides {period!r} s: any other samples "
              f"up to one step late, which a model-based controller does not expect." if period else
              "It runs at every communication point.")
    text = (f"mbcontrol {spec.name} controller: reads {', '.join(spec.inputs)}; writes the PTO "
            f"force command(s). Set the inputs, then read the outputs, at each communication "
            f"point. {timing}")
    return model_description(ident, guid(spec, ident), text, variables, outputs, step)
