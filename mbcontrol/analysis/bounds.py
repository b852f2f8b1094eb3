"""Theoretical limits of absorbed power: complex-conjugate and constrained pseudo-spectral bounds.

Everything here is linear theory on the frequency-domain (FD) model built straight from the
BEM data (the physics of `analysis.frequency_domain_response`, no radiation fit, Coulomb
friction removed), seen from one PTO as a Thevenin equivalent.

Convention: phasors of exp(-i omega t) as stored (hydro data, `mbcontrol.waves`), the bound
stack's documented exception to the public exp(+i omega t) (`lti.phasor`). A wave component
(omega, a, phi) has the complex elevation a exp(-i phi). Seen from the PTO (its own damping and
stiffness set to zero, so the PTO force F is the whole force it applies to its follower),

    V = (F_e A + F) / Z_i,        X = V / (-i omega) = i V / omega,

with V, X the PTO velocity and position (`<pto>__velocity`, `<pto>__position`), A the complex
wave amplitude, F_e the equivalent excitation per unit amplitude and Z_i the intrinsic
impedance. F is positive along the PTO's coordinate (as the scene's PTO force
-(damping v + stiffness x) + u on its follower; for a heave PTO to ground, NED, downwards), so
in still water V = F / Z_i, and Re Z_i >= 0 says a force does non-negative work on the device:
1/2 Re[F conj(V)] = 1/2 |F|^2 Re Z_i / |Z_i|^2. In this convention a heaving body has Z_i = B - i[omega (m + A) - K / omega], the
complex conjugate of the textbook (exp(+i omega t)) form; Re Z_i >= 0 for a passive device.
Mean absorbed power (W, positive when absorbed) is P = -1/2 Re[F conj(V)] per component; its
maximum over F is |F_e A|^2 / (8 Re Z_i), reached at V = F_e A / (2 Re Z_i), i.e.
F = -F_e A conj(Z_i) / (2 Re Z_i) (complex-conjugate control).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import InputError, MbcontrolError, UnknownName
from ..waves import repeat_period
from .dense import OVERSAMPLE, dense_extremes

# Re Z_i may be a tiny negative number where the radiation damping all but vanishes: BEM
# damping matrices carry noise of that size (rm3's WAMIT data have eigenvalues down to -0.1
# N s/m below 0.2 rad/s, where |Z_i| ~ 1e6-1e7 N s/m: Re Z_i / |Z_i| down to -2.4e-8).
# Anything below -PASSIVITY_TOL |Z_i| is a real defect of the data or the model
PASSIVITY_TOL = 1e-6


class NotPassiveError(MbcontrolError, ValueError):
    """The PTO's intrinsic impedance has Re Z_i < 0: the device would create energy."""


class UnboundedError(MbcontrolError, ValueError):
    """A wave excites the PTO where Re Z_i = 0 (no radiation damping): an infinite bound."""


@dataclass(frozen=True)
class Thevenin:
    """One PTO's Thevenin equivalent on a frequency grid, exp(-i omega t) phasors.

    impedance: Z_i (N s/m, or N m s/rad for a rotary PTO); excitation: F_e per unit wave
    amplitude (N/m, or N m/m). V = (F_e A + F) / Z_i.
    """
    pto: str
    omega: np.ndarray           # rad/s
    impedance: np.ndarray       # complex, N s/m or N m s/rad
    excitation: np.ndarray      # complex, N/m or N m/m
    force_unit: str
    velocity_unit: str


def _pto_name(plant, pto: str | None) -> str:
    names = [p.name for p in plant.scene.ptos]
    if not names:
        raise InputError(f"{plant.name}: the scene has no PTO")
    if pto is None:
        return names[0]
    if pto not in names:
        raise UnknownName(f"{plant.name}: no PTO {pto!r}; PTOs are {', '.join(names)}")
    return pto


def pto_thevenin(plant, omega, pto: str | None = None, direction: float = 0.0,
                 params=None, *, check_passive: bool = True) -> Thevenin:
    """Intrinsic impedance Z_i and equivalent excitation F_e of one PTO (default: the first).

    The full FD system [-omega^2 (M + A) - i omega (B + B_mech) + K] X = P F_exc + b F (the
    exp(-i omega t) form of analysis.frequency_domain_response) is solved twice per
    frequency: for a unit PTO force (velocity H_u) and for a unit wave (velocity H_w, PTO
    force zero). Then Z_i = 1 / H_u and F_e = H_w / H_u, so V = (F_e A + F) / Z_i.
    omega: rad/s, inside the hydro data's band. params: overrides (dict) of the plant's
    parameters for the other PTOs, mooring, friction. Raises NotPassiveError if Re Z_i < 0.
    """
    from .ports import port_responses

    name = _pto_name(plant, pto)
    omega = np.atleast_1d(np.asarray(omega, float))
    Y, H = port_responses(plant, omega, [name], direction, params)
    H_u, H_w = Y[:, 0, 0], H[:, 0]
    Z_i = 1.0 / H_u
    if check_passive:
        bad = Z_i.real < -PASSIVITY_TOL * np.abs(Z_i)
        if np.any(bad):
            worst = int(np.argmin(Z_i.real / np.abs(Z_i)))
            raise NotPassiveError(
                f"{plant.name}: PTO {name!r} sees a non-passive intrinsic impedance, Re Z_i < 0 "
                f"at {int(bad.sum())} of {omega.size} frequencies "
                f"({omega[bad].min():.4g}..{omega[bad].max():.4g} rad/s; worst Re Z_i = "
                f"{Z_i.real[worst]:.4g} at {omega[worst]:.4g} rad/s). Check the radiation "
                f"damping (negative values) and negative mechanical damping in the scene")
    return Thevenin(name, omega, Z_i, H_w / H_u, plant.units(f"{name}__force"),
                    plant.units(f"{name}__velocity"))


@dataclass(frozen=True)
class ConjugateBound:
    """Complex-conjugate (unconstrained) optimum, per wave component (exp(-i omega t)).

    power: mean absorbed power (W); power_by_component (W); force, velocity, position: the
    optimal complex amplitudes (N or N m; m/s or rad/s; m or rad) per component.
    """
    power: float
    power_by_component: np.ndarray
    thevenin: Thevenin
    force: np.ndarray
    velocity: np.ndarray
    position: np.ndarray


def _wave_phasors(wave) -> np.ndarray:
    """Complex elevation amplitudes a exp(-i phi) (m) of the wave's components."""
    return np.asarray(wave.amplitude, float) * np.exp(-1j * np.asarray(wave.phase, float))


def complex_conjugate_bound(plant, wave, pto: str | None = None, params=None) -> ConjugateBound:
    """Optimal unconstrained mean power sum_k a_k^2 |F_e(omega_k)|^2 / (8 Re Z_i(omega_k)) (W).

    For a regular wave or an irregular sea (components add: power is mean over the repeat
    period, cross terms between distinct frequencies average out). Linear theory, no force or
    stroke limit: the optimal velocity V = F_e A / (2 Re Z_i) is in phase with the equivalent
    excitation. Raises UnboundedError, naming the components, where Re Z_i = 0 (the bound is
    infinite there: `ports.multiport_bound` says inf, `mbcontrol simulate` "unbounded").
    """
    from .ports import undamped_note
    th = pto_thevenin(plant, wave.omega, pto, wave.direction, params)
    R = th.impedance.real
    E = th.excitation * _wave_phasors(wave)
    if np.any(R <= 0):             # as ports.multiport_bound (simulate's check): inf
        raise UnboundedError(f"{plant.name}: {undamped_note(wave, R <= 0, th.pto)}")
    velocity = E / (2 * R)
    force = -E * np.conj(th.impedance) / (2 * R)
    per = np.abs(E) ** 2 / (8 * R)
    return ConjugateBound(float(per.sum()), per, th, force, velocity,
                          velocity / (-1j * th.omega))


@dataclass(frozen=True)
class PseudoSpectralBound:
    """Optimal constrained periodic PTO force (non-causal) and what it absorbs.

    mean_power: W (nan unless the solver found an optimum); time: collocation grid over one
    repeat period (s); force, velocity, position: time series on it (N or N m, m/s or rad/s,
    m or rad); max_force, max_position: their largest absolute values on the grid;
    omega, force_coefficients: the force's complex amplitudes (exp(-i omega t));
    unconstrained_power: the complex-conjugate bound (W); solve_time: wall time of the
    cvxpy solve, canonicalisation included (s); solver_time: the solver's own (s);
    certified_power: an upper bound on the QP's optimum from its dual (W; solver "IPM" only,
    else nan): what no force on the grid can beat, whatever the solver's accuracy;
    max_force_dense, max_position_dense, force_overshoot_pct, position_overshoot_pct: the
    same force between the points, on a 16x finer grid (analysis.dense; % over the limit).
    """
    mean_power: float
    unconstrained_power: float
    time: np.ndarray
    force: np.ndarray
    velocity: np.ndarray
    position: np.ndarray
    max_force: float
    max_position: float
    omega: np.ndarray
    force_coefficients: np.ndarray
    status: str
    solve_time: float
    solver_time: float | None
    period: float
    certified_power: float = math.nan
    max_force_dense: float = math.nan
    max_position_dense: float = math.nan
    force_overshoot_pct: float = math.nan
    position_overshoot_pct: float = math.nan


class PseudoSpectralProblem:
    """The convex QP of the pseudo-spectral bound, built once for a plant, sea and PTO.

    Decision variables: cos and sin coefficients (c_k, s_k) of the PTO force on the force's
    frequency grid, F(t) = sum_k c_k cos(w_k t) + s_k sin(w_k t), i.e. phasors F_k = c_k + i s_k.
    With G_k = 1 / conj(Z_i) the mean power is
        P = -1/2 sum_k [Re G_k |F_k|^2 + Re(G_k conj(E_k) F_k)],   E_k = F_e(w_k) A_k,
    concave because Re G_k = Re Z_i / |Z_i|^2 >= 0. Limits hold at n_t collocation times
    t_j = j T / n_t over one repeat period T, with n_t = max(ceil(oversample (2 k_max + 1)),
    min_points): 2 k_max + 1 samples fix a trigonometric polynomial of degree k_max, and the
    floor keeps a single sinusoid's overshoot between points below 1/cos(pi/32) - 1 = 0.5 %.
    Between the points the force still bulges (reported by solve, see analysis.dense, whose
    OVERSAMPLE default puts the figure within 0.2 % of its dense-grid limit, from above).
    harmonics (regular waves only): the force may also hold 2..harmonics times the wave
    frequency (no excitation there), which can raise the constrained bound (a flatter force).
    omega_max (rad/s): the force may hold every multiple of 2 pi / T from the hydro data's
    lowest frequency up to omega_max, as any T-periodic force does (a saturating force's
    harmonics and the gaps between a sea's components): only then is the figure a bound on
    every controller whose force stays in that band.
    """

    def __init__(self, plant, wave, *, pto: str | None = None, params=None,
                 oversample: float = OVERSAMPLE, harmonics: int = 1, min_points: int = 32,
                 omega_max: float | None = None, force_on: str | None = None):
        T, k_wave = repeat_period(wave)
        if harmonics > 1 and wave.omega.size != 1:
            raise InputError("harmonics > 1 needs a regular wave")
        self.period = T
        cc = complex_conjugate_bound(plant, wave, pto, params)
        self.conjugate = cc
        k = np.arange(1, harmonics + 1) if harmonics > 1 else k_wave
        if omega_max is not None:
            lowest = math.ceil(float(plant.hydro.omega[0]) * T / (2 * np.pi) * (1 - 1e-9))
            k = np.union1d(k, np.arange(max(lowest, 1),
                                        math.floor(omega_max * T / (2 * np.pi) * (1 + 1e-9)) + 1))
        self.omega = 2 * np.pi * k / T
        th = cc.thevenin if k.size == k_wave.size else pto_thevenin(
            plant, self.omega, pto, wave.mean_direction, params)  # its excitation: cc's below
        E = np.zeros(k.size, complex)
        E[np.searchsorted(k, k_wave)] = cc.thevenin.excitation * _wave_phasors(wave)
        Z = th.impedance
        self.thevenin, self.E = th, E
        n_t = max(math.ceil(oversample * (2 * int(k.max()) + 1)), int(min_points))
        self.time = np.arange(n_t) * T / n_t
        basis = np.exp(-1j * np.outer(self.time, self.omega))           # (n_t, n_k)

        def affine(alpha, beta):
            """Time series of Re sum (alpha + beta F_k) e^{-i w t}: constant and (c, s) map."""
            eb = basis * beta[None, :]
            return (basis @ alpha).real, np.hstack([eb.real, -eb.imag])

        # the limited force: the machine's, or (Pto.limited_force "hull") the force the
        # drivetrain puts on the hull, F - Z_d V, V = (E + F) / Z, Z_d its reflected impedance
        # gear^2 (J s + b + K / s) at s = -i omega (this module's exp(-i omega t))
        owner = next(p for p in plant.scene.ptos if p.name == _pto_name(plant, pto))
        self.force_on = owner.limited_force(force_on)
        alpha, self.force_gain = np.zeros(k.size), np.ones(k.size, complex)
        if self.force_on == "hull":
            z_d = owner.drivetrain.reflected_impedance(-1j * self.omega)
            alpha, self.force_gain = -z_d * E / Z, 1 - z_d / Z
        self.force_offset = alpha        # the limited force's phasors: alpha + force_gain F_k
        self.force_map = affine(alpha, self.force_gain)
        self.velocity_map = affine(E / Z, 1 / Z)
        gain = 1j / (self.omega * Z)                                     # X = i V / omega
        self.position_map = affine(gain * E, gain)
        G = 1 / np.conj(Z)
        gamma = G * np.conj(E)
        # Re G < 0 only as BEM noise (PASSIVITY_TOL): as ~zero (1e-12 of the largest, so the
        # QP stays convex and its dual finite; it lowers the figure by ~1e-12 of it)
        rho = np.concatenate([G.real, G.real])
        self.rho = np.maximum(rho, 1e-12 * rho.max())                    # 1/(N s/m) each
        self.linear = np.concatenate([gamma.real, -gamma.imag])          # m/s per N
        # scaling: forces in units of the largest conjugate-optimal component, power in units
        # of the conjugate bound, so the interior-point solver sees numbers of order one
        self.F0 = float(np.max(np.abs(cc.force))) or 1.0
        self.P0 = cc.power if cc.power > 0 else 1.0
        self._problems: dict = {}

    def _build(self, has_force: bool, has_stroke: bool):
        import cvxpy as cp
        from scipy import sparse
        z = cp.Variable(self.rho.size)            # (c, s) in units of F0
        quadratic = sparse.diags(0.5 * self.rho * self.F0**2 / self.P0)
        objective = cp.Maximize(-cp.quad_form(z, quadratic)
                                - (0.5 * self.F0 / self.P0 * self.linear) @ z)
        limits, constraints = {}, []
        # the time series are auxiliary variables tied to z by one dense equality each, so the
        # dense block appears once, not in both rows of |y| <= limit (Clarabel: 1.6x faster on
        # a 278-component sea); the dense block is what the solve time grows with
        if has_force:
            limits["force"] = cp.Parameter(nonneg=True)
            f = cp.Variable(self.time.size)
            constraints += [f == self.force_map[1] @ z + self.force_map[0] / self.F0,
                            f <= limits["force"], -f <= limits["force"]]
        if has_stroke:
            limits["stroke"] = cp.Parameter(nonneg=True)
            x = cp.Variable(self.time.size)
            x0, A = self.position_map
            constraints += [x == self.F0 * A @ z + x0, x <= limits["stroke"],
                            -x <= limits["stroke"]]
        return cp.Problem(objective, constraints), z, limits

    def solve(self, force_max: float = np.inf, stroke_max: float = np.inf,
              solver: str = "CLARABEL", **solver_options) -> PseudoSpectralBound:
        """Solve for limits |F| <= force_max (N or N m) and |x| <= stroke_max (m or rad).

        solver: a cvxpy solver name, or "IPM" (analysis.box_qp: dense, fast on wide grids,
        and with a certified upper bound, PseudoSpectralBound.certified_power)."""
        if force_max <= 0 or stroke_max <= 0:
            raise InputError(f"limits must be > 0, got force_max={force_max}, "
                             f"stroke_max={stroke_max}")
        key = (bool(np.isfinite(force_max)), bool(np.isfinite(stroke_max)))
        if solver == "IPM":              # box_qp needs a box; without one cvxpy's default
            if any(key):
                return self._solve_ipm(force_max, stroke_max, **solver_options)
            solver, solver_options = "CLARABEL", {}
        if key not in self._problems:
            self._problems[key] = self._build(*key)
        problem, z, limits = self._problems[key]
        if key[0]:
            limits["force"].value = force_max / self.F0
        if key[1]:
            limits["stroke"].value = stroke_max
        start = time.perf_counter()
        problem.solve(solver=solver, **solver_options)
        wall = time.perf_counter() - start
        ok = problem.status in ("optimal", "optimal_inaccurate")
        # no optimum (e.g. infeasible: the force limit cannot hold the stroke): nan throughout
        coeffs = (np.asarray(z.value) * self.F0 if ok and z.value is not None
                  else np.full(self.rho.size, math.nan))
        stats = problem.solver_stats
        return self._result(coeffs, problem.status, wall, getattr(stats, "solve_time", None),
                            (force_max, stroke_max))

    def _result(self, coeffs, status, wall, solver_time, limits, certified=math.nan):
        half = coeffs.size // 2
        F_k = coeffs[:half] + 1j * coeffs[half:]
        V_k = (self.E + F_k) / self.thevenin.impedance
        # the power from the coefficients, not the solver's scaled objective value
        power = float(-0.5 * np.sum((F_k * np.conj(V_k)).real))
        series = [m[0] + m[1] @ coeffs for m in (self.force_map, self.velocity_map,
                                                 self.position_map)]
        return PseudoSpectralBound(
            power, self.conjugate.power, self.time, *series,
            float(np.max(np.abs(series[0]))), float(np.max(np.abs(series[2]))),
            self.omega, F_k, status, wall, solver_time, self.period, certified,
            **dense_extremes(self, F_k, *limits))

    def _solve_ipm(self, force_max, stroke_max, **options):
        from .box_qp import fourier_gram, solve_box_qp
        rows, offsets, limits, grams = [], [], [], []   # z in units of F0, power of P0
        n_t, k = self.time.size, np.rint(self.omega * self.period / (2 * np.pi)).astype(int)
        if np.isfinite(force_max):
            rows.append(self.force_map[1])
            offsets.append(self.force_map[0] / self.F0)
            limits.append(np.full(n_t, force_max / self.F0))
            grams.append(fourier_gram(k, self.force_gain, n_t))
        if np.isfinite(stroke_max):
            rows.append(self.F0 * self.position_map[1])
            offsets.append(self.position_map[0])
            limits.append(np.full(n_t, stroke_max))
            grams.append(fourier_gram(k, self.F0 * 1j / (self.omega * self.thevenin.impedance),
                                      n_t))
        d, lim = np.concatenate(offsets), np.concatenate(limits)

        def gram(w):
            return sum(g(w[i * n_t:(i + 1) * n_t]) for i, g in enumerate(grams))
        start = time.perf_counter()
        r = solve_box_qp(self.rho * self.F0**2 / self.P0, 0.5 * self.F0 / self.P0 * self.linear,
                         np.vstack(rows), d, -lim, lim, gram=gram, **options)
        wall = time.perf_counter() - start
        ok = r.status == "optimal"
        coeffs = r.z * self.F0 if ok else np.full(self.rho.size, math.nan)
        return self._result(coeffs, r.status, wall, wall, (force_max, stroke_max),
                            -r.dual_bound * self.P0 if ok else math.nan)

    def series(self, result: PseudoSpectralBound, t) -> dict:
        """Force, velocity and position (as in the result) at any times t (s), e.g. finer."""
        basis = np.exp(-1j * np.outer(np.asarray(t, float), self.omega))
        F = result.force_coefficients
        V = (self.E + F) / self.thevenin.impedance
        X = V * 1j / self.omega
        return {name: (basis @ Y).real for name, Y in
                (("force", F), ("velocity", V), ("position", X))}


def pseudo_spectral_bound(plant, wave, *, pto: str | None = None, force_max: float = np.inf,
                          stroke_max: float = np.inf, params=None, oversample=OVERSAMPLE,
                          harmonics: int = 1, min_points: int = 32, solver: str = "CLARABEL",
                          omega_max: float | None = None, force_on: str | None = None,
                          **solver_options) -> PseudoSpectralBound:
    """Optimal constrained mean absorbed power (W) for a periodic sea, non-causal.

    Optimises the PTO force's Fourier coefficients, by default on the wave's own frequency
    grid (as WecOptTool does; no bound on a saturating controller, whose force fills the gaps
    and the harmonics: give omega_max, rad/s, for every multiple of 2 pi / T up to it), with
    |F(t_j)| <= force_max (N or N m) and |x(t_j)| <= stroke_max (m or rad) at collocation
    times over one repeat period; a convex QP solved by cvxpy (default Clarabel;
    solver_options go to it, e.g. max_threads=1) or by analysis.box_qp (solver="IPM"). With
    no limits it equals complex_conjugate_bound. The wave's ramp is ignored (steady periodic
    state). oversample, min_points, harmonics: see PseudoSpectralProblem. Limits may be
    exceeded between collocation points (which only raises the figure): the result states
    by how much (max_force_dense, force_overshoot_pct...; 1.3 % in a 300 s sea at the default).
    Clarabel's time grows like n_points x n_components^2: 0.02 s for a regular wave, about
    0.6 s for 75 components, 12-25 s for 278 (a 600 s sea); "IPM" like n_points x n^2 with a
    BLAS constant (300 s sea to 12 rad/s, 573 components: see analysis.box_qp).
    For several limits on one sea, build one PseudoSpectralProblem and call solve repeatedly.
    force_on: the force force_max limits (scene Pto.limited_force; None: its force_max_on).
    """
    problem = PseudoSpectralProblem(plant, wave, pto=pto, params=params, oversample=oversample,
                                    harmonics=harmonics, min_points=min_points,
                                    omega_max=omega_max, force_on=force_on)
    return problem.solve(force_max, stroke_max, solver, **solver_options)
