"""An identification problem: measured regular-wave runs, the plant that should reproduce them,
the parameters to fit and the cost, evaluated with exact sensitivities.

Each run is simulated on its own clock: the model starts at rest `settle` seconds before the
run's steady window and is driven by the incident wave measured for that run (amplitude and
phase at the model, from the calibration), so at the window's samples model and measurement
are directly comparable. Runs that free the same DOFs share one plant (frozen as the run
says), compiled once; they are stepped one compiled call per run, or with batch=True all
together in one call (`simulate_batch`'s machinery). With `jacobian=True` the plant carries
its forward sensitivities (`mbcontrol.sim.sensitivity`).

Costs (residual vector r, cost 1/2 |r|^2), per run and free channel:
- "harmonic": (|Y_model| - |Y_meas|) / |Y_meas| w_c, the relative error of the first-harmonic
  amplitude (dimensionless); with phase=True also the phase error of Y_model / Y_meas (rad),
  weighted by w_c;
- "peaks": the seed's Eq. 67: the peaks and lows of each period of the window, model minus
  measured, divided by the channel scale s_c (the measured amplitude at the run's frequency,
  averaged over the channel's runs) times w_c; Eq. 67's error per channel is reported in the
  channel's unit squared;
- "timeseries": output error y_model(t) - y_meas(t) at the window's samples (resampled to
  `samples_per_period` per period), / s_c w_c.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ... import defaults, waves
from ...errors import InputError, UnknownName
from ...plant import Fidelity, build_plant
from ...scene import load_scene
from ...sim import batch_states, plant_outputs, sensitivity_name, sensitivity_plant
from .costs import harmonic, harmonic_weights, peak_low_indices, peaks_and_lows, whole_periods

COSTS = ("harmonic", "peaks", "timeseries")


@dataclass(frozen=True)
class FitParameter:
    """A parameter to identify: its plant name, initial value, bounds (its unit) and whether
    it is fitted as log(value) (for positive parameters: scale factors, damping)."""
    name: str
    initial: float
    lo: float
    hi: float
    log: bool = True

    def __post_init__(self):
        if not (self.lo < self.hi) or not (self.lo <= self.initial <= self.hi):
            raise InputError(f"fit parameter {self.name}: expected lo < hi and the initial value "
                             f"{self.initial:g} within [{self.lo:g}, {self.hi:g}]")
        if self.log and self.lo <= 0:
            raise InputError(f"fit parameter {self.name}: a log transform needs lo > 0, got "
                             f"{self.lo:g} (give a positive lower bound or log=False)")

    def to_theta(self, value):
        return np.log(value) if self.log else np.asarray(value, float)

    def from_theta(self, theta):
        return np.exp(theta) if self.log else np.asarray(theta, float)

    @property
    def bounds(self) -> tuple[float, float]:
        return float(self.to_theta(self.lo)), float(self.to_theta(self.hi))


@dataclass(frozen=True)
class Run:
    """One measured regular-wave run, ready to fit (see `mbcontrol.studies.identify.records`).

    time (s) and channels (name -> samples, model units: m, rad) of the free DOFs; the steady
    window (s, on the run's clock); the incident wave at the model: eta(t) = amplitude
    cos(omega t + phase) (m, rad/s, rad, run clock); group: runs of a group share a plant,
    built from the scene with `freeze` (Fidelity.freeze entries) and `scene_parameters`.
    """
    name: str
    omega: float
    amplitude: float
    phase: float
    window: tuple[float, float]
    time: np.ndarray = field(repr=False)
    channels: dict = field(repr=False)
    group: str = ""
    freeze: tuple = ()
    scene_parameters: dict = field(default_factory=dict)
    source: str = ""
    notes: dict = field(default_factory=dict)

    @property
    def period(self) -> float:
        return 2 * math.pi / self.omega

    @property
    def free(self) -> tuple[str, ...]:
        return tuple(self.channels)


class Identification:
    """Runs, a scene and parameters to fit: residuals and their exact Jacobian in theta.

    scene: a catalogue name or scene path; runs: `Run`s; fit: `FitParameter`s (plant parameter
    names); outputs: measured channel -> plant output (e.g. {"Roll": "roll"}); params: fixed
    overrides of other plant parameters; weights: channel -> w_c (default 1); settle: s of
    simulation before each window (the model starts at rest: long enough for its slowest mode
    to die out, so that the window holds its steady response); ramp_periods: the simulated
    wave's half-cosine ramp; dt: step (s; default "identify.dt", 0.01 s, and settle "identify.settle",
    60 s, in mbcontrol.defaults); direction: wave heading in the n-frame (rad);
    batch: step a plant's runs together in one compiled call, each for the longest run's
    duration (True), or one call per run for its own duration (False, the default: measured
    10-20 % faster on the flume data, `benchmarks/identify.py`, as a compiled call of 512
    steps leaves little overhead to share and the batch pays the longest window for every
    run); drop_absent: a fit parameter that no run's plant has (its joint is blocked in every run)
    is dropped with a warning instead of raising.
    """

    def __init__(self, scene, runs, fit, *, outputs: dict, cost: str = "harmonic",
                 phase: bool = False, weights: dict | None = None, params: dict | None = None,
                 dt: float | None = None, settle: float | None = None, ramp_periods: float = 5.0,
                 direction: float = math.pi / 2, method: str = "rk4",
                 samples_per_period: int = 40, compiled: bool = True, batch: bool = False,
                 drop_absent: bool = False):
        if cost not in COSTS:
            raise InputError(f"cost {cost!r}: expected one of {', '.join(COSTS)}")
        if not runs:
            raise InputError("identification: no runs given")
        names = [p.name for p in fit]
        if len(set(names)) != len(names):
            raise InputError(f"identification: a parameter is listed twice in {names}")
        dt, settle = defaults.resolve("identify.dt", dt), defaults.resolve("identify.settle", settle)
        self.options = dict(cost=cost, phase=phase, weights=weights, params=params, dt=dt,
                            settle=settle, ramp_periods=ramp_periods, direction=direction,
                            method=method, samples_per_period=samples_per_period,
                            compiled=compiled, batch=batch)
        self.scene, self.runs, self.fit = scene, list(runs), list(fit)
        self.outputs, self.cost, self.phase = dict(outputs), cost, bool(phase)
        self.weights = {c: 1.0 for c in self.outputs} | dict(weights or {})
        self.params = dict(params or {})
        self.dt, self.settle, self.ramp_periods = float(dt), float(settle), float(ramp_periods)
        self.direction, self.method, self.compiled = float(direction), method, compiled
        self.batch = bool(batch)
        self.samples_per_period = int(samples_per_period)
        for run in self.runs:
            unknown = [c for c in run.channels if c not in self.outputs]
            if unknown:
                raise InputError(f"{run.source or run.name}: channel(s) {unknown} have no plant "
                                 f"output; expected some of {sorted(self.outputs)}")
        self.groups: dict = {}
        for i, run in enumerate(self.runs):
            key = (tuple(run.freeze), tuple(sorted(run.scene_parameters.items())))
            self.groups.setdefault(key, []).append(i)
        self.duration = self.settle + max(r.window[1] - r.window[0] for r in self.runs)
        self.simulations = 0
        self.time_blocks = None         # set by residuals(): see there
        self._plants, self._sensitivity = {}, {}
        self._measured = [self._measure(run) for run in self.runs]
        self.scales = self._channel_scales()
        self.check(drop_absent)

    @property
    def scene_name(self) -> str:
        return load_scene(self.scene).name

    # ------------------------------------------------------------------ theta <-> values
    def theta0(self) -> np.ndarray:
        return np.array([p.to_theta(p.initial) for p in self.fit], float)

    def values(self, theta) -> dict:
        return {p.name: float(p.from_theta(t)) for p, t in zip(self.fit, np.asarray(theta))}

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = zip(*(p.bounds for p in self.fit)) if self.fit else ((), ())
        return np.array(lo, float), np.array(hi, float)

    # ------------------------------------------------------------------ plants
    def plant(self, key):
        """The plant of a group of runs (built once; hydro corrections as parameters)."""
        if key not in self._plants:
            freeze, scene_params = key
            scene = load_scene(self.scene, dict(scene_params) or None)
            fidelity = Fidelity(freeze=freeze) if freeze else None
            self._plants[key] = build_plant(scene, fidelity=fidelity, hydro_corrections=True)
        return self._plants[key]

    def check(self, drop_absent: bool = False) -> None:
        """Build every group's plant; KeyError for a parameter none of them has (or, with
        drop_absent, a warning and the fit parameter dropped)."""
        known = set()
        for key in self.groups:
            known |= set(self.plant(key).parameters)
        absent = [p.name for p in self.fit if p.name not in known]
        if drop_absent and self.fit:
            self.fit = [p for p in self.fit if p.name in known]
            if self.fit:             # present but without effect (drag on a blocked DOF)
                _, J = self.residuals(self.theta0(), jacobian=True)
                absent += [p.name for p, col in zip(self.fit, J.T) if not np.any(col)]
                self.fit = [p for p in self.fit if p.name not in absent]
                self._sensitivity.clear()
            if absent:
                warnings.warn(f"not fitted: {', '.join(absent)}: no effect on these runs "
                              f"(their DOF is blocked in every run given)", stacklevel=3)
        unknown = [n for n in [p.name for p in self.fit] + list(self.params) if n not in known]
        if unknown:
            raise UnknownName(f"{self.scene}: unknown parameter(s) {unknown}; the plant has "
                              f"{', '.join(sorted(known))}")

    def _sensitivity_plant(self, key):
        if key not in self._sensitivity:
            plant = self.plant(key)
            names = [p.name for p in self.fit if p.name in plant.parameters]
            channels = sorted({c for i in self.groups[key] for c in self.runs[i].channels})
            self._sensitivity[key] = sensitivity_plant(
                plant, names, [self.outputs[c] for c in channels])
        return self._sensitivity[key]

    # ------------------------------------------------------------------ measurement
    def _measure(self, run) -> dict:
        """Per channel: the measured first harmonic, peaks and lows, and resampled window."""
        start, end, n = whole_periods(run.time, run.omega, *run.window)
        t_res = start + np.arange(n * self.samples_per_period) * run.period / self.samples_per_period
        out = {}
        for channel, y in run.channels.items():
            out[channel] = {"harmonic": harmonic(run.time, y, run.omega, start, end),
                            "peaks": peaks_and_lows(run.time, y, run.omega, start, end),
                            "samples": np.interp(t_res, run.time, y), "t": t_res}
        return out

    def _channel_scales(self) -> dict:
        """s_c: the mean measured first-harmonic amplitude of each channel over its runs."""
        amplitudes: dict = {}
        for m in self._measured:
            for channel, d in m.items():
                amplitudes.setdefault(channel, []).append(abs(d["harmonic"]))
        return {c: float(np.mean(a)) for c, a in amplitudes.items()}

    # ------------------------------------------------------------------ simulation
    def _duration(self, run) -> float:
        """Simulated time (s): the batch's common one, or the run's own settle + window."""
        return self.duration if self.batch else self.settle + run.window[1] - run.window[0]

    def _shift(self, run) -> float:
        """t_shift: the run's clock minus the simulation's (the window ends at the end)."""
        return run.window[1] - self._duration(run)

    def _wave(self, run):
        return waves.regular(2 * run.amplitude, run.period,
                             phase=run.phase + run.omega * self._shift(run),
                             direction=self.direction, ramp_time=self.ramp_periods * run.period)

    def simulate(self, values: dict, jacobian: bool = False) -> list[dict]:
        """Per run: {channel: (t_run, y, dy/dp columns or None)} over the steady window, on
        the run's clock, at the simulation's samples; dy columns follow `self.fit` (zeros for
        parameters the run's plant does not have)."""
        results = [None] * len(self.runs)
        for key, members in self.groups.items():
            base = self.plant(key)
            plant = self._sensitivity_plant(key) if jacobian else base
            overrides = {n: v for n, v in {**self.params, **values}.items()
                         if n in plant.parameters}
            p = plant.params(**overrides)
            runs = [self.runs[i] for i in members]
            batches = [runs] if self.batch else [[r] for r in runs]
            stepped = []                                   # per run: (t, X of the run)
            for group in batches:
                t, X, _, _ = batch_states(plant, [self._wave(r) for r in group], [p],
                                          duration=self._duration(group[0]), dt=self.dt,
                                          method=self.method, compiled=self.compiled)
                stepped += [(t, X[c]) for c in range(len(group))]
            self.simulations += len(runs)
            for (t, Xc), i, run in zip(stepped, members, runs):
                shift = self._shift(run)
                keep = t >= run.window[0] - shift - 1e-9
                tw = t[keep]
                W = plant.excitation(self._wave(run), tw)
                U = np.zeros((tw.size, len(plant.inputs)))
                Y = plant_outputs(plant, Xc[keep], U, W, p, compiled=self.compiled)
                out = {}
                for channel in run.channels:
                    name = self.outputs[channel]
                    y = Y[:, plant.outputs.index(name)]
                    dy = None
                    if jacobian:
                        dy = np.zeros((tw.size, len(self.fit)))
                        for j, fp in enumerate(self.fit):
                            s = sensitivity_name(name, fp.name)
                            if s in plant.outputs:
                                dy[:, j] = Y[:, plant.outputs.index(s)]
                    out[channel] = (tw + shift, y, dy)
                results[i] = out
        return results

    # ------------------------------------------------------------------ residuals
    def residuals(self, theta, jacobian: bool = False):
        """r (and J = dr/dtheta with jacobian=True) of the cost at theta."""
        values = self.values(theta)
        sims = self.simulate(values, jacobian)
        dp = np.array([p.from_theta(t) if p.log else 1.0 for p, t in zip(self.fit, theta)])
        rows, jrows, blocks = [], [], []
        for run, meas, sim in zip(self.runs, self._measured, sims):
            for channel, (t, y, dy) in sim.items():
                blocks.append(len(rows))
                m, w = meas[channel], self.weights[channel]
                start, end, _ = whole_periods(run.time, run.omega, *run.window)
                if self.cost == "harmonic":
                    W = harmonic_weights(t, run.omega, start, end)
                    Y = complex(*(W @ y))
                    A, A_meas = abs(Y), abs(m["harmonic"])
                    rows.append(w * (A - A_meas) / A_meas)
                    if jacobian:
                        dY = W @ dy                                     # (2, n_fit)
                        jrows.append(w * (Y.real * dY[0] + Y.imag * dY[1]) / (A * A_meas))
                    if self.phase:
                        ratio = Y / m["harmonic"]
                        rows.append(w * np.angle(ratio))
                        if jacobian:      # d arg(Y) = (Re Y dIm - Im Y dRe) / |Y|^2
                            jrows.append(w * (Y.real * dY[1] - Y.imag * dY[0]) / A ** 2)
                elif self.cost == "peaks":
                    idx = peak_low_indices(t, y, run.omega, start, end)
                    scale = self.scales[channel] / w
                    model, measured = y[idx], m["peaks"]
                    if model.size != measured.size:
                        raise InputError(f"{run.name} {channel}: {model.size} modelled and "
                                         f"{measured.size} measured peaks and lows")
                    rows.extend((model - measured) / scale)
                    if jacobian:
                        jrows.extend(dy[idx] / scale)
                else:
                    scale = self.scales[channel] / w
                    model = np.interp(m["t"], t, y)
                    rows.extend((model - m["samples"]) / scale)
                    if jacobian:
                        jrows.extend(np.column_stack([np.interp(m["t"], t, dy[:, j])
                                                      for j in range(len(self.fit))]) / scale)
        r = np.array(rows, float)
        # consecutive residuals of one run and channel in time (peaks, timeseries): their
        # errors may be correlated, which fit.uncertainty allows for; harmonic ones stand alone
        self.time_blocks = (list(np.diff(blocks + [r.size])) if self.cost != "harmonic"
                            else [1] * r.size)
        if not jacobian:
            return r
        J = np.array(jrows, float).reshape(r.size, len(self.fit)) * dp[None, :]
        return r, J

    def cost_value(self, theta) -> float:
        r = self.residuals(theta)
        return 0.5 * float(r @ r)
