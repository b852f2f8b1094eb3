"""What a sweep was made from, for its summary and Dataset ("provenance"): its inputs (content
hashes of the scene, hydro data, radiation fit; the package version), the controller with its
settings as its cases run them, and what else decided its cases (amplitudes, nonlinear plant,
identification, per-sea design, measured records)."""
from __future__ import annotations

from ...results import jsonable


def sweep_provenance(inputs: dict, controller, settings, vary, roles, *, amplitudes: str,
                     nonlinear: str, identified, design: bool, robust: bool, measured) -> dict:
    """The sweep's provenance: its inputs, the controller and its resolved settings (or how
    they were designed), and what else decided its cases."""
    made_by = {**inputs, "controller": controller,
               "settings": resolved_settings(controller, settings, vary, roles),
               "amplitudes": amplitudes}
    if nonlinear != "scene":
        made_by["nonlinear"] = nonlinear
    if identified is not None:
        made_by["identified"] = identified["source"]
    if design:
        made_by["settings"] = {"designed_per_sea": True, "robust": bool(robust),
                               "given": dict(settings or {})}
    if measured is not None:
        made_by["records"] = [{"file": r.name, "sha256": r.sha256} for r in measured]
    return made_by


def resolved_settings(controller, settings, vary=None, roles=None) -> dict:
    """The controller's settings as its cases run them, defaults included (its describe()
    without run statistics; e.g. an MPC's forecast), for provenance; varied settings are
    listed by name as "varied"."""
    if controller is None:
        return {}
    import inspect

    from mbcontrol.controllers import REGISTRY, make

    from ...waves import regular
    given = dict(settings or {})
    if "wave" in inspect.signature(REGISTRY[controller]).parameters:
        given.setdefault("wave", regular(1.0, 10.0))   # as the cases hand it a sea; its
    try:                                                 # settings do not depend on which
        described = make(controller, **given).describe()
    except (TypeError, ValueError, AttributeError, KeyError):
        described = dict(settings or {})  # a controller that describes itself only once reset
    described = {k: v for k, v in described.items() if k not in ("stats", "name")}
    for name, role in (roles or {}).items():
        if role == "setting":
            described[name] = "varied"
    return jsonable(described)
