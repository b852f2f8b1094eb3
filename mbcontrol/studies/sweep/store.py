"""A sweep's results on disk, case by case: `<store>/cases/<key>.json`, each written to a
temporary file and renamed, so an interrupted sweep keeps every finished case and a rerun
computes only the missing ones (a case's key is a hash of all that decides its result).
`assemble` turns the records into one labelled xarray Dataset."""
from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr


class CaseStore:
    """The folder of case records; None as folder keeps them in memory only."""

    def __init__(self, folder=None):
        self.folder = Path(folder) / "cases" if folder is not None else None
        self._memory: dict = {}
        if self.folder is not None:
            self.folder.mkdir(parents=True, exist_ok=True)

    def has(self, key: str) -> bool:
        return key in self._memory or (self.folder is not None
                                       and (self.folder / f"{key}.json").exists())

    def write(self, key: str, record: dict) -> None:
        self._memory[key] = record
        if self.folder is None:
            return
        fd, tmp = tempfile.mkstemp(dir=self.folder, suffix=".tmp")
        with os.fdopen(fd, "w") as fh:
            json.dump(record, fh, default=_number)
        os.replace(tmp, self.folder / f"{key}.json")

    def read(self, key: str) -> dict:
        if key not in self._memory:
            self._memory[key] = json.loads((self.folder / f"{key}.json").read_text())
        return self._memory[key]

    def keys_on_disk(self) -> list[str]:
        return sorted(p.stem for p in self.folder.glob("*.json")) if self.folder else []


def _number(value):
    return float(value) if isinstance(value, (np.floating, np.integer)) else str(value)


def assemble(cases, store: CaseStore, seas, vary: dict, seeds: int, attrs: dict) -> xr.Dataset:
    """One Dataset over (sea, seed, *varied names) with a variable per metric; sea carries
    coordinates hs, tp, te, gamma, weight."""
    names = list(vary)
    shape = (len(seas), seeds) + tuple(len(vary[n]) for n in names)
    records = {c.index: store.read(c.key) for c in cases}
    metrics = sorted({m for r in records.values() for m in r["metrics"]})
    data = {}
    for m in metrics:
        a = np.full(shape, np.nan)
        for index, r in records.items():
            value = r["metrics"].get(m)
            a[index] = np.nan if value is None else float(value)
        data[m] = (("sea", "seed", *names), a)
    coords = {"sea": np.arange(len(seas)), "seed": np.arange(seeds),
              "hs": ("sea", [s.hs for s in seas]), "tp": ("sea", [s.tp for s in seas]),
              "te": ("sea", [s.te for s in seas]), "gamma": ("sea", [s.gamma for s in seas]),
              "weight": ("sea", [s.weight for s in seas])}
    coords.update({n: list(map(float, vary[n])) for n in names})
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({k: json.dumps(v) if isinstance(v, (dict, list)) else v
                     for k, v in attrs.items() if v is not None and not
                     (isinstance(v, float) and math.isnan(v))})
    return ds
