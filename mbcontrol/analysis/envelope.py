"""The operating envelope of linear hydrodynamics, predicted in the frequency domain.

`analysis.validity` marks a run INVALID when a surface-piercing body's significant heave
relative to the free surface exceeds its mean draft, or a body's significant roll or pitch
exceeds "validity.angle_max" (30 deg): beyond them linear hydrodynamics do not describe the
device. This module predicts those same quantities before a run, from the BEM data alone,
for any PTO force, so that tuners choose settings that stay inside (controllers.tuning) and
a sea where none can is known before it is simulated.

Linear theory, phasors exp(-i omega t) as analysis.ports (the bound stack's documented
exception to the public exp(+i omega t), `lti.phasor`): each envelope quantity q is
q = G U + H a per wave component, with U the PTO force, a the component's complex amplitude,
G and H from `ports.output_responses`. A relative heave is -(body heave, z down) minus the
surface elevation at the body's centre of buoyancy, e^{i k (x cos beta + y sin beta)} per unit
amplitude (the convention of mbcontrol.waves and of the excitation coefficients), as
validity.excursions measures it. Its statistic is the one the check uses: the significant
amplitude, 2 std over a sea's components (sqrt(sum |q_j|^2 / 2) per std), or a regular
wave's amplitude |q|. Limits are the check's own times "envelope.share": a tuned setting is
kept a margin inside, for what one finite record and the nonlinear plant add to the
spectral prediction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import defaults
from .validity import mean_draft

# ENVELOPE_SHARE, the default "envelope.share" (0.9): a tuned setting's predicted significant
# motion is kept within this share of the check's limit: a 200 s record's 2 std scatters by a
# few % about the spectral value (sphere, rm3: tests/analysis/test_envelope.py), and the
# nonlinear plant's motion differs by a few % more.


def peak_share() -> float:
    """The share of the check's limit a predictive controller bounds each quantity to at every
    sample, |q| <= L, not its statistic: half of "envelope.share" (read now). Whatever the
    motion, std(q) <= max |q|, so L = share / 2 of the limit keeps 2 std within the tuners'
    share; the bound is what an MPC does: it rides L like a square wave (sphere, Hs 2.64 m,
    Tp 12.58 s, L at 0.64 of the draft: 2 std = 1.64 L, 4 % past the draft)."""
    return defaults.get("envelope.share") / 2


@dataclass(frozen=True)
class EnvelopeItem:
    """One quantity of the envelope: what, where, and its limit (m or rad)."""
    name: str                  # e.g. "float relative heave", "flap pitch"
    output: str                # the plant output it is made of
    limit: float               # the validity check's limit (m or rad)
    source: str                # where the limit comes from
    point: tuple | None = None  # (x, y) of the surface subtracted (relative heave), else None

    @property
    def relative(self) -> bool:
        return self.point is not None


def envelope_items(plant) -> list[EnvelopeItem]:
    """The quantities validity.excursions checks, with their limits: per body with hydro
    data, its relative heave (surface-piercing bodies) and each of roll and pitch that is
    one of its hydro DOFs (a body without them cannot roll or pitch in the linear model)."""
    if plant.hydro is None or "body" not in plant.hydro.data.coords:
        return []
    data, dofs = plant.hydro.data, set(plant.hydro.dofs)
    items = []
    for body in map(str, data["body"].values):
        if f"{body}__Heave" not in plant.outputs:
            continue
        draft = mean_draft(data, body)
        if draft is not None:
            cob = data["center_of_buoyancy"].sel(body=body).values
            items.append(EnvelopeItem(f"{body} relative heave", f"{body}__Heave",
                                      defaults.get("validity.draft_factor") * draft,
                                      "mean draft V / A_wp",
                                      (float(cob[0]), float(cob[1]))))
        for angle in ("Roll", "Pitch"):
            if f"{body}__{angle}" in dofs:
                angle_max = defaults.get("validity.angle_max")
                items.append(EnvelopeItem(f"{body} {angle.lower()}", f"{body}__{angle}",
                                          angle_max, f"{math.degrees(angle_max):.0f} deg"))
    return items


@dataclass(frozen=True)
class EnvelopeResponse:
    """The envelope of one PTO in one wave: q = G U + H a per component (exp(-i omega t)).

    items: the EnvelopeItems; G (n_omega, n_items) per unit PTO force, H (n_omega,
    n_items) per unit complex wave amplitude (relative heave: the surface already
    subtracted); amplitude: the wave's complex amplitudes (n_omega); regular: one component.
    """
    items: tuple
    G: np.ndarray
    H: np.ndarray
    amplitude: np.ndarray
    regular: bool

    @property
    def limits(self) -> np.ndarray:
        return np.array([item.limit for item in self.items])

    def significant(self, force) -> np.ndarray:
        """The significant amplitude of every item (..., n_items; m or rad) under the PTO force
        phasors `force` (..., n_omega; N or N m, exp(-i omega t), per component at phase 0
        with its amplitude); 0 for the PTO held free."""
        U = np.asarray(force, complex)
        q = U[..., :, None] * self.G + (self.H * self.amplitude[:, None])
        if self.regular:
            return np.abs(q[..., 0, :])
        return 2 * np.sqrt(0.5 * np.sum(np.abs(q) ** 2, axis=-2))

    def ratio(self, force) -> np.ndarray:
        """The largest significant / limit over the items (...,); 0 with no items."""
        if not self.items:
            return np.zeros(np.shape(force)[:-1])
        return np.max(self.significant(force) / self.limits, axis=-1)

    def report(self, force) -> list[dict]:
        """Per item: name, significant, limit, source (JSON-ready)."""
        sig = self.significant(force)
        return [{"name": item.name, "significant": float(s), "limit": item.limit,
                 "share": float(s / item.limit), "source": item.source}
                for item, s in zip(self.items, sig)]


def envelope_response(plant, wave, pto: str, params=None) -> EnvelopeResponse:
    """The envelope of PTO `pto` in `wave` (see the module doc); params: overrides as
    ports.linear_params (every other PTO keeps its law from params)."""
    from ..waves import wavenumber
    from .ports import output_responses
    items = tuple(envelope_items(plant))
    omega = np.atleast_1d(np.asarray(wave.omega, float))
    # phases drop out of every statistic: each component is taken at phase 0
    amplitude = np.asarray(wave.amplitude, float) * np.ones(omega.size)
    if not items:
        empty = np.zeros((omega.size, 0), complex)
        return EnvelopeResponse(items, empty, empty, amplitude, omega.size == 1)
    G, H = output_responses(plant, omega, [pto], [item.output for item in items],
                            wave.direction, params)
    G, H = G[..., 0], H.copy()
    water = plant.scene.water
    k = (omega ** 2 / water.g if not math.isfinite(water.depth)
         else np.array([wavenumber(float(w), water.depth, water.g) for w in omega]))
    for j, item in enumerate(items):
        if item.relative:            # up = -heave (z down), minus the surface there
            x, y = item.point
            surface = np.exp(1j * k * (x * np.cos(wave.direction) + y * np.sin(wave.direction)))
            G[:, j], H[:, j] = -G[:, j], -H[:, j] - surface
    return EnvelopeResponse(items, G, H, amplitude, omega.size == 1)


def envelope_bound(plant, wave, pto: str, *, share: float | None = None,
                   params=None) -> dict:
    """The most PTO `pto` can absorb in `wave` (W, linear theory, the spectral mean) with every
    envelope quantity's predicted significant motion within `share` (default
    "envelope.share") of its limit: the
    complex-conjugate bound with the envelope as constraints. No force history, causal or
    not, that keeps the device inside absorbs more; a tuned law inside the same envelope
    reaches a share of it. A second-order cone programme in the force phasors U_j (cvxpy,
    Clarabel): maximise sum -1/2 Re(U_j conj(V_j)), V = Y U + H a (ports.port_responses), s.t.
    sqrt(sum |q_ij|^2) <= share limit_i / sqrt(2) (a sea's 2 std; a regular wave: |q_i| <=
    share limit_i). The other PTOs hold the laws `params` gives them (base: none). Returns
    {"bound_W", "unconstrained_W", "share", "binding": [names of the items at their limit]}.
    The PTO's force and stroke limits are not in it (so it bounds a law that also meets them).

    A component that excites the PTO where the hydro data give it no radiation damping
    (Re Y <= 0: BEM damping repaired to zero, as the sphere's above 11.5 rad/s, which a
    measured record's FFT reaches) makes the unconstrained bound infinite, as
    `ports.multiport_bound` (and so `mbcontrol simulate`) declares it: unconstrained_W is
    inf and "unbounded" states which components (`ports.undamped_note`). The envelope still
    caps the force there, so bound_W stays finite when the programme has an optimum (inf when
    no envelope item limits those components).
    """
    import cvxpy as cp

    from ..plant import controlled_params
    from .ports import port_responses, undamped_note
    share = defaults.resolve("envelope.share", share)
    base = controlled_params(plant, params, whole=[pto], linear=True)
    Y, H = port_responses(plant, wave.omega, [pto], wave.direction, base)
    y, h = Y[:, 0, 0], H[:, 0] * np.asarray(wave.amplitude, float)
    damped = y.real > 0
    per = np.where(damped, np.abs(h) ** 2 / (8 * np.where(damped, y.real, 1.0)),
                   np.where(h != 0, np.inf, 0.0))
    unconstrained = float(np.sum(per))
    out = {"unconstrained_W": unconstrained, "share": share, "binding": []}
    if not math.isfinite(unconstrained):
        out["unbounded"] = undamped_note(wave, ~damped & (h != 0), pto)
    env = envelope_response(plant, wave, pto, params=base)
    if not env.items:
        return {"bound_W": unconstrained, **out}
    U = cp.Variable(y.size, complex=True)
    # scaled: force by the optimum's RMS, power by the unconstrained bound (over the damped
    # components: the others have neither)
    rms = np.abs(h[damped] / (2 * y.real[damped]))
    f_scale = (float(np.sqrt(np.mean(rms ** 2))) if rms.size else 0.0) or 1.0
    p_scale = float(np.sum(per[damped])) or 1.0
    power = -0.5 * (cp.sum(cp.multiply(np.maximum(y.real, 0.0) * f_scale ** 2,
                                       cp.square(cp.abs(U))))
                    + cp.real(cp.sum(cp.multiply(np.conj(h) * f_scale, U))))
    radius = share * env.limits * (1.0 if env.regular else 1 / np.sqrt(2))
    cons = [cp.norm(cp.multiply(env.G[:, i] * f_scale, U) + env.H[:, i] * env.amplitude, 2)
            <= radius[i] for i in range(len(env.items))]
    problem = cp.Problem(cp.Maximize(power / p_scale), cons)
    problem.solve(solver=cp.CLARABEL)
    if problem.status in (cp.UNBOUNDED, cp.UNBOUNDED_INACCURATE):
        return {"bound_W": math.inf, **out, "status": problem.status}
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE):
        # infeasible: the free wave alone takes the device outside (relative heave of a
        # body held still is the sea itself): no force keeps it inside
        return {"bound_W": None, **out, "status": problem.status}
    force = np.asarray(U.value) * f_scale
    sig = env.significant(force)
    out["binding"] = [item.name for item, s, r in zip(env.items, sig, share * env.limits)
                      if s >= 0.999 * r]
    return {"bound_W": float(problem.value * p_scale), **out}
