"""fidelity="auto": simulate the full model and simplified candidates, keep the cheapest that
is accurate enough in the user's waves, and report every candidate with its error and cost.

Error of a candidate (stated in every report): the largest, over the compared signals and the
waves, of RMS(y - y_ref) / RMS(y_ref) after the wave's ramp, y_ref from the full model at the
same step. Compared signals: body DOFs "<body>__<Dof>" and PTO "<pto>__velocity"/"<pto>__power",
leaving out those whose reference RMS is below 1e-3 of the largest of their unit (m, rad, m/s,
W, ...): a signal that small is numerical noise in a model that cannot move it.
Cost: the wall time of simulate (its attrs["wall_time_s"], best of `repeats` runs at the same
step), the state count, and the compiled f's instruction count (4 evaluations per RK4 step), a
deterministic proxy for the stepping cost. The choice ranks by instructions, because walls of
millisecond runs are too noisy to rank by on a shared machine; the wall time vetoes a candidate
that is measured clearly slower (WALL_VETO, and by more than WALL_NOISE_S) and is reported for
every candidate.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from .. import defaults
from ..console import progress_bar
from ..plant import (Fidelity, FidelityError, ProcessPlant, as_wave_list, has_couplings,
                     plant_for)
from ..scene import Scene, load_scene
from ..sim import simulate

RADIATION_LADDER = (0.02, 0.05, 0.1, 0.2)   # looser fits tried after the scene's tolerance
# SIGNAL_FLOOR, the default "fidelity.signal_floor": signals below this share of their unit class's largest RMS: not compared
INSTRUCTION_TIES = 0.05  # instruction counts within 5 % of the fewest are ties: fewer states
                         # win, then the lower error (so an equal-cost model never beats the full)
WALL_VETO = 2.0         # a candidate measured this much slower than the fastest is not chosen:
                        # walls of equal-cost models varied by up to 1.5x on a loaded 2-core
                        # machine, too much to rank by, but a 2x slowdown is real ...
WALL_NOISE_S = 0.02     # ... unless it is under 20 ms: the sphere's 4,400-step runs take 3 ms,
                        # and one scheduler hiccup in the full model's runs (5.6 ms against
                        # 2.7 ms for its exact equal) vetoed it and flipped the choice
# STEPS_PER_PERIOD, the default "fidelity.steps_per_period": default dt = T_p / 200: RK4's error ~ (w dt)^4 ~ 1e-6 at the peak
ERROR_DEFINITION = ("max over compared signals and waves of RMS(y - y_ref) / RMS(y_ref) after "
                    "the wave ramp; y_ref: the full model at the same dt")


@dataclass
class Candidate:
    """One model tried: its options, measured error against the full model and its cost."""
    label: str
    fidelity: Fidelity
    error: float               # see ERROR_DEFINITION (dimensionless)
    worst_signal: str          # the signal with that error
    wall_s: float              # s, simulate's wall_time_s, best of `repeats`, summed over waves
    states: int
    instructions: int          # CasADi instructions of f (per evaluation; 4 per RK4 step)
    passed: bool
    role: str                  # "reference" | "single" | "combined"
    plant: ProcessPlant = field(repr=False, default=None)


@dataclass
class FidelityReport:
    """What auto chose and why: every candidate with its error and cost, and the evidence."""
    scene: str
    tol: float
    chosen: Candidate
    reference: Candidate
    candidates: list
    signals: tuple
    dt: float                  # s, the step every model was simulated with
    duration: float            # s
    t_start: float             # s, errors measured from here (end of the ramp)
    step_error: float          # the full model's error at dt against dt/2 (same measure)
    waves: list                # wave descriptions
    couplings: dict | None     # coupling_size of the scene (None: no coupling between bodies)
    freeze: dict | None        # freeze_report per free-joint DOF (None: no free joints)
    error_definition: str = ERROR_DEFINITION

    @property
    def fidelity(self) -> Fidelity:
        return self.chosen.fidelity

    @property
    def plant(self) -> ProcessPlant:
        return self.chosen.plant

    @property
    def error(self) -> float:
        return self.chosen.error

    @property
    def wall_ratio(self) -> float:
        """Chosen wall time / full model's (below 1: faster)."""
        return self.chosen.wall_s / self.reference.wall_s

    @property
    def state_ratio(self) -> float:
        return self.chosen.states / self.reference.states

    def table(self) -> str:
        head = f"{'candidate':<52} {'error':>9} {'wall ms':>8} {'states':>6} {'instr':>6}  result"
        lines = [head, "-" * len(head)]
        for c in self.candidates:
            mark = "chosen" if c is self.chosen else ("pass" if c.passed else "fail")
            lines.append(f"{c.label[:52]:<52} {c.error:9.2e} {1e3 * c.wall_s:8.2f} "
                         f"{c.states:6d} {c.instructions:6d}  {mark}")
        return "\n".join(lines)

    def __str__(self) -> str:
        lines = [(f"fidelity for {self.scene}: {self.chosen.label} "
                  f"(error {self.error:.2e} <= tol {self.tol:g}; wall x{self.wall_ratio:.2f}, "
                  f"states {self.chosen.states}/{self.reference.states} of the full model)"),
                 f"error = {self.error_definition}",
                 (f"dt = {self.dt:.4g} s (full model's own step error {self.step_error:.1e}), "
                  f"duration {self.duration:.4g} s, errors from t = {self.t_start:.4g} s; "
                  f"signals: {', '.join(self.signals)}")]
        if self.couplings:
            c = self.couplings
            lines.append(f"coupling between bodies: impedance {c['impedance']:.2e} "
                         f"({' / '.join(c['impedance_pair'] or [])}), kernel {c['kernel']:.2e}")
        if self.freeze:
            frozen = [d for d, row in self.freeze.items() if row["frozen"]]
            lines.append(f"frozen by the waves' excitation: {', '.join(frozen) or 'none'}")
        return "\n".join(lines + ["", self.table()])

    def to_dataset(self) -> xr.Dataset:
        """The candidate table as an xarray Dataset (netCDF-safe), settings in attrs."""
        c = self.candidates
        ds = xr.Dataset(
            {"error": ("candidate", [x.error for x in c], {"units": "1",
                                                           "definition": self.error_definition}),
             "wall_time": ("candidate", [x.wall_s for x in c], {"units": "s"}),
             "states": ("candidate", [x.states for x in c]),
             "instructions": ("candidate", [x.instructions for x in c]),
             "passed": ("candidate", np.array([x.passed for x in c], dtype=np.int8)),
             "worst_signal": ("candidate", [x.worst_signal for x in c]),
             "role": ("candidate", [x.role for x in c]),
             "fidelity": ("candidate", [json.dumps(x.fidelity.as_dict()) for x in c])},
            coords={"candidate": [x.label for x in c]})
        ds.attrs.update({"scene": self.scene, "tol": self.tol, "chosen": self.chosen.label,
                         "chosen_fidelity": json.dumps(self.fidelity.as_dict()),
                         "dt_s": self.dt, "duration_s": self.duration, "t_start_s": self.t_start,
                         "step_error": self.step_error, "signals": json.dumps(self.signals),
                         "waves": json.dumps(self.waves, default=str),
                         "couplings": json.dumps(self.couplings),
                         "freeze": json.dumps(self.freeze)})
        return ds


def auto(scene: Scene | str, waves, tol: float | None = None, *, duration: float | None = None,
         dt: float | None = None, signals=None, method: str = "rk4", params=None,
         radiation_tols=RADIATION_LADDER, options=("radiation_tol", "couplings", "freeze",
                                                   "kinematics", "pressure"),
         repeats: int = 3, progress: bool = False) -> FidelityReport:
    """The cheapest model of `scene` whose error in `waves` is at most `tol` (see module doc).

    tol : the error allowed (default "fidelity.tol", 0.01, in mbcontrol.defaults).
    waves : a Wave or a list (errors and walls: worst and sum over them). duration (s) : default
        the longest ramp plus 40 peak periods. dt (s) : default T_p/200 (shortest T_p), halved (up
        to 3 times) until the full model's own step error, measured against dt/2, is below
        tol/10, so the errors are the models' and not the integrator's. radiation_tols : looser
        fit tolerances tried (those above the scene's; one giving an order already tried is
        skipped). options : which simplifications to try ("pressure": linear hydrostatics and
        Froude-Krylov forces, when the scene's are nonlinear). params : as simulate's.
    Each option is tried alone, then the passing ones together (the loosest passing radiation
    tolerance); if that combination fails, passing options are added one at a time, cheapest
    first, keeping each that keeps the error within tol. Among the candidates within tol (the
    full model always is) and not measured clearly slower than the fastest of them (WALL_VETO
    times and WALL_NOISE_S more), the fewest compiled instructions win; counts within
    INSTRUCTION_TIES are ties, broken by fewer states, then the lower error.
    """
    scene = load_scene(scene) if not isinstance(scene, Scene) else scene
    tol = defaults.resolve("fidelity.tol", tol)
    wave_list = as_wave_list(waves)
    if not wave_list:
        raise FidelityError("auto: waves: expected a Wave or a non-empty list of Waves")
    if not tol > 0:
        raise FidelityError(f"auto: tol: expected a positive error tolerance, got {tol!r}")
    unknown = set(options) - {"radiation_tol", "couplings", "freeze", "kinematics", "pressure"}
    if unknown:
        raise FidelityError(f"auto: options: unknown {sorted(unknown)}; expected some of "
                            f"radiation_tol, couplings, freeze, kinematics, pressure")
    periods = [_peak_period(w) for w in wave_list]
    t_start = max(w.ramp_time for w in wave_list)
    duration = t_start + 40 * max(periods) if duration is None else float(duration)
    if duration <= t_start:
        raise FidelityError(f"auto: duration: expected more than the ramp ({t_start:g} s), "
                            f"got {duration:g} s")
    run = _Runner(wave_list, duration, method, params, repeats, t_start)
    full = plant_for(scene)
    dt, step_error, reference = _converged_step(run, full, dt, min(periods), tol)
    run.set_reference(full, dt, reference, signals)
    ref = run.measure("full", Fidelity(), full, role="reference", tol=tol)

    singles = _single_candidates(scene, full, options, radiation_tols)
    bar = _bar(progress, len(singles) + 1)
    tried, evidence = [ref], {}
    for label, fidelity, plant in singles:
        plant = plant or plant_for(scene, fidelity, waves=wave_list, hydro=full.hydro,
                                   reference=full)
        evidence.update({k: v for k, v in plant.notes["fidelity"].items() if k != "options"})
        resolved = Fidelity(**plant.notes["fidelity"]["options"])     # freeze made explicit
        if fidelity.freeze == "auto" and not resolved.freeze:
            _tick(bar)
            continue                    # the waves move every free DOF: nothing to freeze
        tried.append(run.measure(label, resolved, plant, role="single", tol=tol))
        _tick(bar)
    tried += _combinations(scene, full, wave_list, run, tried[1:], tol)
    _tick(bar)
    if bar is not None:
        bar.close()
    chosen = _cheapest([c for c in tried if c.passed])
    return FidelityReport(scene.name, tol, chosen, ref, tried, run.signals, dt, duration,
                          t_start, step_error, [w.describe() for w in wave_list],
                          evidence.get("couplings"), evidence.get("freeze"))


def _peak_period(wave) -> float:
    period = wave.period
    return float(period) if period else float(2 * np.pi / wave.omega[np.argmax(wave.amplitude)])


def _bar(progress, total):
    if not progress:
        return None
    return progress_bar(total=total, desc="fidelity candidates", leave=False)


def _tick(bar):
    if bar is not None:
        bar.update(1)


class _Runner:
    """Simulates plants in the waves and measures their error against the reference runs."""

    def __init__(self, waves, duration, method, params, repeats, t_start):
        self.waves, self.duration, self.method = waves, duration, method
        self.params, self.repeats, self.t_start = params, max(1, int(repeats)), t_start
        self.dt, self.reference, self.signals = None, None, ()

    def simulate(self, plant, dt, repeats=1):
        """Per wave: the dataset of the first run and the best wall time of `repeats` runs."""
        out = []
        for wave in self.waves:
            runs = [simulate(plant, wave, duration=self.duration, dt=dt, method=self.method,
                             params=self.params) for _ in range(repeats)]
            out.append((runs[0], min(r.attrs["wall_time_s"] for r in runs)))
        return out

    def set_reference(self, plant, dt, reference, signals=None):
        """reference: the full model's datasets at dt, one per wave."""
        self.dt, self.reference = dt, reference
        self.signals = tuple(signals) if signals is not None else compared_signals(
            plant, reference, self.t_start)

    def error(self, datasets, reference=None, signals=None) -> tuple[float, str]:
        """(largest relative RMS error, its signal) of datasets against the reference runs."""
        reference = self.reference if reference is None else reference
        worst, name = 0.0, ""
        for ds, ref in zip(datasets, reference):
            if ref.sizes["time"] != ds.sizes["time"]:    # the step check: ref at dt/2
                ref = ref.sel(time=ds["time"].values, method="nearest")
            window = ds["time"].values >= self.t_start
            for signal in self.signals if signals is None else signals:
                if signal not in ds:
                    raise FidelityError(f"auto: signals: {signal!r} is not an output of every "
                                        f"candidate model")
                e = relative_rms_error(ds[signal].values, ref[signal].values, window)
                if e > worst or not name:
                    worst, name = e, signal
        return worst, name

    def measure(self, label, fidelity, plant, *, role, tol) -> Candidate:
        results = self.simulate(plant, self.dt, self.repeats)
        error, worst = self.error([ds for ds, _ in results])
        return Candidate(label, fidelity, error, worst, float(sum(w for _, w in results)),
                         plant.nx, int(plant.f.n_instructions()), error <= tol, role, plant)


def relative_rms_error(y, y_ref, window) -> float:
    """RMS(y - y_ref) / RMS(y_ref) over the samples where `window` is True."""
    diff, ref = np.asarray(y)[window] - np.asarray(y_ref)[window], np.asarray(y_ref)[window]
    scale = np.sqrt(np.mean(ref ** 2))
    return float(np.sqrt(np.mean(diff ** 2)) / scale) if scale > 0 else 0.0


def compared_signals(plant, datasets, t_start) -> tuple[str, ...]:
    """Body DOFs and PTO velocity/power whose reference RMS (after t_start) is at least
    SIGNAL_FLOOR of the largest of their unit class, in any of the datasets."""
    names = [f"{b}__{d}" for b in plant.topology.bodies for d in
             ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")]
    names += [f"{p.name}__{k}" for p in plant.scene.ptos for k in ("velocity", "power")]
    keep = set()
    for ds in datasets:
        window = ds["time"].values >= t_start
        rms = {n: float(np.sqrt(np.mean(ds[n].values[window] ** 2))) for n in names}
        largest: dict = {}
        for n, value in rms.items():
            largest[plant.units(n)] = max(largest.get(plant.units(n), 0.0), value)
        keep |= {n for n, value in rms.items() if value > 0
                 and value >= defaults.get("fidelity.signal_floor") * largest[plant.units(n)]}
    return tuple(n for n in names if n in keep)


def _converged_step(run, full, dt, period, tol):
    """(dt, the full model's error at dt against dt/2, its datasets at dt).

    A default dt = T_p/200 is halved (up to 3 times) until that step error is below tol/10; a
    given dt is kept and its step error only reported.
    """
    fixed = dt is not None
    dt = period / defaults.get("fidelity.steps_per_period") if dt is None else float(dt)
    coarse = [ds for ds, _ in run.simulate(full, dt)]
    for halving in range(4):
        fine = [ds for ds, _ in run.simulate(full, dt / 2)]
        signals = compared_signals(full, fine, run.t_start)
        error = run.error(coarse, fine, signals)[0]
        if fixed or error <= 0.1 * tol or halving == 3:
            return dt, error, coarse
        dt, coarse = dt / 2, fine


def _single_candidates(scene, full, options, radiation_tols):
    """(label, Fidelity, plant or None) of each option alone; radiation tolerances giving an
    order already tried are skipped (their plants are built here to know the order)."""
    out = []
    if "radiation_tol" in options and full.hydro is not None:
        orders = {full.hydro.radiation.A.shape[0]}
        for tol in sorted(t for t in radiation_tols if t > scene.hydro.radiation_tol):
            fidelity = Fidelity(radiation_tol=tol)
            plant = plant_for(scene, fidelity, hydro=full.hydro)
            order = plant.hydro.radiation.A.shape[0]
            if order not in orders:
                orders.add(order)
                out.append((f"radiation_tol={tol:g}", fidelity, plant))
    if "couplings" in options and has_couplings(full):
        out.append(("couplings=drop", Fidelity(couplings="drop"), None))
    if "freeze" in options and any(j.type == "free" for j in scene.joints):
        out.append(("freeze=auto", Fidelity(freeze="auto"), None))
    if "kinematics" in options:
        out.append(("kinematics=linear", Fidelity(kinematics="linear"), None))
    if "pressure" in options and scene.hydro.hydrostatics != "linear" and full.hydro is not None:
        out.append(("pressure=linear", Fidelity(pressure="linear"), None))
    return out


def _combinations(scene, full, waves, run, singles, tol) -> list[Candidate]:
    """All passing options together (loosest passing radiation_tol); if that fails, passing
    options added one at a time, cheapest alone first, each kept only if still within tol."""
    passing = sorted((c for c in singles if c.passed), key=_cost_key)
    best: dict = {}
    for c in passing:                               # cheapest alone first
        for key, value in _changes(c.fidelity).items():
            best.setdefault(key, value)
    tols = [c.fidelity.radiation_tol for c in passing if c.fidelity.radiation_tol is not None]
    if tols:
        best["radiation_tol"] = max(tols)           # the loosest fit that passed alone
    if len(best) < 2:
        return []
    tried = []

    def attempt(settings, role_label):
        fidelity = Fidelity(**settings)
        plant = plant_for(scene, fidelity, waves=waves, hydro=full.hydro, reference=full)
        cand = run.measure(role_label + fidelity.label(scene.hydro.radiation_tol), fidelity,
                           plant, role="combined", tol=tol)
        tried.append(cand)
        return cand

    if attempt(best, "all passing: ").passed:
        return tried
    kept: dict = {}
    for key, value in best.items():
        trial = {**kept, key: value}
        if len(trial) == 1:
            kept = trial                          # it passed alone
        elif trial != best and attempt(trial, "greedy: ").passed:
            kept = trial
    return tried


def _changes(fidelity: Fidelity) -> dict:
    default = Fidelity()
    return {k: v for k, v in fidelity.__dict__.items() if v != getattr(default, k)}


def _cost_key(c: Candidate):
    return (c.instructions, c.states, c.wall_s)


def _cheapest(passing: list[Candidate]) -> Candidate:
    fastest = min(c.wall_s for c in passing)
    usable = [c for c in passing
              if c.wall_s <= max(WALL_VETO * fastest, fastest + WALL_NOISE_S)]
    fewest = min(c.instructions for c in usable)
    ties = [c for c in usable if c.instructions <= (1 + INSTRUCTION_TIES) * fewest]
    return min(ties, key=lambda c: (c.states, c.error))
