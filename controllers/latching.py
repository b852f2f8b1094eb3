"""Latching and declutching: PTO laws that switch at each zero crossing of the PTO velocity.

Latching holds the PTO still for `latch_time` s from each velocity zero crossing (the body at
the end of its stroke), then lets it go as a damper `damping`: a body whose natural period is
shorter than the wave's is held back so that its velocity comes into phase with the
excitation. Declutching does the opposite: the PTO force is off (u = 0) for `declutch_time`
s from each crossing, then it is a damper `damping`.

How the switching is simulated (documented fixed small step, no event location): a switching
law keeps a timer, so it cannot be the static CasADi law `simulate` compiles; it runs in the
Python zero-order-hold loop and is called every simulation step (period None). A crossing is
seen at the first sample after it (at most one step late); its time is interpolated linearly
between the two samples and the release is put at the sample nearest crossing + latch_time.
Switching times are therefore exact to one step, and results converge as dt shrinks (the
tests measure it: mean power changes by < 1 % from dt = 0.02 s to 0.005 s on the sphere).

The latch is a brake force, not a constraint (the plant's structure is fixed): a deadbeat
velocity controller. Over one step of length h with the force u held, the PTO velocity
changes by h (u + F_rest) / M, with M the inertia the PTO force meets instantaneously (mass
plus infinite-frequency added mass, from the linearised plant: 1 / (dv/dt per unit u)) and
F_rest every other force (excitation, restoring, radiation). F_rest is estimated from the last
step, M (v_k - v_{k-1}) / h - u_{k-1}, and the brake applies u_k = -M v_k / h - F_rest: the
velocity is cancelled in one step and stays at O(h^2 dF/dt / M) while latched (a plain large
damper would leave a creep of O(h F_rest / M)). It is stable for an inertia error up to about
40 % (the loop's poles, z^2 + 2(r - 1) z + (1 - r) = 0, r = M_assumed / M_true, lie inside the
unit circle for 0 < r < 1.4). The brake dissipates -u v, which is counted in the PTO's power as
a real brake's would be; it vanishes with h (the tests measure its share).

Force limit: every command, brake and damper alike, is saturated to +-force_max (N or N m;
None: the scene PTO's force_max, inf: none; controllers.limits.force_limits). A saturated
brake cannot hold the body: it slips while "latched" and the brake keeps estimating the rest
of the force from the velocity change under the force it really applied.
"""
from __future__ import annotations

import numpy as np
from mbcontrol.errors import ControllerError

from .base import per_pto, signal_indices
from .impedance import intrinsic_impedance
from .law import Law
from .limits import force_limits, limits_report, saturate
from .tuning import electrical_winding


class _Switching(Law):
    """Common machinery: per-PTO crossing detection, a timer, and a damper when engaged."""
    name = "switching"
    kind, exportable = "switching", True        # the law protocol (controllers.law)
    run_state = ("per PTO: held or not, the release time (s), the last velocity sign, the last "
                 "sample (t, v, u) and the log of holds (`holds`: (on, off) times, s)")
    units = {"damping": "N s/m (or N m s/rad)", "latch_time": "s", "declutch_time": "s",
             "period": "s", "force_max": "N (or N m)"}

    @classmethod
    def tune(cls, plant, wave, pto=None, **options):
        """The hold time and damping for a regular `wave`, found by simulating the plant
        (its tuner below; options: Law.tune's, the PTO's limits taken where it takes them)."""
        from .law import pto_of
        from .law_tuning import tune_switching
        return tune_switching(cls, cls._tuner(), plant, wave, pto_of(plant, pto), **options)

    @staticmethod
    def _tuner():
        """The law's tuner (below): wave -> (hold time s, damping N s/m, simulated W)."""
        raise NotImplementedError

    _moves_while_held = False     # the hold stops the PTO (latching) or frees it (declutching)

    def __init__(self, damping: float = 0.0, hold_time: float = 0.0,
                 period: float | None = None, force_max=None):
        self.damping = damping
        self._hold_time = hold_time
        self.period = period          # s; None: every simulation step (switch at each step)
        self.force_max = force_max
        self._limits = None

    def reset(self, plant) -> None:
        names = [p.name for p in plant.scene.ptos]
        self._c = per_pto(plant, self.damping, f"{self.name} damping")
        if np.any(self._c < 0) or self._hold_time < 0:
            raise ControllerError(f"{self.name}: damping and hold time must be >= 0, got "
                                  f"{self._c}, {self._hold_time}")
        self._names = names
        self._limits = force_limits(plant, self.force_max)
        self._velocity = signal_indices(plant, [f"{n}__velocity" for n in names])
        n = len(names)
        self._held = np.zeros(n, bool)            # in the hold (latched / declutched) phase
        self._release = np.full(n, -np.inf)       # s, end of the current hold
        self._sign = np.zeros(n)                  # sign of v at the last sample (0: unknown)
        self._t_prev, self._v_prev, self._u_prev = None, np.zeros(n), np.zeros(n)
        self.holds: list[list[tuple[float, float]]] = [[] for _ in names]  # (on, off) samples

    @property
    def damping_per_pto(self) -> np.ndarray:
        """The engaged damper per PTO, N s/m (or N m s/rad), scene order, after reset()."""
        return self._c.copy()

    @property
    def saturation(self) -> np.ndarray:
        """The command's limit per PTO, N or N m (inf: none), after reset()."""
        return self._limits.copy()

    def casadi_law(self, plant):
        return None                   # a timer is state: runs in simulate's Python loop

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        v = np.asarray(y, float)[self._velocity]
        h = None if self._t_prev is None else t - self._t_prev
        if h is not None and h <= 0:  # simulate asks again for the last sample: same answer
            return self._u_prev.copy()
        u = -self._c * v
        for i in range(v.size):
            if self._held[i] and t >= self._release[i] - 0.5 * (h or 0.0):
                self._held[i] = False                 # release at the nearest sample
                self.holds[i][-1] = (self.holds[i][-1][0], t)
                # latched, v is the brake's residual: take its sign afresh; declutched, v is
                # real, and a crossing in the step after the release must count
                self._sign[i] = np.sign(v[i]) if self._moves_while_held else 0.0
            elif not self._held[i]:
                s = np.sign(v[i])
                if self._sign[i] != 0 and s != self._sign[i] and h is not None:
                    # crossing between the samples: interpolate its time linearly
                    dv = v[i] - self._v_prev[i]
                    t_cross = t - h * v[i] / dv if dv != 0 else t
                    self._release[i] = t_cross + self._hold_time
                    if t < self._release[i] - 0.5 * h:
                        self._held[i] = True
                        self.holds[i].append((t, np.inf))
                self._sign[i] = s if s != 0 else self._sign[i]
            if self._held[i]:
                u[i] = self._hold_force(i, v[i], h)
        u = saturate(u, self._limits)     # the force applied: the brake's estimate uses it
        self._t_prev, self._v_prev, self._u_prev = t, v, u
        return u.copy()

    def _hold_force(self, i: int, v: float, h: float) -> float:
        raise NotImplementedError

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "period_s": self.period,
                "saturation": "command (brake and damper) clipped to +-force_max per PTO "
                              "(null: none)",
                "force_max": limits_report(self._limits)}


class Latching(_Switching):
    """Latching: hold the PTO still for `latch_time` s from each velocity zero crossing, then
    a damper u = -damping * v until the next crossing.

    damping: N s/m (or N m s/rad), one number or a dict by PTO name; latch_time: s. The hold
    is a deadbeat brake (see the module docstring), limited like the damper to +-force_max
    (N or N m; None: the scene PTO's force_max).
    """
    name = "latching"
    tuned = ("damping", "latch_time")
    _tuner = staticmethod(lambda: optimal_latch_time)     # defined below

    def __init__(self, damping: float = 0.0, latch_time: float = 0.0,
                 period: float | None = None, force_max=None):
        super().__init__(damping, latch_time, period, force_max)
        self.latch_time = latch_time

    def reset(self, plant) -> None:
        super().reset(plant)
        self._inertia = _port_inertia(plant, self._names)

    @property
    def brake_inertia(self) -> np.ndarray:
        """The inertia the deadbeat brake assumes per PTO, kg or kg m^2, after reset()."""
        return self._inertia.copy()

    def _hold_force(self, i: int, v: float, h: float) -> float:
        M = self._inertia[i]
        # the rest of the force on the PTO over the last step, from its velocity change
        f_rest = M * (v - self._v_prev[i]) / h - self._u_prev[i]
        return -M * v / h - f_rest

    def describe(self) -> dict:
        return {**super().describe(), "latch_time": self.latch_time}


class Declutching(_Switching):
    """Declutching: PTO force off (u = 0) for `declutch_time` s from each velocity zero
    crossing, then a damper u = -damping * v until the next crossing.

    damping: N s/m (or N m s/rad), one number or a dict by PTO name; declutch_time: s;
    force_max: N (or N m), the damper's saturation (None: the scene PTO's force_max).
    """
    name = "declutching"
    tuned = ("damping", "declutch_time")
    _tuner = staticmethod(lambda: optimal_declutch)       # defined below
    _moves_while_held = True

    def __init__(self, damping: float = 0.0, declutch_time: float = 0.0,
                 period: float | None = None, force_max=None):
        super().__init__(damping, declutch_time, period, force_max)
        self.declutch_time = declutch_time

    def _hold_force(self, i: int, v: float, h: float) -> float:
        return 0.0

    def describe(self) -> dict:
        return {**super().describe(), "declutch_time": self.declutch_time}


def _port_inertia(plant, names) -> np.ndarray:
    """Inertia each PTO force meets at once (kg or kg m^2): 1 / (dv/dt per unit u), from the
    plant's exact Jacobians at rest (mass plus infinite-frequency added mass for a heaving
    body). Couplings between PTOs are left to the brake's estimate of the other forces."""
    from mbcontrol.analysis import linearize
    sys = linearize(plant, inputs=[f"u__{n}" for n in names],
                    outputs=[f"{n}__velocity" for n in names])
    gain = np.diag(np.asarray(sys.C) @ np.asarray(sys.B))
    if np.any(gain <= 0):
        raise ControllerError(f"{plant.name}: PTO force does not accelerate its own coordinate "
                              f"(dv/dt per unit u = {gain}); cannot build a latching brake")
    return 1.0 / gain


# ------------------------------------------------------------------------------------------
# tuning by simulation

def mean_power(ds, pto: str, start: float = 0.0, end: float | None = None,
               key: str = "mean_power_W") -> float:
    """Mean absorbed power (W) over [start, end) s, from the work the PTO does
    (mbcontrol.analysis.metrics.step_power); key "mean_electrical_power_W" for the electrical
    one. For an irregular sea use start = the ramp time."""
    from mbcontrol.analysis import pto_metrics
    return pto_metrics(ds, pto, start, end)[key]


def steady_mean_power(ds, pto: str, period: float, skip_periods: int = 5,
                      key: str = "mean_power_W") -> float:
    """Mean absorbed power (W) of a regular-wave run over whole periods after skip_periods:
    mean_power over [skip T, skip T + n T), n the most whole periods the record holds."""
    t = ds["time"].values
    start = skip_periods * period
    n = int(np.floor((t[-1] - start) / period + 1e-9))
    if n < 1:
        raise ControllerError(f"record of {t[-1]:.4g} s too short to skip {skip_periods} periods of "
                              f"{period:.4g} s and average over one")
    return mean_power(ds, pto, start, start + n * period, key)


def natural_period(plant, *, pto: str | None = None, params=None) -> float:
    """Undamped natural period (s) of the PTO's coordinate with no PTO force: where the
    intrinsic reactance Im Z_i(omega) = omega (m + A(omega)) - K / omega changes sign."""
    hyd = plant.hydro
    omega = np.linspace(max(hyd.omega[0], 0.05), hyd.omega[-1], 800)
    X = intrinsic_impedance(plant, omega, pto=pto, params=params)[0].imag
    j = np.flatnonzero((X[:-1] < 0) & (X[1:] >= 0))
    if j.size == 0:
        raise ControllerError(f"{plant.name}: no resonance inside the hydro data's band")
    j = int(j[0])
    w_n = omega[j] - X[j] * (omega[j + 1] - omega[j]) / (X[j + 1] - X[j])
    return float(2 * np.pi / w_n)


LATCH_SCAN_STEP = 0.01          # of the wave period: the scan step before refining (the
                                # sphere's latching peak is about T / 40 wide at half height)


def _simulated_power(plant, wave, controller, pto, dt, periods, skip,
                     objective: str = "auto") -> float:
    """The tuners' objective, simulated: mean electrical power for a PTO with a drivetrain
    (objective "auto" or "electrical", tuning.electrical_winding), else mechanical."""
    from mbcontrol.sim import simulate
    T = wave.period
    ds = simulate(plant, wave, duration=(skip + periods) * T, dt=dt, controller=controller)
    electrical = electrical_winding(plant, pto, objective) is not None
    return steady_mean_power(ds, pto, T, skip,
                             "mean_electrical_power_W" if electrical else "mean_power_W")


def _search(objective, lo, hi, xatol):
    """Bounded 1-D maximisation (Brent): (x, objective(x))."""
    from scipy.optimize import minimize_scalar
    res = minimize_scalar(lambda x: -objective(x), bounds=(lo, hi), method="bounded",
                          options={"xatol": xatol})
    return float(res.x), -float(res.fun)


def _bracket_search(objective, lo, hi, step, xatol):
    """Maximise a sharply peaked 1-D objective: scan [lo, hi] every `step` (finer than the
    peak, so it is bracketed, not stepped over), then refine between the best point's
    neighbours by Brent. A coarse grid or Brent alone can settle on a flank: on the sphere
    (H 2.5 m, T 9.67 s, damping 4.9e4) the simulated power against latch time goes
    278 -> 690 -> 878 -> 537 kW at 2.4, 2.5, 2.6, 2.7 s.
    Returns (x, objective(x)) of the best point seen."""
    xs = np.linspace(lo, hi, max(3, int(np.ceil((hi - lo) / step)) + 1))
    values = [objective(x) for x in xs]
    k = int(np.argmax(values))
    x, value = _search(objective, xs[max(k - 1, 0)], xs[min(k + 1, xs.size - 1)], xatol)
    return (x, value) if value >= values[k] else (float(xs[k]), float(values[k]))


def _regular(wave, what):
    if wave.omega.size != 1:
        raise ControllerError(f"{what} tunes for a regular wave; for a sea state tune on the "
                              f"regular wave at its peak period (or simulate a grid)")
    return wave.period


def optimal_latch_time(plant, wave, *, damping: float | None = None, pto: str | None = None,
                       dt: float | None = None, skip: int = 8, periods: int = 3,
                       tune_damping: bool = False, force_max=None,
                       objective: str = "auto") -> tuple[float, float, float]:
    """(latch_time s, damping N s/m, simulated mean power W) for a regular wave of period T.

    Starts from the classical rule latch_time = (T - T_n) / 2 (released at the end of its
    stroke, the body travels for about half its natural period T_n, so a half cycle lasts
    T / 2 and the velocity comes into phase with the excitation), then maximises the mean
    power simulated on the nonlinear plant in closed loop (`periods` whole periods after
    `skip`; latching settles slowly) within T / 10 of it: a scan every T / 100 brackets the
    sharp peak, Brent refines it to one step.
    damping (while free): default Re Z_i(omega_n), the radiation damping at the natural
    frequency, where the free body oscillates and its impedance is purely resistive. With
    tune_damping, 1-D searches in log damping (x 1/4..4) and in latch time in turn, twice.
    dt: simulation step, default T / 500. force_max: the simulated controllers' force limit
    (N or N m; None: the scene PTO's, as Latching's default), so the tuning sees the brake
    the device has. objective: "auto" maximises the simulated electrical power of a PTO with
    a drivetrain (else the mechanical), "electrical" or "mechanical".
    """
    name = pto or plant.scene.ptos[0].name
    T = _regular(wave, "optimal_latch_time")
    dt = T / 500 if dt is None else dt
    T_n = natural_period(plant, pto=name)
    if T_n >= T:
        raise ControllerError(f"{plant.name}: latching helps for waves longer than the natural "
                              f"period; T = {T:.4g} s <= T_n = {T_n:.4g} s (try declutching)")
    if damping is None:
        damping = float(intrinsic_impedance(plant, [2 * np.pi / T_n], pto=name)[0][0].real)

    def power(latch: float, c: float) -> float:
        return _simulated_power(plant, wave, Latching(c, latch, force_max=force_max), name, dt,
                                periods, skip, objective)

    guess = 0.5 * (T - T_n)
    latch, best = _bracket_search(lambda x: power(x, damping), max(0.0, guess - 0.1 * T),
                                  min(0.5 * T, guess + 0.1 * T), LATCH_SCAN_STEP * T, dt)
    if tune_damping:
        # the best latch time moves with the damping: tune them in turn, latch time last
        for _ in range(2):
            z, best = _search(lambda z: power(latch, damping * np.exp(z)), -np.log(4),
                              np.log(4), xatol=0.02)
            damping *= float(np.exp(z))
            latch, best = _bracket_search(lambda x: power(x, damping),
                                          max(0.0, latch - 0.05 * T),
                                          min(0.5 * T, latch + 0.05 * T),
                                          LATCH_SCAN_STEP * T, dt)
    return latch, float(damping), best


def optimal_declutch(plant, wave, *, damping: float | None = None, pto: str | None = None,
                     dt: float | None = None, skip: int = 8, periods: int = 3,
                     tune_damping: bool = False, force_max=None,
                     objective: str = "auto") -> tuple[float, float, float]:
    """(declutch_time s, damping N s/m, simulated mean power W) for a regular wave of period T.

    A bounded 1-D search over declutch_time tau in [0, 0.45 T] on the simulated mean power (as
    optimal_latch_time). Unless `damping` is given, the damping follows tau: the passive
    optimum |Z_i(omega)| times T / (T - 2 tau), since the damper now acts over only that share
    of each cycle (it keeps the cycle's mean damping). With tune_damping, a second 1-D search
    in log damping (x 1/4..4) at the best tau. dt: simulation step, default T / 500.
    force_max: the simulated controllers' force limit (None: the scene PTO's).
    """
    name = pto or plant.scene.ptos[0].name
    T = _regular(wave, "optimal_declutch")
    dt = T / 500 if dt is None else dt
    passive = float(np.abs(intrinsic_impedance(plant, wave.omega, pto=name)[0][0]))

    def damping_at(tau: float) -> float:
        return damping if damping is not None else passive * T / (T - 2 * tau)

    def power(tau: float, c: float) -> float:
        return _simulated_power(plant, wave, Declutching(c, tau, force_max=force_max), name,
                                dt, periods, skip, objective)

    tau, best = _bracket_search(lambda x: power(x, damping_at(x)), 0.0, 0.45 * T,
                                LATCH_SCAN_STEP * T, dt)
    c = damping_at(tau)
    if tune_damping:
        z, best = _search(lambda z: power(tau, c * np.exp(z)), -np.log(4), np.log(4),
                          xatol=0.02)
        c *= float(np.exp(z))
    return tau, float(c), best
