"""What a co-design point is worth: the objectives `mbcontrol codesign` maximises.

A point is a set of values for named quantities, each a scene parameter (the hull, the
drivetrain, anything the scene writes as "{expr}"), a plant parameter or a controller
setting (`studies.sweep.cases.roles_for` tells which). Its scene is loaded with the scene
parameters (the BEM data and radiation fits are cached by content, so a geometry met before
costs nothing) and one of:

- electrical_bound: the most mean electrical power (W) any PTO force delivers in the wave
  within the PTO's force and stroke limits, non-causal (`analysis.electrical.electrical_bound`,
  the force limit where the scene's force_max_on says: WecOptTool's co-design objective);
  with seas instead of a wave, the site's annual energy of that bound (MWh: each sea's bound
  in its expected spectrum, weighted), the ceiling the annual_energy objective is measured by;
- mechanical_bound: the same for absorbed power (`analysis.pseudo_spectral_bound`);
- controller: the mean power (electrical with a drivetrain, else mechanical; W) of a causal
  controller designed for the wave as `sweep --design` designs it
  (`studies.design`), simulated on the nonlinear plant and checked;
- annual_energy: the site's annual absorbed energy (MWh: the PTOs' mechanical power, as
  `sweep` weighs it) with the controller designed per sea (`studies.sweep`, --design), its
  95 % interval the error bar; mechanical_bound is its ceiling, not electrical_bound.
A cost proxy may divide it (`per`): "volume" (m^3 displaced at rest), "rated_force" (kN, the
PTOs' force_max summed) or an arithmetic expression of the point's names and the scene's
parameters. Each evaluation returns {"objective", "valid", "error_95" (half-width or None),
"reasons", "details"}.
"""
from __future__ import annotations

import dataclasses
import math

from ...errors import InputError

OBJECTIVES = ("electrical_bound", "mechanical_bound", "controller", "annual_energy")
# objectives whose powers are not of one kind: annual_energy is absorbed (mechanical) energy
UNLIKE = {frozenset(("annual_energy", "electrical_bound"))}


@dataclasses.dataclass(frozen=True)
class Spec:
    """What every point of a study shares: the model, the objective and its wave or seas."""
    model: str
    objective: str
    wave: dict | None = None              # waves.from_args keywords (kind, height, period, ...)
    seas: str | None = None               # a weighted seas CSV (annual_energy, a site bound)
    controller: str | None = None         # controller / annual_energy
    per: str | None = None                # cost proxy: volume, rated_force or an expression
    duration: float = 300.0               # s, a record (controller, annual_energy), a site bound's repeat period
    dt: float | None = None
    omega_max: float | None = None        # rad/s, a bound's top force frequency (None: the data's)
    scene_params: tuple = ()              # fixed ((name, value), ...)
    params: tuple = ()
    settings: tuple = ()

    def __post_init__(self):
        if self.objective not in OBJECTIVES:
            raise InputError(f"--objective {self.objective}: expected one of "
                             f"{', '.join(OBJECTIVES)}")
        if self.objective == "annual_energy" and not self.seas:
            raise InputError("--objective annual_energy needs --seas FILE.csv (weighted seas)")
        if self.objective in ("controller", "annual_energy") and not self.controller:
            raise InputError(f"--objective {self.objective} needs --controller (the law "
                             f"designed for each point)")
        if self.objective in ("controller", "mechanical_bound", "electrical_bound") and \
                not self.wave and not (self.seas and self.objective != "controller"):
            raise InputError(f"--objective {self.objective} needs a wave (--wave ...)"
                             + ("" if self.objective == "controller" else " or --seas FILE.csv"))
        if self.wave and self.seas:
            raise InputError("give a wave or --seas, not both")

    @property
    def unit(self) -> str:
        """The objective's unit before a cost proxy: MWh for a site, W for one wave."""
        return "MWh" if self.seas else "W"


def evaluate(spec: Spec, point: dict, roles: dict) -> dict:
    """The objective at `point` (name -> value), roles: name -> "scene" | "param" | "setting"."""
    from ...plant import build_plant
    from ...scene import load_scene
    kind = {"scene": {}, "param": {}, "setting": {}}
    for name, value in point.items():
        kind[roles[name]][name] = value
    scene_params = {**dict(spec.scene_params), **kind["scene"]}
    params = {**dict(spec.params), **kind["param"]}
    settings = {**dict(spec.settings), **kind["setting"]}
    if spec.objective == "annual_energy":
        out = _annual(spec, scene_params, params, settings)
    else:
        plant = build_plant(load_scene(spec.model, scene_params or None))
        if spec.seas:
            out = _site_bound(spec, plant, params)
        elif spec.objective == "controller":
            out = _controller(spec, plant, _wave(plant, spec.wave, spec.duration), params,
                              settings)
        else:
            out = _bound(spec.objective, plant, _wave(plant, spec.wave, spec.duration), params,
                         spec.omega_max)
    return _finish(spec, out, scene_params, point)


def _finish(spec: Spec, out: dict, scene_params: dict, point: dict) -> dict:
    """The evaluation divided by the cost proxy, if one is asked for."""
    from ...scene import load_scene
    if spec.per:
        scale = cost_proxy(spec.per, load_scene(spec.model, scene_params or None),
                           {**scene_params, **point})
        out["details"]["cost_proxy"] = {"per": spec.per, "value": scale}
        out["objective"] = out["objective"] / scale if out["objective"] is not None else None
        if out["error_95"] is not None:
            out["error_95"] /= scale
    return out


def _wave(plant, wave: dict, duration: float):
    from ... import waves
    omega = plant.hydro.omega
    made = waves.from_args(duration=duration, data_band=(float(omega[0]), float(omega[-1])),
                           **wave)
    headings = plant.hydro.data["wave_direction"].values
    return dataclasses.replace(made, direction=float(headings[0]) if len(headings) == 1 else 0.0)


def _bound(objective: str, plant, wave, params, omega_max: float | None = None) -> dict:
    """The force- and stroke-limited non-causal bound (W) of the first PTO; every multiple of
    the wave's repeat frequency up to omega_max (rad/s; None: the hydro data's last one) may
    carry force. The dense interior point ("IPM", analysis.box_qp) solves it: the same optimum
    as Clarabel to 1e-8, 4-25x faster on a sea's hundreds of harmonics."""
    from ...analysis import pseudo_spectral_bound
    from ...analysis import electrical_bound
    pto = plant.scene.ptos[0]
    kw = dict(pto=pto.name, force_max=pto.force_max, stroke_max=pto.stroke_max,
              params=params or None, solver="IPM",
              omega_max=float(plant.hydro.omega[-1]) if omega_max is None else omega_max)
    if objective == "electrical_bound":
        result = electrical_bound(plant, wave, **kw)
        value, status = result.electrical_W, result.mechanical.status
        details = {"mechanical_W": result.mechanical_W, "winding_loss_W": result.winding_loss_W,
                   "max_force": result.mechanical.max_force}
    else:
        result = pseudo_spectral_bound(plant, wave, **kw)
        value, status = result.mean_power, result.status
        details = {"max_force": result.max_force}
    details.update(force_max=pto.force_max, force_max_on=pto.limited_force(),
                   stroke_max=pto.stroke_max, mass_kg=[b.mass for b in plant.scene.bodies])
    ok = status in ("optimal", "optimal_inaccurate")
    return {"objective": float(value), "valid": ok, "error_95": None,
            "reasons": [] if ok else [f"the bound's QP ended {status}"], "details": details}


def _site_bound(spec: Spec, plant, params) -> dict:
    """The annual energy (MWh) of the force-limited bound over the weighted seas: each sea's
    bound in the wave `sweep` runs it in (runner.sea_wave: its JONSWAP with deterministic
    amplitudes, repeating every spec.duration s), weighted by its share of the year. Expected
    amplitudes have no phase scatter, so the figure has no error bar."""
    from ...waves import annual_energy_MWh
    from ..sweep import read_seas
    from ..sweep.runner import sea_wave
    seas = read_seas(spec.seas)
    if any(math.isnan(s.weight) for s in seas):
        raise InputError(f"{spec.seas}: the site's bound needs a weights column")
    per_sea, reasons = [], []
    for i, sea in enumerate(seas):
        out = _bound(spec.objective, plant, sea_wave(plant, sea, spec.duration), params,
                     spec.omega_max)
        per_sea.append(out["objective"])
        reasons += [f"sea {i} (Hs {sea.hs:.3g} m, Tp {sea.tp:.3g} s): {r}" for r in out["reasons"]]
    aep = annual_energy_MWh(per_sea, [s.weight for s in seas])
    return {"objective": aep, "valid": not reasons, "error_95": None, "reasons": reasons,
            "details": {"mean_power_W": per_sea, "seas": len(seas)}}


def _controller(spec: Spec, plant, wave, params, settings) -> dict:
    """A causal law designed for the wave (sea_design), simulated and checked."""
    import inspect

    from mbcontrol.controllers import REGISTRY, make
    from mbcontrol.studies.design import design_for_sea

    from ...analysis import pto_metrics
    from ...analysis import assess
    from ...sim import simulate
    designed = design_for_sea(plant, wave, spec.controller, dt=spec.dt)
    chosen = {**designed["settings"], **settings}
    if "wave" in inspect.signature(REGISTRY[spec.controller]).parameters:
        chosen["wave"] = wave
    run = simulate(plant, wave, duration=spec.duration, dt=spec.dt,
                   controller=make(spec.controller, **chosen), params=params or None)
    pto = plant.scene.ptos[0]
    metrics = pto_metrics(run, pto)
    key = "mean_electrical_power_W" if pto.drivetrain is not None else "mean_power_W"
    verdict = assess(run, plant, wave, mean_power_W=metrics["mean_power_W"])
    return {"objective": float(metrics[key]), "valid": bool(verdict["valid"]), "error_95": None,
            "reasons": list(verdict["invalid_reasons"]),
            "details": {"settings": {k: v for k, v in chosen.items() if k != "wave"},
                        "predicted_W": designed["predicted_W"], "bound_W": designed["bound_W"],
                        "power": key}}


def _annual(spec: Spec, scene_params, params, settings) -> dict:
    from ..sweep import read_seas, sweep
    _, summary = sweep(spec.model, read_seas(spec.seas), scene_params=scene_params or None,
                       params=params or None, controller=spec.controller, settings=settings,
                       design=True, duration=spec.duration, dt=spec.dt, workers=0,
                       progress=False)
    ci = summary.get("annual_energy_ci95_MWh")
    aep = summary["annual_energy_MWh"]
    return {"objective": aep, "valid": summary["annual_energy_coverage"] == 1.0,
            "error_95": None if not ci else (ci[1] - ci[0]) / 2,
            "reasons": [] if summary["annual_energy_coverage"] == 1.0 else [
                f"{summary['failed_cases'] + summary['invalid_cases']} seas failed or invalid: "
                f"the annual energy covers {100 * summary['annual_energy_coverage']:.3g} % of "
                f"the year"],
            "details": {"annual_energy_ci95_MWh": ci, "valid_cases": summary["valid_cases"],
                        "cases": summary["cases"]}}


def cost_proxy(per: str, scene, values: dict) -> float:
    """The divisor of a cost proxy: "volume" (m^3 displaced at rest: each hydrodynamic body's
    immersed volume where its geometry gives it in closed form, else its mass / rho),
    "rated_force" (kN: the PTOs' force_max summed) or an arithmetic expression of `values`
    and the scene's parameters. Must be > 0."""
    from ...scene import immersed_volume
    from ...scene import evaluate_expression
    if per == "volume":
        total = 0.0
        for body in scene.bodies:
            if body.hydro and body.geometry is not None:
                try:
                    total += immersed_volume(body.geometry)
                except ValueError:                 # a faceted primitive or a mesh
                    total += body.mass / scene.water.rho
        value = total
    elif per == "rated_force":
        value = sum(p.force_max for p in scene.ptos) / 1e3
    else:
        value = evaluate_expression(per, {**scene.parameters, **values}, str(scene.path), "--per")
    if not (value > 0 and math.isfinite(value)):
        raise InputError(f"--per {per}: the cost proxy is {value!r}; expected a finite number > 0")
    return float(value)
