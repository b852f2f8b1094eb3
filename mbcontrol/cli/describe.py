"""`mbcontrol models NAME`: what a model is made of and what can be set, without provoking errors.

Lists the scene's bodies, joints, PTOs (with their limits), hydrodynamics, the plant
parameters (`--param NAME=VALUE` in simulate, design, identify) with their defaults and
units, the scene parameters, the [identify] table, and every controller with its settings
(`--set KEY=VALUE`) and defaults, read from the controller registry itself.
"""
from __future__ import annotations

import inspect
import json
import math

from .. import defaults

_ROTATIONAL_DOFS = ("Roll", "Pitch", "Yaw")


def parameter_unit(plant, name: str) -> str:
    """SI unit of a plant parameter, from the element it belongs to ("-": dimensionless,
    "": not known)."""
    scene = plant.scene
    head, _, tail = name.rpartition("__")
    if tail.endswith("_scale"):
        return "-"
    coordinate = _coordinates(plant)
    for pto in scene.ptos:
        if head == pto.name:
            c = "m" if pto.between_points else coordinate.get(pto.joint, "m")
            return _per(tail, c)
    for friction in scene.frictions:
        if head == friction.name:
            c = coordinate.get(friction.joint, "m")
            force = "N m" if c == "rad" else "N"
            return {"viscous": f"{force} s/{c}", "coulomb": force,
                    "velocity_scale": f"{c}/s"}.get(tail, "")
    for drag in scene.drags:
        if head == drag.name:
            dof = tail.removesuffix("_linear")
            c, force = ("rad", "N m") if dof in _ROTATIONAL_DOFS else ("m", "N")
            return f"{force} s/{c}" if tail.endswith("_linear") else f"{force} s^2/{c}^2"
    for mooring in scene.moorings:
        if head == mooring.name:
            return {"stiffness": "N/m", "damping": "N s/m"}.get(tail.split("_")[0], "")
    return ""


def _per(kind: str, c: str) -> str:
    force = "N m" if c == "rad" else "N"
    return {"damping": f"{force} s/{c}", "stiffness": f"{force}/{c}", "preload": force}.get(kind, "")


def _coordinates(plant) -> dict:
    return {j.name: ("rad" if j.type == "revolute" else "m") for j in plant.scene.joints}


def controller_settings() -> dict:
    """{name: {setting: default (None: required or the scene's)}} from the registry."""
    from mbcontrol.controllers import REGISTRY
    out = {}
    for name, cls in REGISTRY.items():
        out[name] = {k: (None if p.default is inspect.Parameter.empty else p.default)
                     for k, p in inspect.signature(cls).parameters.items()}
    return out


def describe(model: str) -> dict:
    """The JSON of `mbcontrol models NAME --json` (a stable contract): model, file,
    description, bodies, joints, ptos, hydro, parameters {name: {default, unit}},
    scene_parameters, identify, controllers {name: {setting: default}}."""
    from ..plant import build_plant
    from ..scene import load_scene
    scene = load_scene(model)
    plant = build_plant(scene)
    limit = (lambda v: None if v is None or not math.isfinite(v) else v)
    return {
        "model": scene.name, "file": str(scene.path), "description": scene.description,
        "bodies": [{"name": b.name, "mass_kg": b.mass, "hydro": bool(b.hydro)}
                   for b in scene.bodies],
        "joints": [{"name": j.name, "type": j.type, "parent": j.parent, "child": j.child}
                   for j in scene.joints],
        "ptos": [{"name": p.name, "joint": p.joint, "force_max": limit(p.force_max),
                  "stroke_max": limit(p.stroke_max), "efficiency": p.efficiency,
                  **_pto_units(plant, p)} for p in scene.ptos],
        "hydro": None if plant.hydro is None else {
            "source": plant.hydro.source, "dofs": list(plant.hydro.dofs),
            "radiation_states": int(plant.hydro.radiation.order),
            "radiation_tol": scene.hydro.radiation_tol,
            "response_band": scene.hydro.response_band},
        "parameters": {n: {"default": float(v), "unit": parameter_unit(plant, n)}
                       for n, v in zip(plant.parameters, plant.p0)},
        "scene_parameters": dict(scene.parameters),
        "identify": {k: list(v) for k, v in scene.identify.items()},
        "controllers": controller_settings(),
    }


def _pto_units(plant, pto) -> dict:
    """The units of a PTO's force and stroke: N and m, or N m and rad on a revolute joint."""
    rotary = not pto.between_points and _coordinates(plant).get(pto.joint) == "rad"
    return {"force_unit": "N m" if rotary else "N", "stroke_unit": "rad" if rotary else "m"}


def run_describe(args) -> int:
    info = describe(args.name)
    if args.json:
        print(json.dumps(info, indent=2, default=str))
        return 0
    print(f"{info['model']}: {info['description']}\n  file: {info['file']}")
    print("  bodies: " + ", ".join(f"{b['name']} ({b['mass_kg']:.4g} kg"
                                    f"{', hydro' if b['hydro'] else ''})" for b in info["bodies"]))
    print("  joints: " + ", ".join(f"{j['name']} ({j['type']}, {j['parent']} -> {j['child']})"
                                    for j in info["joints"]))
    for p in info["ptos"]:
        force = f"{p['force_max']:g} {p['force_unit']}" if p["force_max"] else "none"
        stroke = f"{p['stroke_max']:g} {p['stroke_unit']}" if p["stroke_max"] else "none"
        print(f"  PTO {p['name']} on {p['joint'] or 'two body points'}: force_max {force}, "
              f"stroke_max {stroke}, efficiency {p['efficiency']:g}")
    h = info["hydro"]
    if h:
        band = h["response_band"]
        band = f", judged per frequency in {band[0]:g}-{band[1]:g} rad/s" if band else ""
        print(f"  hydro: {h['source']}; DOFs {', '.join(h['dofs'])}; radiation "
              f"{h['radiation_states']} states (tol {h['radiation_tol']:g}{band})")
    print("  plant parameters (--param NAME=VALUE), default and unit:")
    for name, p in info["parameters"].items():
        print(f"    {name:40s} {p['default']:12.6g}  {p['unit']}")
    if h:
        print("    and for identification, per hydro DOF: <DOF>__added_mass_scale, "
              "__radiation_scale, __excitation_scale (1, dimensionless)")
    if info["scene_parameters"]:
        print("  scene parameters ([parameters] in the scene file): " + ", ".join(
            f"{k} = {v}" for k, v in info["scene_parameters"].items()))
    if info["identify"]:
        print("  identified by default ([identify]): " + ", ".join(info["identify"]))
    print("  controllers (--controller NAME --set KEY=VALUE), settings and defaults:")
    for name, settings in info["controllers"].items():
        shown = ", ".join(f"{k}={'(the run wave)' if k == 'wave' else v}"
                          for k, v in settings.items())
        print(f"    {name:12s} {shown}")
    return 0


def run_keys(args) -> int:
    """`mbcontrol keys [--readme [FILE]]`: the scene-key reference, printed or written into
    the README's scene-keys section."""
    from pathlib import Path

    from ..atomic import write_text
    from ..errors import InputError
    from ..scene import scene_keys_in_readme, scene_keys_markdown
    if args.readme:
        path = Path(args.readme)
        if not path.is_file():
            raise InputError(f"--readme {path}: no such file; expected the README (or guide) "
                             f"whose scene-keys section to rewrite")
        write_text(path, scene_keys_in_readme(path.read_text()))
        print(f"wrote the scene keys into {path}")
    else:
        print(scene_keys_markdown(), end="")
    return 0


def default_help(key: str) -> str:
    """"default 0.01 s: sim.dt" for a --help text (the value in force, environment included)."""
    entry = next(row for row in defaults.table() if row["key"] == key)
    unit = f" {entry['unit']}" if entry["unit"] else ""
    return f"default {entry['value']}{unit}: '{key}' in mbcontrol defaults"


def run_defaults(args) -> int:
    """`mbcontrol defaults [--json]`: every default, its value and where the value came from."""
    rows = defaults.table()
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    width = max(len(r["key"]) for r in rows)
    print(f"{'key':<{width}}  {'value':<24} {'from':<10} environment variable")
    for r in rows:
        value = f"{r['value']}{' ' + r['unit'] if r['unit'] else ''}"
        print(f"{r['key']:<{width}}  {value:<24} {r['source']:<10} {r['env']}\n"
              f"{'':<{width}}  {r['doc']}")
    print("\nChange one for a shell with its environment variable, in Python with "
          "mbcontrol.defaults.set(key, value);\na command's own flag wins over both.")
    return 0
