"""Linear model-predictive control of the PTO force: maximise absorbed energy over a horizon.

Every `dt_s` seconds the controller estimates the control-plant state and the excitation,
forecasts the excitation over `horizon_s`, solves a convex QP for the force sequence and
applies its first move (held, zero-order). The QP, with U the forces over the horizon (held
over each step) and P the PTO positions at the ends of the steps:

    minimise   sum_k u_k . (p_k+1 - p_k)          (minus the absorbed energy, J)
             + r |U|^2 + w1 |s|_1 + w2 |s|^2      (force penalty, stroke slack)
    subject to |u_k| <= force_max, |u_k - u_k-1| <= rate_max dt, |p_k| <= stroke_max + s_k
               (force_max_on = "hull": the hull's force at each step's ends, mpc_qp)

The energy of a held force is exactly u_k (p_k+1 - p_k). Condensed (P affine in U), the
energy term is U^T G U + q^T U with G + G^T positive semidefinite whenever the plant is
passive from force to velocity (the energy a PTO puts into a passive body at rest is never
negative), so the QP is convex; r adds a small margin (force_penalty times the largest
eigenvalue) that makes it strictly convex and keeps the force from chattering. The stroke
limit is soft (slack s >= 0 with an exact L1 penalty) so the QP is always feasible; with
soft_stroke=False it is hard, and a state from which it cannot be met is reported (counted,
warned once, the previous plan's next move applied), not a crash.

Two solver paths on the same scaled QP: "qpoases" (the real-time path: the dense condensed
QP through CasADi's qpOASES interface, matrices built once) and "cvxpy" (the prototyping
path: a cvxpy Problem with Parameters, built once, solved by Clarabel).

State and excitation (`estimator`): "kalman" (default) estimates both from the joint
encoders (controllers.estimation.ExcitationKalman); "state" hands the controller the plant's
state (an oracle for studies, `uses_state`). Forecast (`forecast`): "ar" (the default:
auto-regressive on the Kalman estimates, causal), "model" (the Kalman wave model's free
motion), "none" (zero), "known" (the true future excitation from `wave`: a non-causal
oracle, only when asked; describe() then labels the run an upper bound). A `wave` given with
a causal forecast only sets the Kalman wave model's frequencies and the warm-up damper.

Start-up (warm-up). Until the AR predictor has its first fit the controller applies the
tuned passive damper instead, then blends over to the MPC in one peak period (per PTO,
computed once in reset(): `optimal_damping` for the
sea by linear theory, or |Z_i| at the wave model's frequency without a wave), clipped to the
force limit. The first fit waits for WARM_UP_PERIODS peak periods of estimates (at least
4 x ar_order samples): an AR(8) fitted to the first 32 samples (6.4 s, during the wave's
ramp) learnt the ramp's growth (companion spectral radius 1.14 on rm3) and its forecast,
500 times the excitation 10 s ahead, drove rm3 to 237 m strokes. describe()["warm_up_s"] is
the time the MPC took over; mbcontrol.analysis.metrics starts its statistics after it. A
fitted AR model that is unstable (a root of its characteristic polynomial outside the unit
circle) is stabilised by reflecting those roots into it (estimation.ArPredictor; counted in
describe()["stats"]["ar_unstable_fits"]). With no force limit (rm3's and the OSWEC's
scenes have none) the QP is regularised by force_penalty alone. A PTO whose scene sets no
stroke limit gets a soft one at LINEAR_RANGE_SHARE of the range where the linear model
holds (see LINEAR_RANGE_SHARE; reported in describe()["stroke_max_default"]).

Envelope (envelope=True, the default): the quantities the physics checks measure, each
body's heave relative to the surface (a probe measures the surface at the body; needs the
wave) and its roll and pitch, are soft constraints at every step of the horizon, each within
analysis.peak_share() of the check's limit (controllers.mpc_envelope;
describe()["envelope"]). Without
it the MPC rode PacWave's seas outside the linear model's range: sphere 28, rm3 17, OSWEC 10
of 32 seas INVALID (200 s each); with it none.

Three parts, as do-mpc separates settings, setup and data and Pinocchio its Model and Data:
`mpc.settings` (MpcSettings, frozen: what `Mpc(**settings)` was given), `mpc.setup`
(MpcSetup, built by reset(plant) from the plant and the settings, fixed once built) and
`mpc.run` (MpcRun, this run's estimates, warm start and log, fresh at every reset).
`mpc.build_setup(plant)` builds a setup without touching the controller: the exporter reads
the settings and such a setup, never the caller's run. The names the Mpc had before the
split read through: mpc.horizon_s is mpc.settings.horizon_s, mpc.qp is mpc.setup.qp,
mpc.stats is mpc.run.stats (read-only).
"""
from __future__ import annotations

import inspect
import time
import warnings
from typing import NamedTuple

import numpy as np

from mbcontrol.errors import ControllerError
from mbcontrol.results import jsonable

from .estimation import excitation_error
from .law import PredictiveLaw
from .limits import LINEAR_RANGE_SHARE
from .mpc_settings import ORACLE_LABEL, SETTING_NAMES, MpcSettings
from .mpc_setup import WARM_UP_PERIODS, MpcRun, MpcSetup, build_setup

# defined here (MpcSettings, MpcSetup, MpcRun and WARM_UP_PERIODS are documented where they
# are defined, controllers.mpc_settings and mpc_setup; they stay importable from here)
__all__ = ["Mpc", "MpcView", "ORACLE_LABEL"]


class MpcView(NamedTuple):
    """What leaves the controller for the exporter (Mpc.export_view): settings (frozen), a
    setup built afresh for the plant (fixed), and description, the describe() of an MPC
    bound to that setup before its first step."""
    settings: MpcSettings
    setup: MpcSetup
    description: dict


class Mpc(PredictiveLaw):
    """Linear MPC of the PTO force(s). Settings (the contract names first; MpcSettings
    gives each with its unit and default):

    horizon_s, dt_s: prediction horizon and control period, s (dt_s a multiple of the
    simulation step); force_max (N or N m), stroke_max (m or rad), rate_max (N/s): limits,
    None = the scene PTO's (rate: unlimited); wave: the sea (the Kalman wave model's
    frequencies and the warm-up damper; the forecast only with forecast "known"); forecast:
    "ar" (default, causal), "model", "none", or "known" (the oracle, labelled a bound);
    warm_up_s: passive damping until this time, s (None: WARM_UP_PERIODS peak periods with
    the AR forecast, 0 otherwise; with "ar", until its first fit); estimator: "kalman" or
    "state"; solver: "qpoases" or "cvxpy"; order: reduce the control plant to this many
    states (balanced truncation), None = full; force_penalty: r relative to the energy
    Hessian's largest eigenvalue; stroke_penalty: slack weights (w1 = w2 in scaled units);
    soft_stroke; measured: output names the Kalman filter reads (default: every joint
    coordinate and rate); ar_order; measurement_noise (Kalman, relative); objective: "auto"
    (electrical power for PTOs with a drivetrain: each step's winding loss R F^2 dt /
    (gear kt')^2 enters the QP), "electrical" or "mechanical"; envelope: keep the linear
    model's range (see the module docstring); blocks: move blocking, the force held over
    blocks of steps (None: one force per step; a count, or the lengths: mpc_blocks).

    settings: MpcSettings; setup: MpcSetup of the last reset(plant) (None before); run:
    MpcRun of this run (None before).
    """
    name = "mpc"
    # the law protocol (controllers.law): its settings are MpcSettings, and with limits on, a
    # limit the scene leaves free keeps the MPC's own default (a soft stroke in its range)
    Settings, exportable, own_free_limits = MpcSettings, True, True
    # what the C engine needs that Python does not: the exporter and its Python twin run
    # with these settings (mbcontrol.cli.export adds them unless given, and says why)
    # and 16 blocks of move blocking (mpc_blocks: 1,1,2,2,2,2,3 x 10 steps over 40): the
    # step's time bound. Measured (benchmarks/export_step.py --blocks, 10^5 steps, sphere):
    # step CPU median / p99 88 / 196 -> 19 / 38 us (force, stroke, slew limits binding) and
    # 117 / 233 -> 14 / 31 us (PacWave's worst sea), mean power -0.56 % and -0.39 %; 10
    # blocks -0.23 % and -0.83 %, 8 blocks -45 % in the worst sea
    export_settings = {"envelope": False, "blocks": 16}
    export_note = ("the MPC is exported without the linear model's envelope (its "
                   "relative-heave and angle constraints need a surface probe the C engine "
                   "does not read yet) and with its force held over 16 blocks of the horizon "
                   "(move blocking: a bounded step time): the export and its Python check "
                   "both run with envelope=false, blocks=16")

    def __init__(self, *args, **settings):
        self.settings = MpcSettings(*args, **settings)
        self.setup: MpcSetup | None = None
        self.run: MpcRun | None = None

    @classmethod
    def from_settings(cls, settings: MpcSettings) -> Mpc:
        """An Mpc with these settings (frozen: shared safely)."""
        mpc = cls.__new__(cls)
        mpc.settings, mpc.setup, mpc.run = settings, None, None
        return mpc

    @property
    def period(self) -> float:
        """s: the control period (zero-order hold), dt_s."""
        return self.settings.dt_s

    @property
    def uses_state(self) -> bool:
        return self.settings.uses_state

    # -- set-up --------------------------------------------------------------------------
    def build_setup(self, plant) -> MpcSetup:
        """A setup for `plant` from the settings; the controller is left as it is."""
        return build_setup(self.settings, plant)

    def export_view(self, plant) -> MpcView:
        """The settings and a fresh setup for `plant` (with the description of an MPC bound
        to it): all that mbcontrol.export reads. The controller is left as it is."""
        twin = Mpc.from_settings(self.settings)
        twin.reset(plant)
        return MpcView(self.settings, twin.setup, twin.describe())

    def reset(self, plant) -> None:
        """Bind to `plant`: build the setup, start a fresh run."""
        self.setup = build_setup(self.settings, plant)
        self.run = self.setup.new_run()

    # -- the control law -----------------------------------------------------------------
    def __call__(self, t: float, y: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
        s, r, st = self.setup, self.run, self.settings
        if s is None:
            raise ControllerError("mpc: call reset(plant) before using the controller")
        cp = s.cp
        if r.last_t is not None and t < r.last_t + st.dt_s * (1 - 1e-6):
            # called again within a period (simulate's closing sample, off the controller's
            # grid): hold the command. Updating the filter here would step its discrete model
            # by a whole period for a fraction of one (measured on rm3: a 228 MN command).
            return r.u_prev.copy()
        r.last_t = float(t)
        if st.estimator == "state":
            z = cp.T @ np.asarray(x, float)
        else:
            ym = np.asarray(y, float)[cp.y_index] - cp.y_rest
            r.kalman.update(ym, r.u_prev)
            z = r.kalman.z
        if r.kalman is not None:
            r.history.append((t, r.kalman.d.copy()))
            if r.ar is not None:
                r.ar.append(r.kalman.d)
        s.env.measure(t, r.surface_ar)       # the surface probes: a measurement, now
        velocity = list(s.velocity)
        if self._warming_up(t):              # the tuned damper until the predictor has a fit
            u = -s.warm_up_damping * np.asarray(y, float)[velocity]
            r.u_prev = np.clip(u, -s.limits["force"], s.limits["force"])
            return r.u_prev.copy()
        known = self._known_forecast(t) if st.forecast == "known" else None
        D = self._forecast(known)
        start = time.perf_counter()
        U, status = s.qp.solve(z, D, r.u_prev, r.plan, s.env.offset(t, s.N, r.surface_ar),
                               work=r.qp)
        r.stats["solve_s"].append(time.perf_counter() - start)
        r.stats["solves"] += 1
        if U is None:
            self._failed(t, status)
            U = self._shifted_plan()
        r.plan = U
        u = U[0]
        if r.warm_up_end is not None and t < r.warm_up_end + s.blend_s:
            # bumpless take-over: from the damper to the MPC over one peak period (its first
            # plan alone kicked rm3's PTO with 12 MN, 4x its later peaks)
            share = (t - r.warm_up_end) / s.blend_s
            u = share * u - (1 - share) * s.warm_up_damping * np.asarray(y, float)[velocity]
        r.u_prev = np.clip(u, -s.limits["force"], s.limits["force"])
        return r.u_prev.copy()

    def _forecast(self, known) -> np.ndarray:
        s, r = self.setup, self.run
        n, nd = s.N, s.cp.nd
        if known is not None:
            return known
        if self.settings.forecast == "none" or nd == 0:
            return np.zeros((n, nd))
        if r.ar is not None:
            predicted = r.ar.forecast(n)
            if predicted is not None:
                return predicted
        return r.kalman.model_forecast(n)

    def _warming_up(self, t: float) -> bool:
        r = self.run
        if r.warm_up_end is not None:
            return False
        ready = (r.ar.coefficients is not None if r.ar is not None
                 else t >= self.setup.warm_up_planned - 1e-9)
        if ready:
            r.warm_up_end = float(t)
        return not ready

    def _known_forecast(self, t: float) -> np.ndarray:
        """d at the midpoints of the next N periods from the wave (cached in blocks)."""
        s, r, dt = self.setup, self.run, self.settings.dt_s
        k0 = int(round(t / dt))
        start, block = r.excitation_cache
        if start is None or k0 < start or k0 + s.N > start + len(block):
            times = (k0 + np.arange(s.N + 2000) + 0.5) * dt
            block = s.plant.excitation(self.settings.wave, times) @ s.cp.S.T
            r.excitation_cache = (k0, block)
            start = k0
        return block[k0 - start:k0 - start + s.N]

    def _failed(self, t: float, status: str) -> None:
        r = self.run
        r.stats["failures"] += 1
        if "infeasible" in status.lower():
            r.stats["infeasible"] += 1
        if not r.warned:
            r.warned = True
            hint = (" The hard stroke limit cannot be met from this state; use soft_stroke=True "
                    "(the default)." if not self.settings.soft_stroke else "")
            warnings.warn(f"mpc: QP not solved at t = {t:.4g} s ({status}); applying the previous "
                          f"plan's next move.{hint} Counts are in describe()['stats'].",
                          RuntimeWarning, stacklevel=3)

    def _shifted_plan(self) -> np.ndarray:
        plan = self.run.plan
        if plan is None:
            return np.zeros((self.setup.N, len(self.setup.cp.ptos)))
        return np.vstack([plan[1:], plan[-1:]])

    def casadi_law(self, plant):
        return None                      # dynamic (estimator, horizon): runs in Python

    def estimation_report(self, t, W) -> dict | None:
        """The Kalman excitation estimate's accuracy against the simulation's true excitation
        W (on times t, s), after the warm-up (estimation.excitation_error); simulate calls it."""
        r = self.run
        if r is None or not r.history:
            return None
        start = r.warm_up_end if r.warm_up_end is not None else self.setup.warm_up_planned
        times, estimates = zip(*r.history)
        return excitation_error(times, np.array(estimates), t, W, self.setup.cp.S, start)

    def describe(self) -> dict:
        st, s, r = self.settings, self.setup, self.run
        stats = dict(r.stats) if r is not None else {}
        times = np.asarray(stats.pop("solve_s", [])) * 1e3
        if r is not None:
            stats["soft_solves"] = r.qp.soft_solves
            if r.ar is not None:
                stats["ar_fits"] = r.ar.fits
                stats["ar_unstable_fits"] = r.ar.unstable_fits
        if times.size:
            stats.update(solve_ms_median=float(np.median(times)),
                         solve_ms_p95=float(np.percentile(times, 95)))
        out = {"name": self.name, "horizon_s": st.horizon_s, "dt_s": st.dt_s,
               "force_max": jsonable(st.force_max), "stroke_max": jsonable(st.stroke_max),
               "rate_max": jsonable(st.rate_max), "forecast": st.forecast,
               "oracle": st.oracle, "label": st.label(),
               "estimator": st.estimator + (" (full-state oracle)" if st.uses_state else ""),
               "solver": st.solver, "order": st.order, "soft_stroke": st.soft_stroke,
               "envelope_on": st.envelope,
               "period_s": self.period, "stats": stats}
        out.update(self._warm_up_report())
        if s is not None and st.envelope:
            out["envelope"] = s.env.report()
        if s is not None and s.stroke_default:
            out["stroke_max_default"] = {
                "values": {k: float(v) for k, v in s.stroke_default.items()},
                "why": f"the scene sets no stroke limit: a soft one at {LINEAR_RANGE_SHARE:g} of "
                       f"the linear-hydrodynamics range (30 deg; the shallowest mean draft), "
                       f"where the MPC's linear model holds"}
        return out

    def label(self) -> str:
        """How causal the run is, for JSON, Datasets and figure legends."""
        return self.settings.label()

    def _warm_up_report(self) -> dict:
        """warm_up_s: when the MPC took over (the plan before a run, or when it never did)."""
        s, r = self.setup, self.run
        if s is None:
            return {"warm_up_s": self.settings.warm_up_s}
        end = r.warm_up_end if r.warm_up_end is not None else s.warm_up_planned
        return {"warm_up_s": float(end),
                "warm_up": {"law": "passive damper u = -c v until the first AR fit"
                            if s.ar is not None else "passive damper u = -c v",
                            "damping": [float(c) for c in s.warm_up_damping],
                            # < 1: the sea's damper scaled down to keep its loop held over
                            # dt_s stable (controllers.sampled.held_dampers)
                            "held_factor": float(s.warm_up_factor),
                            "planned_s": float(s.warm_up_planned),
                            "take_over_s": float(s.blend_s),
                            "completed": r.warm_up_end is not None}}


def _view(part: str, name: str) -> property:
    def read(self):
        holder = getattr(self, part)
        if holder is None:
            raise AttributeError(f"mpc.{name}: call reset(plant) first (it is mpc.{part}.{name})")
        return getattr(holder, name)
    return property(read, doc=f"mpc.{part}.{name} (read-only)")


# the Mpc's names from before the split, read-only, each from the part that now holds it
for _name in SETTING_NAMES:
    setattr(Mpc, _name, _view("settings", _name))
for _name in ("plant", "cp", "qp", "N", "limits", "env", "device_omega", "stroke_default",
              "warm_up_planned", "blend_s", "warm_up_damping", "warm_up_factor"):
    setattr(Mpc, _name, _view("setup", _name))
for _name in ("stats", "history", "warm_up_end", "u_prev", "ar"):
    setattr(Mpc, _name, _view("run", _name))
Mpc.warm_up_setting = _view("settings", "warm_up_s")
# Mpc(**settings) takes exactly MpcSettings' arguments (one list of names and defaults)
Mpc.__signature__ = inspect.signature(MpcSettings).replace(
    return_annotation=inspect.Signature.empty)
