"""A MoorDyn mooring at rest, for the linear model: the forces on its Coupled points and their
stiffness, from MoorDyn's own lines brought to rest.

The plant carries the lines' quasi-static part itself (plant.moordyn_loads):

    F_lin(P) = F_0 + J (P - P_0)      (n-frame, N; P the Coupled points' positions, m)

with F_0 the forces on the points with the lines at rest at the scene's pose P_0, and
J = dF/dP (3n x 3n, N/m) their stiffness there. MoorDyn, stepped beside the plant, supplies
only what is left, F_MoorDyn - F_lin. So linearisation, design, Bode plots and bounds see the
mooring's pull and stiffness (a plate held by three chains has surge, sway and yaw restoring
that hydrostatics lack), and a run is still MoorDyn's lines to round-off.

How: the settling twin (plant.moordyn_system: SETTLE_DRAG times the drag) brought to rest at
P_0, then, for each coordinate of each point, moved by +-STEP_M over RAMP_S and brought to rest
again: central differences. Coupled points that no line or free point joins (RM3's three
fairleads, each on its own chain) do not pull on each other: they are moved together, so a
mooring costs 6 moves per point of its largest joined group, not 6 per point. The forces at
rest are means over MEAN_WINDOW_S (the twin's slowest swings outlast its drag). J's error is
that of those means (MEAN_TOL of the forces) over 2 STEP_M, plus the curvature over STEP_M;
on RM3, J is MoorPy's analytic quasi-static stiffness to 2.4 % of its largest entry
(tests/plant/test_moordyn_statics.py). RM3 costs 8.5 s once, the catalogue sphere's chains 3 s.

What the linear model leaves out: the lines' damping (their drag) and their mass; RM3's surge
swings 5-6 % slower in a run than the linear model says (tests/features/sim/test_moordyn.py).
Computed once per file, pose, environment and MoorDyn version, and kept in the cache; the
catalogue's ship beside their lines files (`shipped_statics`).
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..cache import ServedLog
from ..console import status
from ..errors import SceneError
from ..scene import TO_MOORDYN, read_moordyn
from .moordyn_system import (SETTLE_MAX_S, captured_output, environment_of, input_texts,
                             library, moordyn_version)

STEP_M = 0.2             # m: each Coupled point coordinate moved by +-STEP_M
RAMP_S = 2.0             # s over which the twin's point is moved there (no jolt to the lines)
SAMPLE_S = 0.5           # s between the twin's force samples ...
MEAN_WINDOW_S = 20.0     # ... averaged over windows longer than its slowest swing (RM3's
                         # buoys: 17.6 s, +-50 N on 167 kN that its drag barely damps) ...
MEAN_TOL = 2e-5          # ... until two windows' means agree to this share of the forces


_STATICS_SERVED = ServedLog("statics_served")


def recording_served_statics():
    """`with recording_served_statics() as served:` the (lines file, key, statics) asked for
    while it is active, in order, a key again each time it is asked for
    (models/generate_hydro.py --ship-fits keeps the first); off otherwise."""
    return _STATICS_SERVED.recording()


def shipped_statics(lines_file) -> Path:
    """Where statics ship beside a lines file (the catalogue's): {key: statics} as JSON,
    found only for the same file, pose, environment, settings and MoorDyn version."""
    return Path(lines_file).with_suffix(".statics.json")


def _shipped(lines_file, key: str) -> dict | None:
    try:
        return json.loads(shipped_statics(lines_file).read_text()).get(key)
    except (OSError, ValueError, AttributeError):      # none shipped, or not ours: make it
        return None


@dataclass(frozen=True)
class MooringStatics:
    """One mooring at rest at the pose P_0: F_0 (3, n) and J (3n, 3n), n-frame, points in the
    file's Coupled order, J's rows and columns [x1 y1 z1 x2 ...]."""
    force: np.ndarray         # N
    stiffness: np.ndarray     # dF/dP, N/m (negative definite for a restoring mooring)
    report: dict


def mooring_statics(scene, mooring, P0: np.ndarray) -> MooringStatics:
    """F_0 and J of `mooring` (a [[mooring]] type = "moordyn") with its Coupled points at the
    n-frame positions P0 (3, n), from the cache or made (module docs). SceneError when MoorDyn
    cannot bring the lines to rest."""
    from ..atomic import write_bytes
    from ..cache import cache_dir, load_or_make
    md = library()
    data = read_moordyn(mooring.file, f"{scene.path}: mooring '{mooring.name}'.file")
    environment = environment_of(scene, mooring, data)
    _, twin = input_texts(data, environment, P0)
    key = hashlib.sha256(json.dumps([twin, np.asarray(P0, float).tolist(), moordyn_version(md),
                                     STEP_M, RAMP_S, SAMPLE_S, MEAN_WINDOW_S, MEAN_TOL]).encode()).hexdigest()

    def make(path):
        status(f"{mooring.file}: bringing MoorDyn's lines to rest at {1 + 2 * len(_moves(data))} "
               f"poses for the linear model's pull and stiffness (once; cached)", __name__)
        try:
            solved = _solve(md, data, twin, P0, f"{mooring.file}")
        except RuntimeError as exc:                    # MoorDyn's own failure
            dtm = data.option("dtM")
            raise SceneError(
                f"{mooring.file}: MoorDyn failed while bringing the lines to rest for the "
                f"linear model ({exc}). Remedy: a smaller MoorDyn time step (the file's dtM, "
                f"now {f'{dtm:g} s' if dtm else 'its default'}), or fewer or longer segments "
                f"(NumSegs)") from None
        write_bytes(path, json.dumps(solved).encode())

    solved = _shipped(mooring.file, key) or load_or_make(
        cache_dir() / "moordyn" / f"statics-{key}.json", lambda path: json.loads(path.read_bytes()),
        make, what="MoorDyn mooring statics")
    _STATICS_SERVED.note((mooring.file, key, solved))
    flip = np.tile(TO_MOORDYN, P0.shape[1])
    F = np.asarray(solved["force"]) * flip                 # MoorDyn's frame -> n-frame
    J = flip[:, None] * np.asarray(solved["jacobian"]) * flip[None, :]
    return MooringStatics(F.reshape(-1, 3).T, J, {**solved["report"], "environment": environment})


def _solve(md, data, twin: str, P0, where: str) -> dict:
    import tempfile
    from pathlib import Path
    with tempfile.TemporaryDirectory(prefix="mbcontrol-moordyn-statics-") as folder:
        path, log = Path(folder) / "twin.txt", Path(folder) / "moordyn.log"
        path.write_text(twin)
        x0 = np.ascontiguousarray((np.asarray(P0, float).T * TO_MOORDYN).ravel())
        with captured_output(log):
            handle = md.Create(str(path))
            try:
                md.Init(handle, x0, np.zeros_like(x0))
                took, F0 = _held_mean(md, handle, x0, 0.0, where, "at the rest pose")
                rest_state = md.Serialize(handle)
                J = np.zeros((x0.size, x0.size))
                for moved in _moves(data):
                    pushed = []
                    for sign in (1.0, -1.0):
                        md.Deserialize(handle, rest_state)
                        step = np.zeros_like(x0)
                        step[list(moved)] = sign * STEP_M
                        md.Step(handle, x0, step / RAMP_S, took, RAMP_S)   # moved smoothly ...
                        pushed.append(_held_mean(md, handle, x0 + step, took + RAMP_S, where,
                                                 f"with coordinates {moved} moved")[1])
                    for c, rows in moved.items():                  # ... and held there
                        J[rows, c] = (pushed[0][rows] - pushed[1][rows]) / (2 * STEP_M)
            finally:
                md.Close(handle)
    return {"force": F0.tolist(), "jacobian": J.tolist(),
            "report": {"settle_time_s": took, "step_m": STEP_M, "mean_tolerance": MEAN_TOL}}


def _moves(data) -> list[dict]:
    """The twin's moves: each a dict {flat coordinate moved: the flat rows of the points
    joined to it}, one coordinate per group of joined Coupled points (joined through lines and
    free points; anchors join nothing)."""
    parent = {p.id: p.id for p in data.points}

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i
    for line in data.lines:
        a, b = line.attach_a, line.attach_b
        if data.point(a).kind != "fixed" and data.point(b).kind != "fixed":
            parent[root(a)] = root(b)
    groups = {}
    for j, p in enumerate(data.coupled):
        groups.setdefault(root(p.id), []).append(j)
    rows = {g: [3 * j + a for j in members for a in range(3)] for g, members in groups.items()}
    return [{3 * members[k] + axis: rows[g] for g, members in groups.items() if k < len(members)}
            for k in range(max(map(len, groups.values()))) for axis in range(3)]


def _held_mean(md, handle, x, t0: float, where: str, what: str):
    """(time held, s; the points' mean forces, flat, MoorDyn's frame, N) with the points held
    at x until two consecutive MEAN_WINDOW_S means agree to MEAN_TOL of their size."""
    per_window, t, means, samples = int(MEAN_WINDOW_S / SAMPLE_S), t0, [], []
    v = np.zeros_like(x)
    while t - t0 < SETTLE_MAX_S:
        samples.append(np.asarray(md.Step(handle, x, v, t, SAMPLE_S)))
        t += SAMPLE_S
        if len(samples) == per_window:
            means.append(np.mean(samples, axis=0))
            samples = []
            if len(means) > 1:
                change = np.max(np.abs(means[-1] - means[-2])) / max(np.max(np.abs(means[-1])), 1.0)
                if change < MEAN_TOL:
                    return t - t0, means[-1]
    raise SceneError(f"{where}: MoorDyn's lines do not come to rest {what}: after "
                     f"{SETTLE_MAX_S:g} s of heavily damped settling the forces' "
                     f"{MEAN_WINDOW_S:g}-s means still change by {change:.2g} of their size; "
                     f"check the lines' lengths, weights and anchors: the linear model needs "
                     f"the mooring's static equilibrium")
