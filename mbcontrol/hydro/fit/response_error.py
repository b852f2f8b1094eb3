"""The error a radiation fit causes in the device's response: what decides the fit's order.

The kernel K(iω) = B(ω) + iω(A(ω) - A∞) (module radiation) sits inside the device's linear
impedance at rest, in its generalised coordinates s (velocity form, exp(+iωt) phasors):

    Z(ω) = iω M + B_m + K_s/(iω) + P K(iω) Pᵀ,

M the rigid-body mass with P A∞ Pᵀ (drivetrain inertia included), B_m and K_s the mechanical
damping and stiffness (friction slope, moorings; hydrostatics and gravity with their lever arms,
so an OSWEC's hinge gets its net positive stiffness, not the CoG hydrostatics' negative one), and
P (n_s, n_h) the generalised force of a hydro-DOF wrench (ν = Pᵀ s). The PTOs are free (their own
damping and stiffness zero): Z is what a PTO force works against, the impedance a controller is
designed on. All of it comes from the plant (:func:`mbcontrol.plant.device_around`).

A fit K + δK moves the velocity v = Z⁻¹ f under any generalised force f (waves, PTOs) by exactly
δv = -Z'⁻¹ δZ v, Z' = Z + δZ, δZ = P δK Pᵀ. The response error at ω is the largest relative change
over all forces, in the kinetic-energy norm |v|_M = |D v|, D = diag(√M_ii) (which makes it unitless):

    e(ω) = ‖D Z'⁻¹ P δK Pᵀ D⁻¹‖₂ · m(ω),    m(ω) = min(1, h(ω) / (MOVES · max_ω h)),

h(ω) = max over headings |D Z⁻¹ P F_d(ω)|, the device's motion per unit wave amplitude. So e is
the relative error of the response at each frequency where the device moves at least MOVES of its
most, and counts less where it barely moves: the band comes from the device's own modes. The
scene's [hydro] response_band, when set, limits it further. It is |Z⁻¹ Jᵀ δK J| of issue 37.

To first order the response moves by at most ‖D Z⁻¹ P S⁻¹‖ ‖S⁻¹ Pᵀ D⁻¹‖ m(ω) per unit error of
S K S (:meth:`ResponseGate.sensitivity`); the least-squares fits weigh each frequency by it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...waves import interpolate_complex
from .kernel import kernel_data, reciprocal

SIGNIFICANT = 6        # digits of the device's matrices in a fit's cache key
ROUND_OFF = 1e-9       # entries below this share of their array's largest are zeros in the key
MOVES = 0.1            # full weight where the device's wave motion is at least this share of its peak
LS_FLOOR = 0.02        # least-squares weight where the response is insensitive (of the largest):
                       # the fit stays sane there (impulse response, step sizes) without spending poles


@dataclass(frozen=True, eq=False)
class Device:
    """The linear device around the radiation kernel, at rest, PTOs free (module docstring).

    coordinates: names of s; dofs: the hydro DOFs (columns of P, the kernel's order); mass,
    damping, stiffness (n_s, n_s) in kg, N s/m, N/m (kg m², N m s, N m for angles); P (n_s, n_h);
    excitation (n_dir, n_omega, n_h) per unit wave amplitude as the data store it (exp(-iωt)), on
    omega (rad/s) and headings (rad); band: (lo, hi) rad/s where the error is judged (the scene's
    [hydro] response_band), None for the whole fit band."""
    coordinates: tuple
    dofs: tuple
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    P: np.ndarray
    excitation: np.ndarray
    omega: np.ndarray
    headings: np.ndarray
    band: tuple | None = None

    def key(self) -> list:
        """What a fit judged by this device depends on, rounded for a cache key: each array to
        SIGNIFICANT digits, entries below ROUND_OFF of its largest as 0 (round-off, e.g. a
        large-angle plant's stiffness at rest against a linear one's, must not make a new fit)."""
        def rounded(a):
            a = np.ravel(a)
            floor = ROUND_OFF * np.max(np.abs(a), initial=0.0)
            return [float(f"{x:.{SIGNIFICANT}g}") if abs(x) > floor else 0.0 for x in a]
        return [list(self.coordinates), list(self.dofs), rounded(self.mass), rounded(self.damping),
                rounded(self.stiffness), rounded(self.P), rounded(np.abs(self.excitation)),
                list(self.band) if self.band else None]

    def restricted(self, dofs) -> "Device":
        """The same device seen by a kernel on ``dofs`` (a subset of self.dofs, any order)."""
        idx = [list(self.dofs).index(d) for d in dofs]
        return Device(self.coordinates, tuple(dofs), self.mass, self.damping, self.stiffness,
                      self.P[:, idx], self.excitation[..., idx], self.omega, self.headings, self.band)

    def at(self, w, K) -> "ResponseGate":
        """The gate on frequencies w (rad/s) around kernel data K (nω, n_h, n_h) in self.dofs' order."""
        return ResponseGate(self, np.asarray(w, float), np.asarray(K, complex))


class ResponseGate:
    """Response errors of fits of K on one frequency grid (module docstring)."""

    def __init__(self, device: Device, w, K):
        self.device, self.w, self.K = device, w, K
        s = 1j * np.maximum(w, 1e-12)[:, None, None]
        P = device.P
        self.Z = s * device.mass + device.damping + device.stiffness / s + P @ K @ P.T
        self.d = np.sqrt(np.abs(np.diag(device.mass)))
        F = np.stack([interpolate_complex(device.omega, f, w) for f in device.excitation])  # (n_dir, nω, n_h)
        V = np.linalg.solve(self.Z, np.einsum("ij,dkj->kid", P, np.conj(F)))               # (nω, n_s, n_dir)
        h = np.linalg.norm(self.d[None, :, None] * V, axis=1).max(axis=1)
        lo, hi = device.band if device.band else (-np.inf, np.inf)
        judged = (w >= lo) & (w <= hi)
        peak = h[judged].max(initial=0.0)
        # no wave motion at all (no excitation in the data): every frequency counts in full
        self.weight = (np.minimum(1.0, h / (MOVES * peak)) if peak > 0 else np.ones(w.size)) * judged

    def _relative(self, fit, group):
        """D Z'⁻¹ δZ D⁻¹ (nω, n_s, n_s) for a fit (nω, m, m) of the entries ``group`` (None: all)."""
        g = np.arange(self.K.shape[1]) if group is None else np.asarray(group)
        Pg = self.device.P[:, g]
        dZ = Pg @ (fit - self.K[np.ix_(range(self.w.size), g, g)]) @ Pg.T
        return self.d[None, :, None] * np.linalg.solve(self.Z + dZ, dZ) / self.d[None, None, :]

    def errors(self, fit, group=None) -> np.ndarray:
        """The response error per frequency (nω,): e(ω) of the module docstring."""
        return np.linalg.norm(self._relative(fit, group), 2, axis=(1, 2)) * self.weight

    def worst(self, fit) -> dict:
        """Where the response error of a fit of the whole kernel is largest: ω, its weight, and the
        entry of D Z'⁻¹ δZ D⁻¹ that dominates it (the velocity that moves most, and under what force)."""
        e = self.errors(fit)
        k = int(np.argmax(e))
        E = np.abs(self._relative(fit, None)[k])
        i, j = np.unravel_index(int(np.argmax(E)), E.shape)
        c = self.device.coordinates
        return {"error": float(e[k]), "omega": float(self.w[k]), "weight": float(self.weight[k]),
                "what": f"velocity of {c[i]} under a force on {c[j]}"}

    def sensitivity(self, group, scale=None) -> np.ndarray:
        """Per frequency (nω,), how far a kernel error of unit 2-norm on ``group`` (in the units of
        S K S, S = diag(scale)) can move the response error, to first order."""
        P = self.device.P[:, group]
        if scale is not None:
            P = P / np.asarray(scale)[None, :]
        left = np.linalg.norm(self.d[None, :, None] * np.linalg.solve(self.Z, np.broadcast_to(P, (self.w.size,) + P.shape)),
                              2, axis=(1, 2))
        right = np.linalg.norm(P.T / self.d[None, :], 2)
        return left * right * self.weight

    def on(self, group) -> "GroupJudge":
        """The gate for a fit of one decoupled DOF group (indices into the device's dofs)."""
        return GroupJudge(self, [int(i) for i in group])


@dataclass(frozen=True)
class GroupJudge:
    """A ResponseGate seen by the fit of one DOF group: errors of its fit (the others exact)."""
    gate: ResponseGate
    group: list

    def __call__(self, fit) -> np.ndarray:
        return self.gate.errors(fit, self.group)

    def sensitivity(self, scale=None) -> np.ndarray:
        return self.gate.sensitivity(self.group, scale)


def response_error_on(device: Device, data, fit, omega_max=None) -> dict:
    """The response error of ``fit`` (a RadiationModel of ``data``) in ``device``, as
    fit_radiation judges it: on the data's frequencies up to omega_max (rad/s), K made reciprocal
    as the fit had it (kernel.reciprocal); the ResponseGate.worst dict (its "error" is the max)."""
    dofs = list(fit.dofs)
    w, K, _ = kernel_data(data, dofs, omega_max)
    return device.restricted(dofs).at(w, reciprocal(K)[0]).worst(fit.frequency_response(w))
