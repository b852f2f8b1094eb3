"""The MPC's setup and run data (controllers.mpc): what is built from a plant and the settings,
and what one run keeps.

`MpcSetup` (`build_setup(settings, plant)`): the control plant, the limits per PTO, the
condensed QP (matrices, forms and solvers), the Kalman filter's model, the AR predictors'
configurations, the envelope rows and the warm-up plan. Fixed once built: its arrays are
read-only, and no solve, filter step or forecast changes it, so it can be read (by the
exporter, `mbcontrol.export`) or shared without touching a run.

`MpcRun` (`setup.new_run()`): one run's state, from rest: the Kalman estimate, the AR
predictors' histories and fits, the QP's warm start (the last plan, the active set, the form
that solved last), the last command, the warm-up's end, and the log (solve counts and times,
the excitation estimates).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from mbcontrol.analysis import winding_coefficient
from mbcontrol.errors import ControllerError

from .base import signal_indices
from .control_plant import ControlPlant, build_control_plant, device_frequency, hydro_band, \
    pto_impedance
from .estimation import (ArConfig, ArPredictor, ExcitationKalman, KalmanEstimate,
                         wave_frequencies)
from .limits import command_limit, hull_limits, linear_range, per_pto_values
from .mpc_blocks import block_lengths
from .mpc_envelope import MpcEnvelope
from .mpc_qp import CondensedQp, QpWork
from .mpc_settings import FrozenDict, MpcSettings
from .sampled import held_dampers

# warm-up before the first AR fit, in peak periods of the sea (or of the wave model without
# a wave): 5 periods give the least-squares fit 5 T / dt_s samples (225 for rm3 at Tp 9 s,
# dt_s 0.2 s: 28 per AR(8) coefficient), 3 periods past the simulation's ramp (2 Tp). The
# root reflection alone already prevents the blow-up; the warm-up is for the fit's quality.
# Measured on rm3 (Hs 2 m, Tp 9 s, seeds 0-2, 400 s, power over t >= 80 s): 278.5-279.3,
# 254.1-255.9 and 247.9-248.8 kW for warm-ups of 0-5 periods (within 0.7 %), stabilised
# fits 10 -> 3, 12 -> 6, 7 -> 1 from 0 to 5 periods; 8 periods gave +0.6 % to +4.4 % power
# but costs another 27 s of every record's statistics
WARM_UP_PERIODS = 5.0


@dataclass(frozen=True)
class MpcSetup:
    """What an MPC builds from a plant and its settings; fixed once built.

    N: horizon steps; limits: {"force" (N or N m), "stroke" (m or rad), "rate" (N/s)}: one
    value per PTO of cp.ptos; stroke_default: {PTO: m or rad} the soft stroke limits set
    where the scene sets none (None when stroke_max was given); device_omega (rad/s): the
    device's resonance seen from its PTO; omega (rad/s): the Kalman wave model's frequencies;
    kalman: the filter's model (None with estimator "state"); ar, surface_ar: the excitation's
    and the surface probes' AR predictor configurations (None: no AR forecast); velocity:
    the PTO velocities' indices in the plant's outputs; warm_up_planned (s), blend_s (s, the
    take-over), warm_up_damping (N s/m or N m s/rad, per PTO) and warm_up_factor (<= 1: the
    sea's damper scaled down to keep its held loop stable): the warm-up plan."""
    settings: MpcSettings
    plant: object
    cp: ControlPlant
    N: int
    limits: FrozenDict
    stroke_default: FrozenDict | None
    device_omega: float
    omega: np.ndarray
    env: MpcEnvelope
    qp: CondensedQp
    kalman: ExcitationKalman | None
    ar: ArConfig | None
    surface_ar: ArConfig | None
    velocity: tuple
    warm_up_planned: float
    blend_s: float
    warm_up_damping: np.ndarray
    warm_up_factor: float

    def new_run(self) -> MpcRun:
        """Fresh run data: every estimate at rest, no plan, an empty log."""
        nu = len(self.cp.ptos)
        return MpcRun(kalman=None if self.kalman is None else self.kalman.estimate(),
                      ar=None if self.ar is None else self.ar.predictor(),
                      surface_ar=None if self.surface_ar is None else self.surface_ar.predictor(),
                      qp=self.qp.workspace(), u_prev=np.zeros(nu))


@dataclass(eq=False)
class MpcRun:
    """One run of an MPC: kalman (the filter's estimate), ar and surface_ar (the predictors'
    histories and fits), qp (the QP's warm start and counters), u_prev (N or N m, the last
    command), plan ((N, nu) forces of the last solve), last_t (s, the last call),
    warm_up_end (s, when the MPC took over; None before), excitation_cache (the oracle's
    forecast block), stats (solves, failures, infeasible, solve_s: wall times in s),
    history ((t, d estimate) per call), warned (a failed solve was reported)."""
    kalman: KalmanEstimate | None
    ar: ArPredictor | None
    surface_ar: ArPredictor | None
    qp: QpWork
    u_prev: np.ndarray
    plan: np.ndarray | None = None
    last_t: float | None = None
    warm_up_end: float | None = None
    excitation_cache: tuple = (None, None)
    stats: dict = field(default_factory=lambda: {"solves": 0, "failures": 0,
                                                 "infeasible": 0, "solve_s": []})
    history: list = field(default_factory=list)
    warned: bool = False


def build_setup(settings: MpcSettings, plant) -> MpcSetup:
    """The MPC's setup for `plant`: the control plant at dt_s, the limits, the QP, the filter,
    the predictors' configurations and the warm-up plan (warns when no wave is given)."""
    s = settings
    env = MpcEnvelope(plant, s.wave, on=s.envelope, forecast=s.forecast, dt=s.dt_s)
    cp = build_control_plant(plant, s.dt_s, measured=s.measured, order=s.order,
                             extra_outputs=env.outputs)
    ptos = [p for p in plant.scene.ptos if p.name in cp.ptos]
    strokes = [p.stroke_max if math.isfinite(p.stroke_max) else linear_range(plant, p.name)
               for p in ptos]
    stroke_default = None if s.stroke_max is not None else FrozenDict(
        {p.name: v for p, v in zip(ptos, strokes) if not math.isfinite(p.stroke_max)})
    hull = hull_limits(ptos, list(cp.ptos), s.force_max)   # force_max_on = "hull"
    limits = FrozenDict({
        "force": per_pto_values(plant, s.force_max, [command_limit(p) for p in ptos],
                                "force_max"),
        "stroke": per_pto_values(plant, s.stroke_max, strokes, "stroke_max"),
        "rate": per_pto_values(plant, s.rate_max, [math.inf] * len(ptos), "rate_max")})
    N = int(round(s.horizon_s / s.dt_s))
    efficiency = per_pto_values(plant, s.efficiency, [p.efficiency for p in ptos], "efficiency")
    device_omega = device_frequency(cp, hydro_band(plant))
    if s.wave is None:
        warnings.warn(f"mpc: no sea state given (wave=...): the Kalman wave model is centred "
                      f"on the device's resonance seen from its PTO ({device_omega:.3g} "
                      f"rad/s, period {2 * np.pi / device_omega:.3g} s), a guess; the "
                      f"sea's own spectrum estimates the excitation better", RuntimeWarning,
                      stacklevel=3)
    omega = wave_frequencies(s.wave, device_omega)
    winding = [0.0 if s.objective == "mechanical" else winding_coefficient(plant, p.name)
               or 0.0 for p in ptos]            # a drivetrain's R / (gear kt')^2, W/N^2
    qp = CondensedQp(cp, N, limits, efficiency=efficiency, winding=winding,
                     loss_damping=pto_impedance(cp, float(np.median(omega))),
                     force_penalty=s.force_penalty, stroke_penalty=s.stroke_penalty,
                     soft_stroke=s.soft_stroke, solver=s.solver, envelope=env.rows(cp),
                     hull=hull, blocks=block_lengths(s.blocks, N))
    if s.estimator == "kalman":
        kalman = ExcitationKalman(cp, omega, measurement_noise=s.measurement_noise)
    else:
        kalman = None
        if s.forecast != "known":
            raise ControllerError("mpc: estimator 'state' knows no excitation; use forecast 'known'")
    planned, blend_s = _warm_up_time(s, device_omega)
    ar = (ArConfig(cp.nd, s.dt_s, order=s.ar_order,
                   min_samples=int(math.ceil(planned / s.dt_s - 1e-9)) + 1)
          if s.forecast == "ar" else None)
    damping, factor = _warm_up_damping(s, plant, cp, omega)
    setup = MpcSetup(settings=s, plant=plant, cp=cp, N=N, limits=limits,
                     stroke_default=stroke_default, device_omega=device_omega, omega=omega,
                     env=env, qp=qp, kalman=kalman, ar=ar, surface_ar=env.surface_config(ar),
                     velocity=tuple(signal_indices(plant, [f"{n}__velocity" for n in cp.ptos])),
                     warm_up_planned=planned, blend_s=blend_s, warm_up_damping=damping,
                     warm_up_factor=factor)
    _read_only(setup)
    return setup


def _warm_up_time(s: MpcSettings, device_omega: float) -> tuple[float, float]:
    """(planned warm-up, take-over), s: the setting, or WARM_UP_PERIODS peak periods (AR
    forecast); the take-over lasts one peak period."""
    period = float(s.wave.period) if s.wave is not None else 2 * np.pi / device_omega
    if s.warm_up_s is not None:
        planned = float(s.warm_up_s)
    elif s.forecast != "ar":
        planned = 0.0
    else:
        planned = max(WARM_UP_PERIODS * period, (4 * s.ar_order - 1) * s.dt_s)
    return planned, (period if planned > 0 else 0.0)


def _warm_up_damping(s: MpcSettings, plant, cp, omega) -> tuple[np.ndarray, float]:
    """(the warm-up damper per PTO, N s/m; its held factor): optimal_damping for the sea
    (linear theory, the other PTOs free), or |Z_i| at the wave model's median frequency (the
    regular-wave optimum) without a wave or when the sea lies outside the hydro data. A
    limit on the hull is not held during the warm-up (the command clip holds a machine
    limit)."""
    out = pto_impedance(cp, float(np.median(omega)))
    if s.wave is not None:
        from .passive import optimal_damping
        for i, name in enumerate(cp.ptos):
            try:
                out[i] = optimal_damping(plant, s.wave, pto=name)[0]
            except ValueError:
                pass
    # held over dt_s, as it is applied: a damper tuned in continuous time can destabilise
    # the sampled loop (rm3, Tp >= 11.3 s, dt_s 0.2 s: the cause of its divergences)
    held, factor = held_dampers(plant, dict(zip(cp.ptos, out)), s.dt_s)
    return np.array([held[name] for name in cp.ptos]), float(factor)


def _read_only(setup: MpcSetup) -> None:
    """Every array the setup built made read-only: a run that wrote into one would change
    every later run (the plant and the wave are the caller's, left as they are)."""
    seen = set()

    def freeze(obj, depth=0):
        if id(obj) in seen or depth > 8:
            return
        seen.add(id(obj))
        if isinstance(obj, np.ndarray):
            obj.flags.writeable = False
        elif isinstance(obj, (dict, list, tuple)):
            for v in (obj.values() if isinstance(obj, dict) else obj):
                freeze(v, depth + 1)
        elif type(obj).__module__.endswith(("mpc_qp", "mpc_active_set", "estimation",
                                            "mpc_envelope", "control_plant")):
            for v in vars(obj).values():
                freeze(v, depth + 1)

    for name in ("cp", "limits", "stroke_default", "omega", "env", "qp", "kalman",
                 "warm_up_damping"):
        freeze(getattr(setup, name))
