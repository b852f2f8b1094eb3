"""A sweep's results on disk, case by case: `<store>/cases/<key>.json`, each written to a
temporary file and renamed, so an interrupted sweep keeps every finished case and a rerun
computes only the missing ones (a case's key is a hash of all that decides its result).
`assemble` turns the records into one labelled xarray Dataset."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import xarray as xr

from ...atomic import write_text
from ...cache import read_entry
from ...errors import EnvironmentProblem, InputError


PROVENANCE_FILE = "provenance.json"


class CaseStore:
    """The folder of case records; None as folder keeps them in memory only.

    inputs: what made the plant (`mbcontrol.plant.provenance`: model, package version,
    content hashes of the scene, hydro data and radiation fit). A store remembers the inputs
    it was made from (`<store>/provenance.json`) and refuses others: its records would be
    of another device (case keys include the hashes too, so nothing is ever mixed)."""

    def __init__(self, folder=None, inputs: dict | None = None):
        self.folder = Path(folder) / "cases" if folder is not None else None
        self._memory: dict = {}
        if self.folder is not None:
            self.folder.mkdir(parents=True, exist_ok=True)
            if inputs is not None:
                _check_inputs(Path(folder), inputs)

    def has(self, key: str) -> bool:
        """Is the case's record here and readable? One that cannot be read (truncated,
        damaged) is moved aside with a warning (mbcontrol.cache.read_entry): the case runs
        again, the others are kept."""
        if key in self._memory:
            return True
        if self.folder is None:
            return False
        record = read_entry(self.folder / f"{key}.json", _read_json,
                            what="sweep case record", then="running the case again")
        if record is not None:
            self._memory[key] = record
        return record is not None

    def write(self, key: str, record: dict) -> None:
        self._memory[key] = record
        if self.folder is None:
            return
        _write_json(self.folder / f"{key}.json", record)

    def read(self, key: str) -> dict:
        if not self.has(key):
            raise EnvironmentProblem(f"{self.folder / key}.json: the case's record is gone or "
                                     f"unreadable since it was written; run the sweep again")
        return self._memory[key]

    def keys_on_disk(self) -> list[str]:
        return sorted(p.stem for p in self.folder.glob("*.json")) if self.folder else []


def _check_inputs(folder: Path, inputs: dict) -> None:
    """Record the inputs in a new store; refuse a store made from other inputs."""
    path = folder / PROVENANCE_FILE
    # unreadable: moved aside and written anew (the case keys hold the same hashes, so no
    # other inputs' case can be taken for these)
    stored = read_entry(path, _read_json, what="sweep store provenance",
                        then="recording this sweep's inputs instead")
    if stored is None:
        _write_json(path, inputs)
        return
    changed = [k for k in sorted(set(stored) | set(inputs)) if stored.get(k) != inputs.get(k)]
    if changed:
        detail = "; ".join(f"{k}: store {str(stored.get(k))[:16]}, now {str(inputs.get(k))[:16]}"
                           for k in changed)
        raise InputError(f"{folder}: this store was made from other inputs ({detail}). Its "
                         f"cases are not this model's: use a new --store, or delete {folder} "
                         f"to recompute")


def _read_json(path: Path):
    return json.loads(path.read_text(encoding="utf-8"))


def _write_json(path: Path, value) -> None:
    write_text(path, json.dumps(value, indent=1, default=_number))


def _number(value):
    return float(value) if isinstance(value, (np.floating, np.integer)) else str(value)


def assemble(cases, store: CaseStore, seas, vary: dict, seeds: int, attrs: dict) -> xr.Dataset:
    """One Dataset over (sea, seed, *varied names) with a variable per metric; sea carries
    coordinates hs, tp, te, gamma, weight."""
    names = list(vary)
    shape = (len(seas), seeds) + tuple(len(vary[n]) for n in names)
    records = {c.index: store.read(c.key) for c in cases}
    # the totals always exist, NaN where no case ran (a sweep whose every case failed)
    metrics = sorted({m for r in records.values() for m in r["metrics"]}
                     | {"mean_power_W", "mean_electrical_power_W"})
    dims = ("sea", "seed", *names)
    valid = np.ones(shape, bool)
    failed = np.zeros(shape, bool)
    reasons = np.full(shape, "", dtype=object)
    for index, r in records.items():
        valid[index] = bool(r.get("valid", True))
        failed[index] = bool(r.get("failed", False))
        reasons[index] = "; ".join(r.get("invalid_reasons", []))
    data = {"valid": (dims, valid, {"long_name": "the case passed its physics checks "
                                                 "(mbcontrol.analysis.validity)"}),
            "failed": (dims, failed, {"long_name": "the case's run raised (diverged, ...): "
                                                   "no metrics"}),
            "invalid_reasons": (dims, reasons.astype(str))}
    for m in metrics:
        a = np.full(shape, np.nan)
        raw = np.full(shape, np.nan)
        for index, r in records.items():
            value = r["metrics"].get(m)
            raw[index] = np.nan if value is None else float(value)
        # an invalid case's numbers never enter a mean, matrix or annual energy: NaN here,
        # counted in the sweep's summary; the reported values stay in <metric>__unchecked
        a[valid] = raw[valid]
        data[m] = (dims, a)
        if not valid.all() and m in ("mean_power_W", "mean_electrical_power_W"):
            data[f"{m}__unchecked"] = (dims, raw)
    if any("design" in r for r in records.values()):
        data.update(_design_variables(records, shape, dims))
    if any("model" in r for r in records.values()):        # --nonlinear invalid
        data.update(_model_variables(records, shape, dims))
    coords = {"sea": np.arange(len(seas)), "seed": np.arange(seeds),
              "hs": ("sea", [s.hs for s in seas]), "tp": ("sea", [s.tp for s in seas]),
              "te": ("sea", [s.te for s in seas]), "gamma": ("sea", [s.gamma for s in seas]),
              "weight": ("sea", [s.weight for s in seas])}
    coords.update({n: list(map(float, vary[n])) for n in names})
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({k: v for k, v in attrs.items() if v is not None and not   # JSON in files only
                     (isinstance(v, float) and math.isnan(v))})
    return ds


def _model_variables(records: dict, shape: tuple, dims: tuple) -> dict:
    """--nonlinear invalid: which cases ran on the nonlinear plant (their linear run left the
    linear range), and the linear run's mean power there (W; INVALID, for comparison)."""
    escalated = np.zeros(shape, bool)
    linear_power = np.full(shape, np.nan)
    for index, r in records.items():
        if r.get("model") == "nonlinear":
            escalated[index] = True
            linear_power[index] = r["linear"]["metrics"].get("mean_power_W", np.nan)
    return {"nonlinear_model": (dims, escalated, {
                "long_name": "the case ran on the nonlinear plant: its linear run left the "
                             "linear range (sweep --nonlinear invalid)"}),
            "mean_power_W__linear": (dims, linear_power, {
                "long_name": "the linear plant's mean absorbed power where it left its range "
                             "(INVALID there; for comparison)", "units": "W"})}


def _design_variables(records: dict, shape: tuple, dims: tuple) -> dict:
    """--design: per case its tuned settings (JSON), linear theory's power, the bound inside
    the same envelope (W), whether the tuner kept the device inside its envelope, whether the
    design fell back to a gentler law (studies.design.fallback), which ("" where none; the
    reason where no law serves the sea) and whether no law serves the sea at all."""
    settings = np.full(shape, "", dtype=object)
    fell_back, no_law = np.zeros(shape, bool), np.zeros(shape, bool)
    fallback = np.full(shape, "", dtype=object)
    bound, predicted = np.full(shape, np.nan), np.full(shape, np.nan)
    inside = np.ones(shape, bool)
    robust = np.ones(shape, bool)
    for index, r in records.items():
        d = r.get("design")
        if d is None:
            continue
        robust[index] = (d.get("robustness") or {}).get("meets", True)
        settings[index] = json.dumps(d["settings"], sort_keys=True)
        bound[index] = np.nan if d["bound_W"] is None else d["bound_W"]
        predicted[index] = np.nan if d["predicted_W"] is None else d["predicted_W"]
        inside[index] = d["envelope"].get("inside") is not False
        no_law[index] = bool(r.get("no_law"))       # fell back to nothing: zero_seas says why
        fell_back[index] = bool(d.get("fell_back")) and not no_law[index]
        if d.get("fallback"):
            fallback[index] = d["fallback"]["to"] or "none: no law serves the sea"
    return {"fell_back": (dims, fell_back, {
                "long_name": "the law tuned for the sea could not hold the PTO's limits or the "
                             "envelope: the design fell back to a gentler law, which ran "
                             "(studies.design.fallback)"}),
            "fallback": (dims, fallback.astype(str), {
                "long_name": "the law it fell back to (\"none: ...\" where no law serves the sea)"}),
            "no_law": (dims, no_law, {
                "long_name": "no law within the PTO's limits serves the sea: not run, its "
                             "energy counted as zero"}),"design_settings": (dims, settings.astype(str),
                                {"long_name": "the settings tuned for the case's sea (JSON)"}),
            "bound_W": (dims, bound, {"long_name": "the most any PTO force absorbs inside the "
                                                   "same envelope (linear theory)",
                                      "units": "W"}),
            "predicted_power_W": (dims, predicted, {"long_name": "the tuned law's mean power "
                                                                 "in linear theory",
                                                    "units": "W"}),
            "inside_envelope": (dims, inside, {"long_name": "the tuner found settings inside "
                                                            "the linear model's envelope"}),
            "meets_robustness_floors": (dims, robust, {
                "long_name": "the tuned linear law's gain and phase margins meet "
                             "controllers.robustness' floors (true where not checked)"})}
