"""Writing an exported controller: C sources with a documented header, a Makefile, the built
shared library, and the FMI 2.0 co-simulation FMU (modelDescription.xml, the sources, the
binary for this platform). Everything is written to a temporary folder and renamed into place,
so an interrupted export leaves the old one or none.

Every name or text from a scene or a plant passes `mbcontrol.textsafe` on its way into C,
XML or a Makefile, even though the scene's name rule already refuses hostile names: an
export is code that a compiler runs and a library that ctypes loads."""
from __future__ import annotations

import hashlib
import math
import platform
import subprocess
import zipfile
from datetime import datetime, timezone
from importlib import resources
from pathlib import Path

import casadi as ca
import numpy as np

from ..textsafe import c_comment, c_identifier, c_string, make_word, xml_attr
from .spec import ControllerSpec

CFLAGS = ("-O3", "-std=c99", "-fPIC", "-Wall", "-Wno-unused-variable", "-Wno-unused-function")
ENGINE_COMMON = ["mbc_bench.c"]
FMU_FILES = ["fmu_common.h", "mbc_fmi2.h"]
HEADERS = ["mbc_qp.h"]


def csrc(name: str) -> str:
    """The text of a hand-written C file shipped with the package."""
    return resources.files("mbcontrol.export").joinpath("csrc", name).read_text()


def c_number(value: float) -> str:
    value = float(value)
    if math.isnan(value):
        return "NAN"
    if math.isinf(value):
        return "INFINITY" if value > 0 else "-INFINITY"
    return repr(value)


def c_array(ctype: str, name: str, values) -> str:
    flat = np.asarray(values, dtype=float if ctype == "double" else int).ravel()  # row-major
    body = ", ".join(c_number(v) if ctype == "double" else str(int(v)) for v in flat) or "0"
    return f"const {ctype} {name}[{max(flat.size, 1)}] = {{{body}}};\n"


def identifier(model: str, name: str) -> str:
    """A C identifier (and file stem) for the export: <model>_<controller> as it is when it is
    one, else mapped by `textsafe.c_identifier` (other characters as '_', a hash appended)."""
    return c_identifier(f"{model}_{name}")


def header(spec: ControllerSpec, ident: str) -> str:
    """mbc_controller.h: the documented fixed-size API of one exported controller. Names,
    units and descriptions enter the comment through `c_comment` (one line, no '*/')."""
    ident = c_identifier(ident)          # unchanged when it came from `identifier`
    lines = [f"/* {ident}: the {c_comment(spec.name)} controller exported by mbcontrol.",
             " *",
             " * Call init(ctx, params) once (params NULL: the designed values below), then",
             " * step(ctx, measurements, t, force) at every sample of the control loop, t in s",
             " * increasing; step returns 0, or nonzero on a failure (the force is then not set).",
             " * reset(ctx) restarts the controller with the same parameters. The context holds",
             " * every state; nothing is allocated, nothing is global. Do not move a context after",
             " * init (it points into itself).",
             " *",
             " * measurements (SI units, as mbcontrol names them):"]
    lines += [f" *   [{i}] {c_comment(n)}" for i, n in enumerate(spec.inputs)]
    lines += [" * force (N or N m, the PTO's whole force command):"]
    lines += [f" *   [{i}] {c_comment(n)}" for i, n in enumerate(spec.outputs)]
    lines += [" * params:"]
    lines += [f" *   [{i}] {c_comment(p.name)} = {p.value!r} {c_comment(p.unit)}: "
              f"{c_comment(p.description)}"
              for i, p in enumerate(spec.parameters)]
    lines += [" */", "#ifndef MBC_CONTROLLER_H", "#define MBC_CONTROLLER_H", ""]
    lines += ["#include <math.h>"]
    lines += [f'#include "{name}"' for name in spec.headers]   # csrc files, named by the spec
    if spec.casadi:
        lines += ["#ifndef casadi_int", "#define casadi_int long long int", "#endif",
                  "#ifndef casadi_real", "#define casadi_real double", "#endif"]
    lines += ["", f"#define MBC_PREFIX {ident}_", "#define MBC_CAT2(a, b) a##b",
              "#define MBC_CAT(a, b) MBC_CAT2(a, b)", "#define MBC_FN(name) MBC_CAT(MBC_PREFIX, name)",
              f"#define MBC_CTX {ident}_ctx", f"#define MBC_N_IN {len(spec.inputs)}",
              f"#define MBC_NU {len(spec.outputs)}", f"#define MBC_N_PARAMS {len(spec.parameters)}",
              f"#define MBC_GUID {c_string(guid(spec, ident))}"]
    for key, value in spec.defines.items():
        if key != "MBC_NU":
            lines.append(f"#define {key} {value}")
    lines += ["", "#define MBC_PARAMS_DESIGNED MBC_CAT(MBC_PREFIX, params_designed)",
              "extern const double MBC_PARAMS_DESIGNED[];"]
    for name, (ctype, _) in spec.arrays.items():
        lines += [f"#define {name} MBC_CAT(MBC_PREFIX, {name[4:]})",
                  f"extern const {ctype} {name}[];"]
    lines += list(spec.declarations)          # the engine's own types and tables
    for fun in spec.casadi:
        lines += [f"int {ident}_{fun.name()}(const casadi_real **arg, casadi_real **res, "
                  f"casadi_int *iw, casadi_real *w, int mem);"]
    lines += ["", f"typedef struct {{\n    {spec.context}\n}} {ident}_ctx;", "",
              f"int {ident}_init({ident}_ctx *ctx, const double *params);",
              f"void {ident}_reset({ident}_ctx *ctx);",
              f"int {ident}_step({ident}_ctx *ctx, const double *measurements, double t, "
              f"double *force);",
              "/* timing: steps through rows of measurements, each step's wall time in ns and "
              "(cpu_ns not NULL) its thread CPU time in ns */",
              f"int {ident}_bench({ident}_ctx *ctx, const double *measurements, int rows, "
              f"const double *t, double *force, double *ns, double *cpu_ns);",
              f"int {ident}_ctx_size(void);", "", "#endif", ""]
    return "\n".join(lines)


def data_source(spec: ControllerSpec, ident: str) -> str:
    out = ['/* constant data of the exported controller (generated by mbcontrol) */',
           '#include "mbc_controller.h"', ""]
    out.append(c_array("double", "MBC_PARAMS_DESIGNED", [p.value for p in spec.parameters]))
    for name, (ctype, values) in spec.arrays.items():
        out.append(c_array(ctype, name, values))
    out += list(spec.tables)
    return "\n".join(out)


def guid(spec: ControllerSpec, ident: str) -> str:
    digest = hashlib.sha256(repr((ident, spec.kind, spec.inputs, spec.outputs,
                                  [(p.name, p.value) for p in spec.parameters],
                                  {k: np.asarray(v[1]).tobytes() for k, v in spec.arrays.items()},
                                  spec.defines)).encode()).hexdigest()
    return f"{{{digest[:8]}-{digest[8:12]}-{digest[12:16]}-{digest[16:20]}-{digest[20:32]}}}"


def write_sources(spec: ControllerSpec, ident: str, folder: Path) -> list[Path]:
    """The C sources of the controller (no FMU wrapper) in `folder`; returns the .c files."""
    ident = c_identifier(ident)          # unchanged when it came from `identifier`
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "mbc_controller.h").write_text(header(spec, ident))
    (folder / "mbc_data.c").write_text(data_source(spec, ident))
    sources = [folder / "mbc_data.c"]
    for fun in spec.casadi:
        renamed = ca.Function(f"{ident}_{fun.name()}", fun.sx_in(), fun.call(fun.sx_in()))
        generated = generate_casadi([renamed], folder, f"{ident}_{fun.name()}.c")
        sources.append(generated)
    for name in spec.engine + ENGINE_COMMON:
        (folder / name).write_text(csrc(name))
        sources.append(folder / name)
    for name in HEADERS:
        (folder / name).write_text(csrc(name))
    (folder / "Makefile").write_text(makefile(ident, [s.name for s in sources]))
    return sources


def generate_casadi(functions, folder: Path, filename: str) -> Path:
    """CasADi's C code of `functions` in folder/filename (CasADi's own generator)."""
    generator = ca.CodeGenerator(filename, {"with_header": False})
    for fun in functions:
        generator.add(fun)
    generator.generate(str(folder) + "/")
    return folder / filename


def makefile(ident: str, sources: list[str]) -> str:
    """The Makefile of the C sources: one rule for lib<ident>.so and `clean`. Every word from
    outside passes `make_word` (unchanged for an identifier and the generated file names)."""
    library = make_word(f"lib{ident}.so")
    files = " ".join(make_word(s) for s in sources)
    return (f"# Builds {library} from the generated sources (no Python needed).\n"
            f"CC ?= gcc\nCFLAGS ?= {' '.join(CFLAGS)}\n\n"
            f"{library}: {files} mbc_controller.h\n"
            f"\t$(CC) $(CFLAGS) -shared -o $@ {files} -lm\n\n"
            f"clean:\n\trm -f {library}\n")


def compile_library(sources: list[Path], target: Path, extra_flags=()) -> None:
    from mbcontrol.sim import compiler
    cc = compiler()
    if cc is None:
        raise RuntimeError("export: no C compiler found ($CC, gcc or cc); the sources are "
                           "written, the library and the FMU need one")
    cmd = [cc, *CFLAGS, *extra_flags, "-shared", "-o", str(target), *map(str, sources), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=sources[0].parent)
    if done.returncode != 0:
        raise RuntimeError(f"export: compiling {target.name} failed:\n{done.stderr[-3000:]}")


def platform_folder() -> str:
    system = {"Linux": "linux", "Darwin": "darwin", "Windows": "win"}.get(platform.system(),
                                                                          "linux")
    return f"{system}{64 if platform.architecture()[0] == '64bit' else 32}"


def zip_fmu(staging: Path, target: Path) -> None:
    """Zip a staged FMU folder into `target` atomically."""
    from mbcontrol.atomic import atomic_path
    with atomic_path(target) as tmp:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            for path in sorted(staging.rglob("*")):
                if path.is_file():
                    z.write(path, path.relative_to(staging).as_posix())


def variable(name, vr, causality, variability, description, start=None, initial=None) -> str:
    """One ScalarVariable of modelDescription.xml; every attribute value through `xml_attr`
    (saxutils.escape leaves quotes alone, which ends an attribute)."""
    attrs = (f'name="{xml_attr(name)}" valueReference="{int(vr)}" '
             f'causality="{xml_attr(causality)}" variability="{xml_attr(variability)}"'
             + (f' initial="{xml_attr(initial)}"' if initial else "")
             + f' description="{xml_attr(description)}"')
    real = "<Real/>" if start is None else f'<Real start="{_xml_number(start)}"/>'
    return f"    <ScalarVariable {attrs}>{real}</ScalarVariable>"


def _xml_number(value: float) -> str:
    value = float(value)
    if math.isinf(value):
        return "INF" if value > 0 else "-INF"
    return repr(value)


def model_description(ident: str, guid_text: str, description: str, variables: list[str],
                      output_indices: list[int], step: float) -> str:
    """modelDescription.xml of an FMI 2.0 co-simulation FMU; `variables` from `variable`."""
    ident, guid_text = xml_attr(c_identifier(ident)), xml_attr(guid_text)
    now = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    from importlib.metadata import PackageNotFoundError, version
    try:
        __version__ = version("mbcontrol")
    except PackageNotFoundError:
        __version__ = "unknown"
    outputs = "\n".join(f'      <Unknown index="{int(i)}"/>' for i in output_indices)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="{ident}" guid="{guid_text}"
  description="{xml_attr(description)}" generationTool="mbcontrol {xml_attr(__version__)}"
  generationDateAndTime="{now}" variableNamingConvention="structured" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="{ident}" canHandleVariableCommunicationStepSize="true"
    canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="false"
    canGetAndSetFMUstate="false" canSerializeFMUstate="false"
    providesDirectionalDerivative="false"/>
  <DefaultExperiment startTime="0.0" stepSize="{_xml_number(step)}"/>
  <ModelVariables>
{chr(10).join(variables)}
  </ModelVariables>
  <ModelStructure>
    <Outputs>
{outputs}
    </Outputs>
    <InitialUnknowns>
{outputs}
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""
