"""Per-sea inputs of the annual energy's budget beyond statistics and identification: the
linear-against-nonlinear model difference, the scene's [[uncertainty]] numbers, and the
electrical energy (powers in W, per sea over the sweep's seas)."""
from __future__ import annotations

import numpy as np

from . import budget as bud


def nonlinear_difference(ds, capped) -> tuple[np.ndarray | None, str]:
    """(per sea the linear run's mean power minus the nonlinear one's where both ran (W; 0
    where only one ran), why not): from a --nonlinear invalid sweep's records."""
    if "nonlinear_model" not in ds:
        return None, ("only one model ran (the sweep's --nonlinear is not 'invalid'); run "
                      "--nonlinear invalid to run the nonlinear plant where the linear leaves "
                      "its range")
    both = ds["nonlinear_model"].values & np.isfinite(ds["mean_power_W"].values) \
        & np.isfinite(ds["mean_power_W__linear"].values)
    if not both.any():
        return None, ("no sea ran both models: every linear run stayed in the linear range "
                      "(--nonlinear invalid), so the difference is not measured here")
    diff = np.where(both, ds["mean_power_W__linear"].values - ds["mean_power_W"].values, 0.0)
    counts = both.sum(axis=1)
    per_sea = np.where(counts > 0, diff.sum(axis=1) / np.maximum(counts, 1), 0.0)
    return np.where(capped, 0.0, per_sea), f"{int((counts > 0).sum())} seas ran both"


def nonlinear_component(weights, diff, why: str, scale) -> dict:
    """Type B, linear over seas: the linear model's error where it left its range."""
    if diff is None:
        return bud.absent("linear_vs_nonlinear", "B", "linear", why)
    return bud.linear_over_seas(
        "linear_vs_nonlinear", weights, diff * scale,
        f"linear minus nonlinear mean power per sea where both ran ({why}; the reported "
        f"power is the nonlinear run's there), summed over seas with their weights, its size "
        f"as a Type B standard uncertainty")


def scene_component(items, rel_grads, eff_grads, weights, power, scale, *, electrical: bool,
                    why_not: str | None) -> dict:
    """The scene's [[uncertainty]] numbers through their sensitivities (diagonal covariance:
    the tables are independent)."""
    if not items:
        return bud.absent("scene_parameters", "B", "linear",
                          "the scene has no [[uncertainty]] tables (mass, efficiency, drag)")
    if rel_grads is None:
        return bud.absent("scene_parameters", "B", "linear", f"needs a linear law ({why_not})")
    grads = rel_grads * (np.nan_to_num(power) * scale)[:, None]
    if electrical:
        grads = grads + eff_grads
    names = [i.parameter for i in items]
    used = [j for j, i in enumerate(items) if electrical or i.kind != "efficiency"]
    note = "" if electrical else "; efficiencies move the electrical energy only"
    return bud.parameters(
        weights, grads[:, used], np.diag([items[j].std ** 2 for j in used]),
        [names[j] for j in used],
        f"{len(used)} scene [[uncertainty]] numbers (independent) through linear theory's "
        f"relative sensitivities (central differences; quadratic drag by statistical "
        f"linearisation) times the simulated power{note}", name="scene_parameters")


def electrical_power(ds, scene, capped_power) -> np.ndarray | None:
    """Per sea the mean electrical power (W) where the scene converts (a drivetrain or an
    efficiency below 1), scaled down as the absorbed power is where capped at the rated
    power; None where electrical equals absorbed."""
    if not any(p.drivetrain is not None or p.efficiency != 1.0 for p in scene.ptos):
        return None
    absorbed = ds["mean_power_W"].mean("seed").values
    electrical = ds["mean_electrical_power_W"].mean("seed").values
    ratio = np.where(absorbed > 0, capped_power / np.where(absorbed > 0, absorbed, 1.0), 1.0)
    return np.where(np.isfinite(electrical), electrical * np.minimum(ratio, 1.0), 0.0)


def pto_means(ds, scene) -> tuple[dict, dict]:
    """Per PTO its mean power and mean |power| per sea (W, means over seeds)."""
    mean = {p.name: ds[f"{p.name}__mean_power_W"].mean("seed").values for p in scene.ptos
            if f"{p.name}__mean_power_W" in ds}
    absolute = {p.name: ds[f"{p.name}__mean_abs_power_W"].mean("seed").values
                for p in scene.ptos if f"{p.name}__mean_abs_power_W" in ds}
    return mean, absolute
