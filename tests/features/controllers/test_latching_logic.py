"""Latching and declutching run in closed loop, not read (issue 19 item 5).

The 10 m heaving hemisphere (`sphere`) in regular waves, no force limit. References that do
not come from the code under test:
- switching: an event schedule written here from the RECORDED velocity alone (crossings
  interpolated linearly, release at the sample nearest crossing + hold time), compared sample
  by sample with which law the recorded force obeys (damper -c v, brake, or zero);
- the brake: the deadbeat bound |v| ~ h^2 |dF/dt| / (m + A_inf) from the hydro arrays;
- chatter: synthetic velocity sequences fed straight to the controllers;
- tuners: the classical latching rule (T - T_n) / 2 (Falnes, Babarit) with T_n solved here
  from the BEM arrays, and brute-force scans of the hold time by simulation, their power
  measured here from the PTO's work (-sum F dx over whole periods).
Measured values in the comments are from one run on this machine.
"""
import numpy as np
import pytest

from mbcontrol import waves
from mbcontrol.controllers.latching import (Declutching, Latching, natural_period,
                                            optimal_declutch, optimal_latch_time)
from mbcontrol.plant import build_plant
from mbcontrol.sim import simulate
from tests.helpers.sphere_reference import heave_impedance

T_LONG = 9.6664        # s, H 2.5 m: longer than the sphere's T_n (4.36 s), latching's case
T_SHORT = 3.0          # s, H 1 m: shorter than T_n, declutching's case
NO_LIMIT = np.inf      # the brake must hold: no saturation (tested in test_limits.py)


@pytest.fixture(scope="module")
def plant():
    return build_plant("sphere")


# --- references written here ---------------------------------------------------------------

def crossings(t, v):
    """(k, t_c): samples k with v[k-1], v[k] of opposite signs, and the crossing time by
    linear interpolation between them."""
    k = np.flatnonzero(v[1:] * v[:-1] < 0) + 1
    return k, t[k] - (t[k] - t[k - 1]) * v[k] / (v[k] - v[k - 1])


def schedule(t, v, hold, rearm):
    """Held samples (bool) and the holds [(k_on, k_off, t_c)] the spec asks for, from the
    recorded velocity: a crossing seen at sample k while free starts a hold there, released at
    the first sample at or past t_c + hold - h/2 (the nearest sample). After a release at
    k_off, crossings seen before sample k_off + rearm are not crossings: latching takes the
    sign afresh (rearm 2: the velocity at release is the brake's residual); declutching keeps
    it (rearm 1: the velocity is real)."""
    h = t[1] - t[0]
    held, holds, armed = np.zeros(t.size, bool), [], 2    # v[0] = 0: sign known from 1
    for k, tc in zip(*crossings(t, v)):
        if k < armed:
            continue
        off = int(np.searchsorted(t, tc + hold - 0.5 * h - 1e-9))
        if off <= k:
            continue
        held[k:off] = True
        holds.append((k, off, tc))
        armed = off + rearm
    return held, holds


def work_power(ds, T, skip, periods):
    """Mean absorbed power (W) over whole periods after `skip`: -sum F dx / time (the force
    is held over each step, so this is the work the PTO does)."""
    F, x = ds["pto__force"].values, ds["pto__position"].values
    dt = float(ds["time"][1] - ds["time"][0])
    i, j = int(round(skip * T / dt)), int(round((skip + periods) * T / dt))
    return -np.sum(F[i:j] * np.diff(x[i:j + 1])) / (j * dt - i * dt)


def natural_period_reference(plant):
    """T_n from the BEM arrays: the root of omega^2 (m + A(omega)) = K, i.e. Im Z_i = 0."""
    w = np.linspace(0.5, 3.0, 20001)
    X = heave_impedance(plant, w)[0].imag
    j = np.flatnonzero((X[:-1] < 0) & (X[1:] >= 0))[0]
    return 2 * np.pi / (w[j] - X[j] * (w[j + 1] - w[j]) / (X[j + 1] - X[j]))


# --- 1. release logic and timing in a simulated run -----------------------------------------

def test_latching_holds_for_latch_time_then_damps(plant):
    wave, c, latch = waves.regular(2.5, T_LONG), 8.9e4, 2.58
    dt = T_LONG / 500
    ctrl = Latching(c, latch, force_max=NO_LIMIT)
    ds = simulate(plant, wave, duration=14 * T_LONG, dt=dt, controller=ctrl)
    t, v, F = (ds[k].values for k in ("time", "pto__velocity", "pto__force"))
    damper = np.abs(F + c * v) <= 1e-9 * np.abs(F).max()
    held, holds = schedule(t, v, latch, rearm=2)
    # the force obeys the damper exactly where the schedule says free, and nowhere else
    assert np.array_equal(~damper[:-1], held[:-1])
    assert len(holds) >= 2 * 14 - 1                      # measured 28: one per half period
    ends = [t[off] if off < t.size - 1 else np.inf for _, off, _ in holds]
    assert np.allclose([(t[on], e) for (on, _, _), e in zip(holds, ends)], ctrl.holds[0],
                       rtol=0, atol=1e-9)                 # and its own record agrees
    # the deadbeat brake leaves |v| ~ h^2 |dF_rest/dt| / (m + A_inf); the rest force's rate
    # is the excitation's (recorded w) plus the radiation memory's: measured up to 1.35 x the
    # excitation's alone, the same at dt = T/250 and T/500 (so O(h^2)); 9.6e-5 of peak |v|
    M = plant.scene.bodies[0].mass + plant.hydro.added_mass_inf[0, 0]
    w = ds["w__sphere__Heave"].values
    still = 2 * dt ** 2 * np.abs(np.diff(w)).max() / dt / M
    for on, off, tc in holds[:-1]:
        # from the velocity alone: still from the step after the crossing's sample (the
        # brake cancels v[on] over that step) to the last still sample, which must be the
        # sample nearest crossing + latch_time; it moves at once after (measured: the hold's
        # |v| <= 0.68 x the bound, the next sample's >= 6.6 x)
        moving = on + 1 + np.flatnonzero(np.abs(v[on + 1:]) > still)[0]
        assert abs(t[moving - 1] - tc - latch) <= 0.5 * dt + 1e-9


def test_declutching_is_off_for_declutch_time_then_damps(plant):
    wave, c, tau = waves.regular(1.0, T_SHORT), 1.8e6, 1.17
    dt = T_SHORT / 500
    ctrl = Declutching(c, tau, force_max=NO_LIMIT)
    ds = simulate(plant, wave, duration=12 * T_SHORT, dt=dt, controller=ctrl)
    t, v, F = (ds[k].values for k in ("time", "pto__velocity", "pto__force"))
    held, holds = schedule(t, v, tau, rearm=1)
    # open (F = 0 exactly) from the first sample after each crossing to the sample nearest
    # crossing + declutch_time, the damper everywhere else
    free = ~held[:-1]
    assert np.all(F[:-1][held[:-1]] == 0.0)
    assert np.allclose(F[:-1][free], -c * v[:-1][free], rtol=1e-12, atol=0)
    assert np.all(v[:-1][held[:-1]] != 0)                # so the two laws are told apart
    assert len(holds) >= 2 * 12 - 1                      # measured 24
    ends = [t[off] if off < t.size - 1 else np.inf for _, off, _ in holds]
    assert np.allclose([(t[on], e) for (on, _, _), e in zip(holds, ends)], ctrl.holds[0],
                       rtol=0, atol=1e-9)                 # and its own record agrees


# --- 2. chatter: what the switching promises right after a release --------------------------

def feed(plant, controller, ts, vs):
    """Commands of `controller` for a synthetic PTO velocity sequence."""
    controller.reset(plant)
    y, k = np.zeros(len(plant.outputs)), plant.outputs.index("pto__velocity")
    out = []
    for t, v in zip(ts, vs):
        y[k] = v
        out.append(float(controller(t, y)[0]))
    return np.array(out)


def test_latching_ignores_dither_in_hold_and_release_residual(plant):
    c, h = 1.0e3, 0.1
    ts = h * np.arange(12)
    # a crossing at 0.15 s latches for 0.25 s -> release at 0.4 s; in the hold and at release
    # v dithers around 0 (the brake's residual), then moves off with the opposite sign
    vs = np.array([1, .5, -.5, 1e-6, -1e-6, 2e-6, .3, .6, .6, .3, -.3, -.6])
    ctrl = Latching(c, 0.25, force_max=NO_LIMIT)
    u = feed(plant, ctrl, ts, vs)
    damper = u == -c * vs
    # reference: held at 0.2, 0.3 s only; the release sample's -1e-6 against the next +2e-6
    # is not a crossing (sign taken afresh), nor is the in-hold dither; 0.95 s is
    assert list(~damper) == [False, False, True, True] + [False] * 6 + [True, True]
    assert [(round(a, 9), b) for a, b in ctrl.holds[0]] == [(0.2, 0.4), (1.0, np.inf)]
    # the opposite case: no dead band. Once the sign is re-taken (one sample after the
    # release), the next sign change latches however small it is: a dither re-triggers
    vs2 = np.array([1, .5, -.5, 1e-6, -1e-6, -2e-6, 2e-6, .3, .6, .6, .6, .6])
    u2 = feed(plant, Latching(c, 0.25, force_max=NO_LIMIT), ts, vs2)
    # reference: crossing at 0.55 s (-2e-6 -> 2e-6) -> held at 0.6, 0.7 s, released at 0.8 s
    assert list(u2 != -c * vs2) == [False, False, True, True, False, False, True, True] + \
        [False] * 4
    # a short latch whose release rounds to its own crossing sample never engages
    u3 = feed(plant, Latching(c, 0.02, force_max=NO_LIMIT), ts, vs)
    assert np.array_equal(u3, -c * vs)


def test_declutching_counts_a_crossing_right_after_release(plant):
    c, h = 1.0e3, 0.1
    ts = h * np.arange(8)
    # declutched at the 0.15 s crossing for 0.27 s -> released at 0.4 s with v = -0.2 (real,
    # the clutch was open), which crosses again at 0.45 s: a crossing while damping
    vs = np.array([1, .5, -.5, -.6, -.2, .2, .5, .6])
    ctrl = Declutching(c, 0.27, force_max=NO_LIMIT)
    u = feed(plant, ctrl, ts, vs)
    # reference: open at 0.2, 0.3 s; damper at 0.4 s; open again from 0.5 s to 0.72 -> 0.7 s
    assert list(u == 0.0) == [False, False, True, True, False, True, True, False]
    assert [(round(a, 9), round(b, 9)) for a, b in ctrl.holds[0]] == [(0.2, 0.4), (0.5, 0.7)]


# --- 3. tuners against the classical rule and brute-force scans ------------------------------

def test_latch_tuner_vs_classical_rule_and_scan(plant):
    wave = waves.regular(2.5, T_LONG)
    dt, skip, periods = T_LONG / 250, 8, 3       # the scan repeats the tuner's objective
    Tn = natural_period(plant)
    # natural_period against the root of Im Z_i from the arrays (measured 4.36491 vs 4.36494 s)
    assert Tn == pytest.approx(natural_period_reference(plant), rel=1e-4)
    latch, c, tuned = optimal_latch_time(plant, wave, dt=dt, skip=skip, periods=periods,
                                         force_max=NO_LIMIT)
    B = heave_impedance(plant, np.array([2 * np.pi / Tn]))[0].real[0]
    assert c == pytest.approx(B, rel=1e-3)         # its default: B(omega_n), 89.3 kN s/m

    # the rule assumes a memory-free body of inertia m + A(omega_n) with no damping:
    # (T - T_n) / 2 = 2.651 s. Damping lengthens the free swing (T_d = T_n / sqrt(1 -
    # zeta^2)), and the body released from rest swings like one of inertia nearer m + A_inf
    # (A_inf 131 t > A(omega_n) 110 t): both shorten the best latch. An exact event-driven
    # simulation of the memory-free oscillator (written for this review) put its optimum
    # within 0.015 s of (T - T_d) / 2: 2.625 s with m + A(omega_n), 2.566 s with m + A_inf.
    # So the sphere's optimum lies between (T - T_d,inf) / 2 = 2.560 s and the rule.
    # measured: tuner 2.577 s, 0.074 s (0.8 % of T) below the rule
    K = plant.hydro.hydrostatic_stiffness()[0, 0]
    M_inf = plant.scene.bodies[0].mass + plant.hydro.added_mass_inf[0, 0]
    zeta = (B + c) / (2 * np.sqrt(K * M_inf))
    T_d_inf = 2 * np.pi * np.sqrt(M_inf / K) / np.sqrt(1 - zeta ** 2)
    assert 0.5 * (T_LONG - T_d_inf) <= latch <= 0.5 * (T_LONG - Tn)

    def power(x):
        ds = simulate(plant, wave, duration=(skip + periods) * T_LONG, dt=dt,
                      controller=Latching(c, x, force_max=NO_LIMIT))
        return work_power(ds, T_LONG, skip, periods)

    # brute force over the tuner's whole window every 0.1 s (the peak is ~0.24 s wide at half
    # height, and skewed: every 0.2 s missed it), then every 0.02 s around the best: finer
    # than the step dt = 0.039 s, the resolution of the switching itself
    rule = 0.5 * (T_LONG - Tn)
    coarse = np.arange(rule - 0.1 * T_LONG, rule + 0.1 * T_LONG, 0.1)
    best = coarse[int(np.argmax([power(x) for x in coarse]))]
    fine = np.arange(best - 0.1, best + 0.1 + 1e-9, 0.02)
    values = np.array([power(x) for x in fine])
    k = int(np.argmax(values))
    # measured: scan best 2.584 s at 821.0 kW; tuner 2.577 s at 822.9 kW; the rule 707.2 kW
    assert 0 < k < fine.size - 1                  # an interior maximum, not the window's edge
    # the release snaps to the nearest sample, so latch times one step apart switch alike
    assert abs(latch - fine[k]) <= dt
    assert tuned >= 0.995 * values[k]
    assert tuned == pytest.approx(power(latch), rel=1e-6)   # its power is the run's work
    assert tuned > 1.1 * power(rule)              # the tuning beats the rule itself


def test_declutch_tuner_vs_scan(plant):
    wave = waves.regular(1.0, T_SHORT)
    # skip 4 periods, not the default 8: the heavily damped start-up has settled by then
    # (power within 1 % of skip 8, measured)
    dt, skip, periods = T_SHORT / 250, 4, 2
    tau, c, tuned = optimal_declutch(plant, wave, dt=dt, skip=skip, periods=periods,
                                     force_max=NO_LIMIT)
    Z = abs(heave_impedance(plant, wave.omega)[0][0])

    def rule(x):             # the documented damping: |Z_i| stretched over the damped share
        return Z * T_SHORT / (T_SHORT - 2 * x)

    assert c == pytest.approx(rule(tau), rel=1e-3)

    def power(x):
        ds = simulate(plant, wave, duration=(skip + periods) * T_SHORT, dt=dt,
                      controller=Declutching(rule(x), x, force_max=NO_LIMIT))
        return work_power(ds, T_SHORT, skip, periods)

    coarse = np.arange(0.0, 0.45 * T_SHORT + 1e-9, 0.02 * T_SHORT)
    best = coarse[int(np.argmax([power(x) for x in coarse]))]
    fine = np.arange(best - 0.02 * T_SHORT, best + 0.02 * T_SHORT + 1e-9, dt)
    values = np.array([power(x) for x in fine])
    k = int(np.argmax(values))
    # the objective is flat on top and rough at the 0.5 % level (the damper is held over a
    # step with h c / M ~ 5 %, switched at samples): the tuner must match the scan's best
    # power within that, at a tau inside the scan's top 1 %
    # measured: scan best 1.200 s at 3034.5 W, top 1 % 1.140..1.212 s; tuner 1.174 s at
    # 3043.5 W (1832 kN s/m); tau = 0 (a damper |Z_i| = 398 kN s/m): 1349.1 W
    assert 0 < k < fine.size - 1
    top = fine[values >= 0.99 * values[k]]
    assert top.min() - dt <= tau <= top.max() + dt
    assert tuned >= 0.995 * values[k]
    assert tuned > 1.5 * power(0.0)
