"""A co-design study: points on a grid or chosen by an optimiser, each evaluated once
(`objectives.evaluate`), kept in a store so an interrupted study resumes, the best reported.

Search (all maximise the objective; a point that fails its checks counts as -inf):
- grid: every combination of the --vary values (in order), on Dask when workers are asked for;
- one --optimize NAME=LO:HI: bounded Brent (scipy minimize_scalar "bounded"): the objective of
  one hull or drivetrain dimension is smooth and mostly unimodal, and Brent needs ~10-20
  evaluations where each may be a BEM solve;
- several: Nelder-Mead with bounds from the box's centre (derivative-free, so the
  evaluations need no gradients; local: give a grid first to see whether the landscape has
  more than one peak). --max-evals caps the evaluations either way.
Evaluations are serial for the optimisers (each point depends on the last).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import time
from pathlib import Path

import numpy as np

from ...atomic import write_text
from ...cache import read_entry
from ...errors import InputError
from .objectives import Spec, evaluate


def point_key(spec: Spec, point: dict, scene_text: str) -> str:
    """A hash of everything that decides a point's value: the scene file's text, the spec
    (but omega_max, which only bounds read) and the point (resumed points are those with the
    same key)."""
    from importlib import metadata
    try:
        version = metadata.version("mbcontrol")
    except metadata.PackageNotFoundError:      # a source tree never installed
        version = "unknown"
    record = {"scene": hashlib.sha256(scene_text.encode()).hexdigest(), "version": version,
              "spec": {k: None if k == "omega_max" and "bound" not in spec.objective else v
                       for k, v in vars(spec).items()},
              "point": {k: float(v) for k, v in sorted(point.items())}}
    text = json.dumps(record, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:20]


class Store:
    """Evaluated points by key: in memory, and as <folder>/points/<key>.json when a folder is
    given (written whole, then renamed: an interrupted study loses at most the point it was
    on)."""

    def __init__(self, folder=None):
        self.folder = None if folder is None else Path(folder) / "points"
        self.memory: dict = {}

    def get(self, key: str):
        if key in self.memory:
            return self.memory[key]
        if self.folder is not None:    # an unreadable record is moved aside: evaluated again
            record = read_entry(self.folder / f"{key}.json", lambda p: json.loads(p.read_text()),
                                what="co-design point record", then="evaluating the point again")
            if record is not None:
                self.memory[key] = record
            return record
        return None

    def put(self, key: str, record: dict) -> None:
        self.memory[key] = record
        if self.folder is not None:
            write_text(self.folder / f"{key}.json", json.dumps(record))


def _evaluate_record(spec: Spec, point: dict, roles: dict) -> dict:
    """A point's record; a point whose evaluation raises is a result (not valid, the reason)."""
    start = time.perf_counter()
    try:
        out = evaluate(spec, point, roles)
    except Exception as exc:            # noqa: BLE001 - one bad design does not stop a study
        out = {"objective": None, "valid": False, "error_95": None,
               "reasons": [f"{type(exc).__name__}: {exc}"], "details": {}}
    return {"params": {k: float(v) for k, v in point.items()}, **out,
            "wall_s": time.perf_counter() - start}


def codesign(spec: Spec, *, vary: dict | None = None, optimize: dict | None = None,
             at: list | None = None, store=None, workers: int | None = 0,
             scheduler: str | None = None, max_evals: int = 40, progress: bool = False) -> dict:
    """Run a study; the JSON contract of `mbcontrol codesign --json`: {"points": [{"params",
    "objective", "valid", "error_95", "reasons", "wall_s", "reused"}], "best": {"params",
    "objective", "error_95"}, "objective_name", "search", "computed", "reused",
    "wall_time_s", "provenance"}. vary: name -> values (a grid); optimize: name -> (lo, hi);
    at: given points (name -> value each: another study's, to compare objectives)."""
    from mbcontrol.controllers import REGISTRY

    from ...plant import build_plant
    from ...scene import load_scene
    from ..sweep.cases import roles_for
    if sum(bool(s) for s in (vary, optimize, at)) != 1:
        raise InputError("codesign: give either --vary (a grid) or --optimize (a search), "
                         "one of them")
    start = time.perf_counter()
    scene = load_scene(spec.model, dict(spec.scene_params) or None)
    plant = build_plant(scene)
    names = list(vary or optimize or at[0])
    roles = roles_for(names, scene, plant.parameters, REGISTRY.get(spec.controller))
    bad = [n for n in names if roles[n] not in ("scene", "param", "setting")]
    if bad:
        raise InputError(f"codesign: {bad[0]} is the wave's heading; expected a scene "
                         f"parameter, a plant parameter or a controller setting")
    laws = {f"{p.name}__{k}" for p in scene.ptos for k in ("damping", "stiffness")}
    idle = [n for n in names if roles[n] == "param" and n in laws]
    if idle:          # the bounds free the PTO force, a controller replaces the scene's law
        raise InputError(f"codesign: {idle[0]} is the scene PTO's own law, which every "
                         f"objective sets aside; vary the controller's setting instead "
                         f"(e.g. damping with --controller passive)")
    text = Path(scene.path).read_text()
    cache, points = Store(store), []

    def run(point: dict) -> dict:
        key = point_key(spec, point, text)
        record = cache.get(key)
        if record is None:
            record = {**_evaluate_record(spec, point, roles), "reused": False}
            cache.put(key, {**record, "reused": True})
        points.append(record)
        return record

    if vary:
        grid = [dict(zip(names, values)) for values in itertools.product(*vary.values())]
        _grid(grid, run, spec, roles, text, cache, workers, scheduler, progress)
        search = "grid"
    elif at:
        for point in at:
            run(dict(point))
        search = "given points"
    else:
        search = _optimise(optimize, run, max_evals)
    best = _best(points)
    return {"points": points, "best": best, "objective_name": spec.objective
            + (f" per {spec.per}" if spec.per else ""), "search": search,
            "computed": sum(not p["reused"] for p in points),
            "reused": sum(bool(p["reused"]) for p in points),
            "wall_time_s": time.perf_counter() - start,
            "provenance": {"model": scene.name, "scene": str(scene.path),
                           "spec": {k: v for k, v in vars(spec).items()},
                           "roles": roles}}


def _grid(grid, run, spec, roles, text, cache, workers, scheduler, progress) -> None:
    """Every grid point: those not stored yet on Dask (workers > 0 or a scheduler), else here."""
    todo = [p for p in grid if cache.get(point_key(spec, p, text)) is None]
    if todo and (workers or scheduler):
        from dask.distributed import Client

        from ..cluster import local_cluster
        cluster = None if scheduler else local_cluster(workers)
        with Client(scheduler or cluster) as client:
            futures = client.map(_evaluate_record, [spec] * len(todo), todo,
                                 [roles] * len(todo), pure=False)
            for point, record in zip(todo, client.gather(futures)):
                cache.put(point_key(spec, point, text), {**record, "reused": True})
        if cluster is not None:
            cluster.close()
        done = {point_key(spec, p, text) for p in todo}
    else:
        done = set()
    bar = None
    if progress:
        from ...console import progress_bar
        bar = progress_bar(total=len(grid), desc="codesign", unit="point", leave=False)
    for point in grid:
        record = run(point)
        if point_key(spec, point, text) in done:
            record["reused"] = False           # computed on Dask in this study
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()


def _optimise(box: dict, run, max_evals: int) -> str:
    """Maximise over the box; returns how (the search's name)."""
    from scipy.optimize import minimize, minimize_scalar
    names = list(box)
    lo = np.array([box[n][0] for n in names], float)
    hi = np.array([box[n][1] for n in names], float)
    if np.any(hi <= lo):
        raise InputError(f"--optimize: expected LO < HI for each of {', '.join(names)}")

    def cost(x) -> float:
        record = run(dict(zip(names, np.atleast_1d(x).tolist())))
        value = record["objective"]
        return math.inf if not record["valid"] or value is None else -float(value)
    if len(names) == 1:
        minimize_scalar(cost, bounds=(lo[0], hi[0]), method="bounded",
                        options={"xatol": 1e-3 * (hi[0] - lo[0]), "maxiter": max_evals})
        return "bounded Brent (scipy minimize_scalar)"
    minimize(cost, 0.5 * (lo + hi), method="Nelder-Mead", bounds=list(zip(lo, hi)),
             options={"maxfev": max_evals, "xatol": 1e-3, "fatol": 1e-6})
    return "Nelder-Mead with bounds (scipy minimize)"


def _best(points: list[dict]) -> dict | None:
    """The valid point with the largest objective (None when none is valid)."""
    valid = [p for p in points if p["valid"] and p["objective"] is not None]
    if not valid:
        return None
    top = max(valid, key=lambda p: p["objective"])
    return {"params": top["params"], "objective": top["objective"],
            "error_95": top["error_95"]}
