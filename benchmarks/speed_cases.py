"""The speed benchmark's cases, settings, records and error measure (see speed.py)."""
from __future__ import annotations

import sys
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline


TOL = 0.01                   # the accuracy every setting must meet (relative RMS)


RTF_TARGET = 20_000          # x real time, for the one- and two-body models


SPEEDUP_TARGET = 50          # x faster than the baseline, every model


RADIATION_TOLS = (None, 0.05, 0.1)           # None: the scene's own radiation_tol


CRUDE_RADIATION_METHODS = ("rk4", "exp-rk4")  # methods tried with the cruder radiation fits


ADAPTIVE = ("cvodes", "adams")


DT_LADDER = [8 * 2 ** (j / 4) for j in range(21)]      # Tp/8 ... Tp/256


ADAPTIVE_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)


ADAPTIVE_OUTPUT = 20                                   # output grid Tp/20 for adaptive methods


BASELINE_LADDER = [10 * 2 ** (j / 2) for j in range(9)]  # Tp/10 ... Tp/160


BASELINE_RTOLS = (1e-3, 1e-5)


REF_SS = 320                 # toolbox reference: RK4 at Tp/320 (checked against Tp/160)


REF_CONV = 160               # convolution reference: Tp/160 (checked against Tp/80)


REF_TARGET = TOL / 10        # a reference is halved in step until its check is below this


REF_MAX = 1280               # ... down to Tp/REF_MAX


FLOOR_RATIO = 0.8            # a step ladder stops when 2^(1/4) finer steps gain less than this


REPEAT_UNDER_S = 5.0                         # repeat a timing only when a run is shorter


ERROR_MEASURE = ("max over joint coordinates of RMS(y - y_ref)/RMS(y_ref) after the wave "
                 "ramp; y_ref a converged reference of the same equations")


@dataclass(frozen=True)
class Case:
    """A benchmark model: catalogue name, scene parameters, sea state, whether the real-time
    target applies."""
    scene: str
    params: dict | None
    hs: float
    tp: float
    rtf_target: bool
    label: str = ""

    @property
    def name(self) -> str:
        return self.label or self.scene


CASES = {
    "sphere": Case("sphere", None, 2.5, 9.67, True),
    "rm3": Case("rm3", None, 2.5, 8.0, True),
    "hinged_barge": Case("hinged_barge", None, 0.03, 1.1, True),
    "barge_chain": Case("barge_chain", {"N": 8}, 0.03, 1.1, False, "barge_chain N=8"),
}


@dataclass
class Trial:
    """One setting tried: side ("mbcontrol" | "baseline"), its parameters and the outcome."""
    model: str
    side: str
    method: str
    step: float | None = None        # dt or delta (s); the output grid for adaptive methods
    rtol: float | None = None
    radiation_tol: float | None = None
    states: int = 0
    record_s: float = 0.0            # simulated seconds of the timed run
    error: float = np.nan
    wall_s: float = np.nan
    runs: int = 0
    worst: str = ""                  # the coordinate with the largest error
    status: str = "ok"               # ok | unstable | failed: ... | skipped: ...
    chosen: bool = False
    extrapolated: bool = False       # timed on a shorter record than asked for
    note: str = ""

    @property
    def rtf(self) -> float:
        return self.record_s / self.wall_s if self.wall_s > 0 else np.nan

    @property
    def meets(self) -> bool:
        return self.status == "ok" and self.error <= TOL


@dataclass
class Result:
    case: Case
    toolbox: Trial | None = None
    baseline: Trial | None = None
    model_diff: float = np.nan
    ss_check: float = np.nan         # toolbox reference vs its check (the 2x coarser step)
    conv_check: float = np.nan       # convolution reference vs its check
    ss_k: int = REF_SS               # the references' steps: Tp/ss_k, Tp/conv_k
    conv_k: int = REF_CONV
    trials: list = field(default_factory=list)
    ss_reference: tuple | None = None   # (t, q) of the toolbox's converged reference
    model_diff_by_coordinate: dict = field(default_factory=dict)


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def coordinate_errors(t, q, t_ref, q_ref, after: float) -> np.ndarray:
    """Per column of q: RMS(q - q_ref)/RMS(q_ref) for t >= after, the reference interpolated
    to t by a cubic spline."""
    mask = t >= after
    ref = CubicSpline(t_ref, q_ref)(t[mask])
    return np.sqrt(np.mean((q[mask] - ref) ** 2, axis=0) / np.mean(ref ** 2, axis=0))


def coordinate_error(t, q, t_ref, q_ref, after: float) -> float:
    """The error measure: the largest of :func:`coordinate_errors`."""
    return float(np.max(coordinate_errors(t, q, t_ref, q_ref, after)))


def converged(run_at, k: int, after: float):
    """A reference run_at(k) -> (t, q) at step Tp/k, checked against Tp/(k/2); the step is
    halved while their difference exceeds REF_TARGET. Returns (k, ((t, q), difference))."""
    coarse, fine = run_at(k // 2), run_at(k)
    diff = coordinate_error(*coarse, *fine, after)
    while diff > REF_TARGET and 2 * k <= REF_MAX:
        k, coarse, fine = 2 * k, fine, run_at(2 * k)
        diff = coordinate_error(*coarse, *fine, after)
    return k, (fine, diff)


def grid_step(sea, target: float) -> float:
    """The step nearest `target` that divides the sea's repeat period (FFT synthesis)."""
    repeat = 2 * np.pi / sea.d_omega
    return repeat / max(1, round(repeat / target))
