"""MoorDyn, the library, for one `[[mooring]] type = "moordyn"`: created, silenced, stepped.

Each mooring gets its own MoorDyn system, made from the checked copy of its input file
(`mbcontrol.scene.moordyn_file.run_text`: the file's tables and options, its Coupled points at
the run's initial pose, console and file output off) written to a private temporary folder,
never beside the user's file. `Init` runs MoorDyn's own initial-condition solve (dynamic
relaxation) with the Coupled points held at that pose. MoorDyn prints to the process's
standard output; creation and initialisation run with it captured, and what it said is quoted
when it fails. Frames are converted here and only here: the plant speaks the n-frame (NED),
MoorDyn its z-up frame (`TO_MOORDYN`).
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

from ..errors import SceneError, SimulationError
from ..scene import TO_MOORDYN, read_moordyn, run_text


SETTLE_DRAG = 20.0       # the settling twin's drag, times the file's: critically damps the lines
SETTLE_DT_DIVISOR = 2.0  # ... and its dtM, the file's over this: the added drag stiffens it
SETTLE_STEP_S = 1.0      # s of the twin per step
SETTLE_WINDOW_S = 10.0   # s over which the forces must stop changing ...
SETTLE_TOL = 1e-3        # ... by this fraction of their size
SETTLE_MAX_S = 300.0     # s: give up (the run's report says so)


def library():
    """The moordyn module; SceneError with the reason when it cannot be imported (no wheel
    for this platform, or not installed)."""
    try:
        import moordyn
    except Exception as exc:              # ImportError, or a wheel the loader refuses
        raise SceneError(f"MoorDyn moorings need the moordyn package (pip install moordyn, "
                         f"a wheel for Linux, macOS and Windows); it cannot be imported "
                         f"here: {type(exc).__name__}: {exc}") from None
    return moordyn


@contextlib.contextmanager
def captured_output(log: Path):
    """Standard output and error of this process, C++ included, into `log` meanwhile."""
    import ctypes
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with open(log, "ab") as sink:
        os.dup2(sink.fileno(), 1)
        os.dup2(sink.fileno(), 2)
        try:
            yield
        finally:
            libc.fflush(None)
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)


def _said(log: Path, lines: int = 6) -> str:
    try:
        text = [l.strip() for l in log.read_text(errors="replace").splitlines() if l.strip()]
    except OSError:
        return ""
    keep = [l for l in text if "ERR" in l or "rror" in l] or text
    return " | ".join(keep[-lines:])[:600]


def input_texts(data, environment: dict, P0) -> tuple[str, str]:
    """(the run's input file, its settling twin's: SETTLE_DRAG times the drag at dtM over
    SETTLE_DT_DIVISOR) with the Coupled points at the n-frame positions P0 (3, n) and the
    environment the run takes (`environment`)."""
    overrides = {"WtrDnsty": environment["water_density_kg_m3"],
                 "WtrDpth": environment["depth_m"], "g": environment["g_m_s2"]}
    rest = np.asarray(P0).T * TO_MOORDYN
    dtm = data.option("dtM")
    twin = run_text(data, rest, {**overrides, **({"dtM": dtm / SETTLE_DT_DIVISOR} if dtm else {})},
                    SETTLE_DRAG)
    return run_text(data, rest, overrides), twin


class MoorDynSystem:
    """One mooring's MoorDyn system, its Coupled points initialised at n-frame positions P0
    (3, n) with velocities V0 (m, m/s)."""

    def __init__(self, scene, mooring, P0: np.ndarray, V0: np.ndarray):
        self.name = mooring.name
        self.md = library()
        data = read_moordyn(mooring.file, f"{scene.path}: mooring '{mooring.name}'.file")
        self.data = data
        self.environment = environment_of(scene, mooring, data)
        self._folder = tempfile.TemporaryDirectory(prefix="mbcontrol-moordyn-")
        folder = Path(self._folder.name)
        path, self.log = folder / "lines.txt", folder / "moordyn.log"
        text, twin = input_texts(data, self.environment, P0)
        path.write_text(text)
        self.n_points = P0.shape[1]
        self.handle, self.settled = None, None
        try:
            with captured_output(self.log):
                self.handle = self.md.Create(str(path))
                self.md.Init(self.handle, self._md(P0), self._md(V0))
                if mooring.settle:
                    self.settled = self._settled(twin, folder / "settle.txt", P0)
        except RuntimeError:
            self.close()
            raise SimulationError(f"mooring '{self.name}' ({mooring.file}): MoorDyn could not "
                                  f"start: {_said(self.log)}") from None
        self.lines = [self.md.GetLine(self.handle, i + 1) for i in range(len(data.lines))]
        import cmoordyn             # the wrapper's own calls, without its per-call list copies
        self._step, self._tension = cmoordyn.step, cmoordyn.line_get_node_ten
        self._node_position = cmoordyn.line_get_node_pos
        self._last_node = [self.md.GetLineNumberNodes(l) - 1 for l in self.lines]
        self.dt_mooring = data.option("dtM")

    def _settled(self, twin: str, twin_file: Path, P0) -> dict:
        """`_settle`, its state kept in the cache (keyed by the twin's input, the pose and
        MoorDyn's version, with its SHA-256 checked before MoorDyn reads it): RM3's lines take
        2 s to settle, each run of a sweep would pay it."""
        from ..cache import cache_dir, load_or_make
        from ..atomic import write_bytes
        key = hashlib.sha256(twin.encode() + np.asarray(P0, float).tobytes()
                             + moordyn_version(self.md).encode()).hexdigest()
        report = {}

        def make(path):
            twin_file.write_text(twin)
            report.update(self._settle(str(twin_file), P0))
            state = self.md.Serialize(self.handle) if report["settled"] else b""
            meta = json.dumps({k: v for k, v in report.items()}).encode()
            write_bytes(path, b"%s\n%s\n%s" % (hashlib.sha256(state).hexdigest().encode(),
                                                 meta, state))

        def read(path):
            digest, meta, state = path.read_bytes().split(b"\n", 2)
            if hashlib.sha256(state).hexdigest().encode() != digest:
                raise ValueError("the MoorDyn state does not match its SHA-256")
            return json.loads(meta), state

        meta, state = load_or_make(cache_dir() / "moordyn" / f"settled-{key}.bin", read, make,
                                   what="settled MoorDyn state")
        if not report:                       # read from the cache
            if not state:
                return {**self._unsettled(meta["settle_error"]), "cached": True}
            self.md.Deserialize(self.handle, state)
        return {**meta, "cached": not report}

    def _settle(self, twin_file: str, P0) -> dict:
        """Bring the lines to rest with the Coupled points held at P0: a twin system with
        SETTLE_DRAG times the drag, stepped SETTLE_STEP_S at a time until the points' forces
        change by less than SETTLE_TOL of their size over SETTLE_WINDOW_S (at most
        SETTLE_MAX_S), then its state copied into this one. MoorDyn's own relaxation stops
        short on some systems: RM3's subsurface buoys leave its fairleads at 4 kN, 168 kN at
        rest (tests/features/sim/test_moordyn.py)."""
        twin = self.md.Create(twin_file)
        back, change = int(SETTLE_WINDOW_S / SETTLE_STEP_S), None
        try:
            x, v = self._md(P0), np.zeros(3 * self.n_points)
            self.md.Init(twin, x, v)
            history, t = [], 0.0
            while t < SETTLE_MAX_S:
                try:
                    history.append(np.asarray(self.md.Step(twin, x, v, t, SETTLE_STEP_S)))
                except RuntimeError:
                    return self._unsettled(f"MoorDyn failed on the damped twin at t = {t:g} s")
                t += SETTLE_STEP_S
                if len(history) > back:
                    scale = max(float(np.max(np.abs(history[-1]))), 1.0)
                    change = float(np.max(np.abs(history[-1] - history[-1 - back]))) / scale
                    if change < SETTLE_TOL:
                        break
            if t >= SETTLE_MAX_S:
                return self._unsettled(f"the forces still change by {change:.2%} per "
                                       f"{SETTLE_WINDOW_S:g} s after {SETTLE_MAX_S:g} s")
            self.md.Deserialize(self.handle, self.md.Serialize(twin))
        finally:
            self.md.Close(twin)
        return {"settle_time_s": t, "settle_change": change, "settled": True}

    def _unsettled(self, why: str) -> dict:
        """MoorDyn's own initial condition is kept, and the run says why."""
        warnings.warn(f"mooring '{self.name}': the lines could not be brought to rest before "
                      f"t = 0 ({why}); the run starts from MoorDyn's own initial condition, "
                      f"which may not be static (see the early tensions)", RuntimeWarning,
                      stacklevel=5)
        return {"settled": False, "settle_error": why}

    @staticmethod
    def _md(P: np.ndarray) -> np.ndarray:
        """n-frame (3, n) -> MoorDyn's flat [x1 y1 z1 x2 ...] (z up)."""
        return np.ascontiguousarray((np.asarray(P, float).T * TO_MOORDYN).ravel())

    def forces(self) -> np.ndarray:
        """The lines' forces on the Coupled points now (3, n), n-frame, N."""
        return self.step(None, None, 0.0, 0.0)

    def step(self, P, V, t: float, dt: float) -> np.ndarray:
        """Advance MoorDyn from t to t + dt (s) with the points at P, moving at V (n-frame,
        (3, n), at t); the forces on them at t + dt (3, n), n-frame, N. SimulationError with
        the time, the mooring and a remedy when MoorDyn fails or returns non-finite forces."""
        zeros = [0.0] * (3 * self.n_points)
        flat = self.step_flat(self._md(P).tolist() if P is not None else zeros,
                              self._md(V).tolist() if V is not None else zeros, t, dt)
        return flat.reshape(-1, 3).T * TO_MOORDYN[:, None]

    def step_flat(self, x: list, v: list, t: float, dt: float) -> np.ndarray:
        """`step` in MoorDyn's own terms, for the run's loop: flat lists [x1 y1 z1 x2 ...] in
        its frame in, its flat forces (3n,) out (the frame conversion is the caller's)."""
        try:
            forces = self._step(self.handle, x, v, t, dt)
        except RuntimeError as exc:
            raise self._failed(t, str(exc)) from None
        if not math.isfinite(sum(forces)):       # a NaN or an inf anywhere: 1 us, not 2
            raise self._failed(t, "non-finite forces on the Coupled points")
        return np.array(forces)

    def _failed(self, t: float, what: str) -> SimulationError:
        dtm = f"{self.dt_mooring:g} s" if self.dt_mooring else "its default"
        return SimulationError(
            f"mooring '{self.name}': MoorDyn failed between t = {t:.4g} s and the next step: "
            f"{what}. Remedy: a smaller MoorDyn time step (the file's dtM, now {dtm}), fewer "
            f"or longer segments (NumSegs), or a smaller plant dt")

    def tensions(self) -> np.ndarray:
        """(2, n_lines) tension magnitudes (N) at end A (anchor) and end B (fairlead)."""
        ten, out = self._tension, np.empty((2, len(self.lines)))
        for j, (line, last) in enumerate(zip(self.lines, self._last_node)):
            out[0, j] = math.hypot(*ten(line, 0))
            out[1, j] = math.hypot(*ten(line, last))
        return out

    def bed_clearance(self, j: int) -> float:
        """Height of line j's lowest node above the sea bed (m; MoorDyn's bed is flat at the
        run's depth)."""
        position = self._node_position
        return min(position(self.lines[j], i)[2] for i in range(self._last_node[j] + 1)) \
            + self.environment["depth_m"]

    def close(self) -> None:
        if self.handle is not None:
            with contextlib.suppress(Exception), captured_output(self.log):
                self.md.Close(self.handle)
            self.handle = None
        self._folder.cleanup()


def moordyn_version(md) -> str:
    try:
        from importlib.metadata import version
        return version("moordyn")
    except Exception:                     # a source build without metadata
        return getattr(md, "__version__", "unknown")


def environment_of(scene, mooring, data) -> dict:
    """Water density, depth and gravity MoorDyn runs with: the file's (MoorDyn's defaults
    where it gives none), or the scene's [water] with environment = "scene"."""
    if mooring.environment == "scene":
        if not math.isfinite(scene.water.depth):
            raise SceneError(f"{scene.path}: mooring '{mooring.name}'.environment: \"scene\" "
                             f"takes the water depth from [water], which is infinite here; "
                             f"MoorDyn needs the sea bed: give [water] depth, or use the "
                             f"file's (environment = \"file\")")
        return {"source": "scene", "water_density_kg_m3": scene.water.rho,
                "depth_m": scene.water.depth, "g_m_s2": scene.water.g}
    # MoorDyn's own rule: at least as deep as the lowest point
    depth = max(data.option("WtrDpth", 0.0), *(-p.position[2] for p in data.points))
    if depth <= 0:
        raise SceneError(f"{mooring.file}: no water depth: the options give no WtrDpth and "
                         f"no point lies below the surface; add '<depth> WtrDpth', or use the "
                         f"scene's (environment = \"scene\")")
    return {"source": "file", "water_density_kg_m3": data.option("WtrDnsty", 1025.0),
            "depth_m": depth, "g_m_s2": data.option("g", data.option("gravity", 9.80665))}
