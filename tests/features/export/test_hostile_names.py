"""Hostile names through the export writers, with the scene's name rule bypassed (a plant
built from a Scene edited in Python, specs and writers called directly), so the escapes of
`mbcontrol.textsafe` are what is tested: the header preprocessed by gcc holds no directive
from a name, the library still builds (by its own Makefile too) and runs through ctypes, the
Makefile has no rule but its own, modelDescription.xml parses and gives the names back, and
every CasADi Function named after a scene or plant name is created."""
from __future__ import annotations

import dataclasses
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile

import casadi as ca
import numpy as np
import pytest

from mbcontrol.controllers import make
from mbcontrol.export import CController, controller_spec, export_controller, export_plant
from mbcontrol.export.build import header, identifier, makefile, model_description, variable
from mbcontrol.plant import CatenaryLine, build_plant
from mbcontrol.scene import load_scene

ISSUE = 'pto*/\n#include\t"/some/file"\n/*'           # the issue's PTO name
SCENE_NAME = "sph*/\n#define EVIL 1\n/*\"'<&>$(shell touch pwned)"
HOSTILE = [ISSUE, SCENE_NAME, "*/", '"', "'", "<&>", "$(shell touch pwned)", "a\tb", "nul\x00",
           "cr\r", "é漢\u202e", "??/", "back\\", "x" * 10_000]


def _gcc() -> str:
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    return cc


def _directives(text: str, folder) -> list[str]:
    """The directives gcc -E finds in a header's own text (-dD keeps #defines, -dI
    #includes; the linemarkers say which file each comes from), the system headers out of the
    way (-nostdinc, an empty math.h standing in)."""
    (folder / "stub").mkdir(exist_ok=True)
    (folder / "stub" / "math.h").write_text("")
    (folder / "probe.h").write_text(text)
    done = subprocess.run([_gcc(), "-std=c99", "-E", "-dD", "-dI", "-nostdinc", "-I",
                           str(folder / "stub"), "-x", "c", str(folder / "probe.h")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    own, current = [], ""
    for line in done.stdout.splitlines():
        marker = re.match(r'# \d+ "(.*)"', line)
        if marker:
            current = marker.group(1)
        elif line.startswith("#") and current.endswith("probe.h"):
            own.append(line)
    return own


HEADER_DIRECTIVES = ("#define MBC_", "#define casadi_", "#include <math.h>")


@pytest.fixture(scope="module")
def plant():
    """The catalogue sphere with a hostile scene name and the issue's PTO name (the name rule
    would refuse both at load; replace() goes round it)."""
    scene = load_scene("sphere")
    scene = dataclasses.replace(scene, name=SCENE_NAME, ptos=tuple(
        dataclasses.replace(p, name=ISSUE) for p in scene.ptos))
    return build_plant(scene)


@pytest.fixture(scope="module")
def exported(plant, tmp_path_factory):
    return export_controller(make("passive", damping=5e4), plant, tmp_path_factory.mktemp("c"))


def _xml(fmu) -> ET.Element:
    with zipfile.ZipFile(fmu) as z:
        return ET.fromstring(z.read("modelDescription.xml"))


def test_the_header_compiles_no_directive_from_a_name(exported, tmp_path):
    text = (exported.c_folder / "mbc_controller.h").read_text()
    assert text.isascii()
    own = _directives(text, tmp_path)
    assert own and all(d.startswith(HEADER_DIRECTIVES) for d in own), own


def test_the_library_builds_by_its_makefile_and_runs(exported, plant, tmp_path):
    if shutil.which("make") is None:
        pytest.skip("no make")
    rules = re.findall(r"^([^\s#][^:=]*):(?!=)", (exported.c_folder / "Makefile").read_text(), re.M)
    assert rules == [f"lib{exported.ident}.so", "clean"]
    folder = shutil.copytree(exported.c_folder, tmp_path / "c")
    done = subprocess.run(["make", "-B", "-s"], cwd=folder, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert not (folder / "pwned").exists()
    controller = CController.from_export(exported)
    controller.reset(plant)                            # the hostile names match the plant's
    y = np.zeros(len(plant.outputs))
    y[plant.outputs.index(f"{ISSUE}__velocity")] = 0.5
    # the passive law: force = -damping * velocity (N, m/s)
    assert controller(0.0, y)[0] == pytest.approx(-5e4 * 0.5)


def test_the_controller_fmu_gives_the_names_back(exported):
    root = _xml(exported.fmu)
    names = [v.get("name") for v in root.iter("ScalarVariable")]
    assert f"{ISSUE}__velocity" in names and f"u__{ISSUE}" in names
    assert f"damping_{ISSUE}" in names
    described = {v.get("name"): v.get("description") for v in root.iter("ScalarVariable")}
    assert ISSUE in described[f"damping_{ISSUE}"]
    assert root.get("modelName") == exported.ident
    assert re.fullmatch(r"[A-Za-z](?:_?[A-Za-z0-9])*", exported.ident)


def test_the_plant_fmu_gives_the_names_back(plant, tmp_path):
    root = _xml(export_plant(plant, None, tmp_path, dt=0.05))
    names = [v.get("name") for v in root.iter("ScalarVariable")]
    assert f"u__{ISSUE}" in names and f"{ISSUE}__position" in names
    assert SCENE_NAME in root.get("description")
    assert not (tmp_path / "pwned").exists()


@pytest.mark.parametrize("text", HOSTILE, ids=[f"hostile{i}" for i in range(len(HOSTILE))])
def test_each_writer_holds_each_hostile_text(plant, tmp_path, text):
    """The writers themselves, called with hostile text where names, units, descriptions and
    the identifier go: header (gcc -E), Makefile (its rules), XML (parsed, given back)."""
    spec = controller_spec(make("passive", damping=5e4), plant)
    spec.name, spec.inputs, spec.outputs = text, [text], [text]
    spec.parameters = [dataclasses.replace(p, name=text, unit=text, description=text)
                       for p in spec.parameters]
    own = _directives(header(spec, text), tmp_path)
    assert own and all(d.startswith(HEADER_DIRECTIVES) for d in own), own

    rules = re.findall(r"^([^\s#][^:=]*):(?!=)", makefile(text, [f"{text}.c"]), re.M)
    assert len(rules) == 2 and rules[1] == "clean" and "\n" not in rules[0]

    doc = model_description(text, text, text, [variable(text, 0, "input", "continuous", text,
                                                        start=0.0)], [1], 0.01)
    root = ET.fromstring(doc.encode())
    kept = re.sub("[\x00-\x08\x0b\x0c\x0e-\x1f]", lambda m: ascii(m.group())[1:-1], text)
    (var,) = root.iter("ScalarVariable")
    assert var.get("name") == var.get("description") == root.get("description") == kept
    assert root.get("guid") == kept


@pytest.mark.parametrize("text", HOSTILE, ids=[f"hostile{i}" for i in range(len(HOSTILE))])
def test_casadi_functions_take_names_made_from_any_text(text):
    """The export's identifier (model_controller, then joined to "law") and a catenary
    mooring's force Function: CasADi refuses a name that is no identifier (or holds '__')."""
    x = ca.SX.sym("x")
    ca.Function(f"{identifier(text, 'passive')}_law", [x], [x])
    line = CatenaryLine(name=text, anchor=(120.0, 0.0, 50.0), fairlead=(0.0, 0.0, 5.0),
                        length=140.0, EA=5e8, weight=1e3)
    force = line._function(line._table(6), 1)
    assert force.name().startswith("mooring_")
