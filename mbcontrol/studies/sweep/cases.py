"""What a sweep runs: sea states (a grid or a weighted list from a CSV), wave seeds, and named
quantities varied over values (plant parameters, controller settings, scene parameters),
crossed into cases. Each case has a key (a hash of everything that decides its result), so a
store on disk knows which cases it already holds.
"""
from __future__ import annotations

import csv
import hashlib
import itertools
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

WEIGHT_SUM_TOLERANCE = 0.02        # a weighted list's weights must sum to 1 within this


@dataclass(frozen=True)
class SeaState:
    """A JONSWAP sea: significant height hs (m), peak period tp (s), peak enhancement gamma,
    and its weight (share of the year; NaN on a grid that carries no occurrence)."""
    hs: float
    tp: float
    gamma: float = 3.3
    weight: float = math.nan
    te: float = math.nan                 # energy period (s), when the source gave it


def grid(hs, tp, gamma: float = 3.3) -> list[SeaState]:
    """Every Hs with every Tp, unweighted."""
    return [SeaState(float(h), float(t), gamma) for h in hs for t in tp]


def te_over_tp(gamma: float) -> float:
    """Te / Tp of a JONSWAP spectrum (m_-1 / m_0 over the peak period), by quadrature."""
    from ...waves import jonswap_spectrum
    w = np.geomspace(0.2, 50.0, 40001)           # in units of the peak frequency (Tp = 2 pi)
    s = jonswap_spectrum(w, 1.0, 2 * math.pi, gamma)
    return float(np.trapezoid(s / w, w) / np.trapezoid(s, w))


def read_seas(path, gamma: float = 3.3) -> list[SeaState]:
    """Sea states from a CSV with columns Hm0 and Tp (or Te: Tp = Te / (Te/Tp of the JONSWAP
    spectrum)) and optional weights (summing to 1). Errors name the file, row and column."""
    path = Path(path)
    try:
        with path.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the seas file ({exc.strerror})") from None
    if not rows:
        raise ValueError(f"{path}: no sea states (expected a header with Hm0 and Tp or Te, "
                         f"then one row per sea)")
    columns = set(rows[0])
    period = "Tp" if "Tp" in columns else "Te" if "Te" in columns else None
    if "Hm0" not in columns or period is None:
        raise ValueError(f"{path}: expected columns Hm0 and Tp (or Te), found "
                         f"{', '.join(sorted(c for c in columns if c))}")
    ratio = te_over_tp(gamma)
    seas = []
    for i, row in enumerate(rows, start=2):              # row 1 is the header
        values = {}
        for name in ("Hm0", period, "weights", "Te"):
            text = (row.get(name) or "").strip()
            if name in ("weights", "Te") and not text:
                continue
            try:
                values[name] = float(text)
            except ValueError:
                raise ValueError(f"{path}: row {i}, column {name}: expected a number, got "
                                 f"{text!r}") from None
        for name in ("Hm0", period):
            if not values[name] > 0 or not math.isfinite(values[name]):
                raise ValueError(f"{path}: row {i}, column {name}: expected a positive "
                                 f"number, got {values[name]:g}")
        if values.get("weights", 0.0) < 0:
            raise ValueError(f"{path}: row {i}, column weights: expected >= 0, got "
                             f"{values['weights']:g}")
        tp = values[period] if period == "Tp" else values[period] / ratio
        seas.append(SeaState(values["Hm0"], tp, gamma, values.get("weights", math.nan),
                             values.get("Te", math.nan)))
    weights = [s.weight for s in seas]
    if "weights" in columns:
        if any(math.isnan(w) for w in weights):
            row = 2 + next(k for k, w in enumerate(weights) if math.isnan(w))
            raise ValueError(f"{path}: row {row}, column weights: missing (every row needs one)")
        total = sum(weights)
        if abs(total - 1.0) > WEIGHT_SUM_TOLERANCE:
            raise ValueError(f"{path}: weights sum to {total:.4g}; expected 1 within "
                             f"{WEIGHT_SUM_TOLERANCE} (shares of the year)")
    return seas


@dataclass(frozen=True)
class Case:
    """One closed-loop simulation of a sweep: its sea, seed, the values of the varied
    quantities (name -> value) and what is fixed; `index` places it in the result grid."""
    model: str
    sea: SeaState
    seed: int
    varied: tuple                       # ((name, value), ...) in the sweep's order
    index: tuple                        # (sea index, seed index, value index per varied name)
    params: tuple = ()                  # fixed plant parameter overrides ((name, value), ...)
    scene_params: tuple = ()            # fixed scene parameters
    controller: str | None = None
    settings: tuple = ()                # fixed controller settings
    duration: float = 600.0
    dt: float = 0.05
    method: str = "rk4"
    roles: dict = field(default_factory=dict, compare=False)   # varied name -> its kind

    @property
    def key(self) -> str:
        """A hash of everything that decides the result (not of where it sits in the grid)."""
        record = {k: v for k, v in asdict(self).items() if k not in ("index", "roles")}
        text = json.dumps(record, sort_keys=True, default=float)
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    def resolved(self) -> tuple[dict, dict, dict]:
        """(plant params, scene params, controller settings) with the varied values in."""
        params, scene, settings = dict(self.params), dict(self.scene_params), dict(self.settings)
        for name, value in self.varied:
            {"param": params, "scene": scene, "setting": settings}[self.roles[name]][name] = value
        return params, scene, settings


def build_cases(model: str, seas, *, seeds: int = 1, vary: dict | None = None, roles=None,
                params=None, scene_params=None, controller=None, settings=None,
                duration: float = 600.0, dt: float = 0.05, method: str = "rk4") -> list[Case]:
    """Every sea x seed x combination of the varied values. roles: varied name -> "param",
    "scene" or "setting" (see `roles_for`)."""
    vary = dict(vary or {})
    names = list(vary)
    cases = []
    for (i, sea), seed, combo in itertools.product(
            enumerate(seas), range(seeds),
            itertools.product(*[list(enumerate(vary[n])) for n in names])):
        cases.append(Case(model, sea, seed, tuple((n, float(v)) for n, (_, v) in zip(names, combo)),
                          (i, seed) + tuple(k for k, _ in combo),
                          tuple(sorted((params or {}).items())),
                          tuple(sorted((scene_params or {}).items())), controller,
                          tuple(sorted((settings or {}).items())), float(duration), float(dt),
                          method, dict(roles or {})))
    return cases


def roles_for(names, scene, plant_parameters, controller_class=None) -> dict:
    """Which kind each varied name is: a scene [parameters] name ("scene"), a plant parameter
    ("param") or a setting of the controller ("setting"); ValueError naming the choices."""
    import inspect
    settings = set(inspect.signature(controller_class).parameters) if controller_class else set()
    roles = {}
    for name in names:
        kinds = [k for k, pool in (("scene", set(scene.parameters)),
                                   ("param", set(plant_parameters)), ("setting", settings))
                 if name in pool]
        if not kinds:
            raise ValueError(f"--vary {name}: not a scene parameter ({', '.join(scene.parameters) or 'none'}), "
                             f"plant parameter or controller setting of {scene.name}")
        if len(kinds) > 1:
            raise ValueError(f"--vary {name}: ambiguous, it is a {' and a '.join(kinds)}")
        roles[name] = kinds[0]
    return roles
