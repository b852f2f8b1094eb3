"""The linear model's envelope (mbcontrol.analysis.envelope) as the MPC's soft constraints.

Each quantity the physics checks measure (a surface-piercing body's heave relative to the
surface, roll and pitch) becomes a row of the control plant's state, scaled by its peak
limit analysis.peak_share() x the check's limit: an MPC bounds every sample, not a statistic,
and std <= max |q| whatever the motion, so 2 std stays within "envelope.share" of it. A
relative heave needs the surface at the body: a probe measures it each period (the wave seen
at the body's centre of buoyancy, now: causal) and it is forecast as the excitation is (an
AR model of the probe's samples), or taken from the wave with the oracle forecast "known".
Without a wave nothing measures the surface, and relative heaves are left out.
The envelope is part of the MPC's setup (fixed once built); a run's surface predictor is its
own (made from `surface_config`, passed to `measure` and `offset`).
"""
from __future__ import annotations

import numpy as np

from .estimation import ArConfig, ArPredictor


class MpcEnvelope:
    """The envelope rows of one MPC, part of its setup.

    items: analysis.envelope.EnvelopeItems kept; limits: their peak limits (m or rad);
    probes: (wave seen at the body, item index) per relative heave."""

    def __init__(self, plant, wave, *, on: bool, forecast: str, dt: float):
        from mbcontrol.analysis import envelope_items, peak_share
        from mbcontrol.analysis import wave_at
        self.items, self.probes = [], []
        if on and plant.hydro is not None:
            self.items = [i for i in envelope_items(plant) if not i.relative or wave is not None]
            self.probes = [(wave_at(plant, wave, *i.point), k)
                           for k, i in enumerate(self.items) if i.relative]
        self.limits = peak_share() * np.array([i.limit for i in self.items])
        self.forecast, self.dt = forecast, dt

    def surface_config(self, ar: ArConfig | None) -> ArConfig | None:
        """The probes' surface predictor: as `ar` forecasts the excitation (its order and
        warm-up), or none (None) without the AR forecast or probes."""
        return (ArConfig(len(self.probes), self.dt, order=ar.order, min_samples=ar.first_fit)
                if ar is not None and self.probes else None)

    @property
    def outputs(self) -> list[str]:
        """The plant outputs the control plant must predict (rows Ce)."""
        return [i.output for i in self.items]

    def rows(self, cp):
        """(ne, nz): each quantity as a row of the control plant's state over its peak limit
        (relative heave: up = -heave; the surface comes in `offset`), or None."""
        if not self.items:
            return None
        sign = np.array([-1.0 if i.relative else 1.0 for i in self.items])
        return (sign / self.limits)[:, None] * cp.Ce

    def measure(self, t: float, surface_ar: ArPredictor | None) -> None:
        """A probe sample of the surface at each body, now, into the run's predictor."""
        if surface_ar is not None:
            surface_ar.append([probe.elevation(np.array([t]))[0] for probe, _ in self.probes])

    def offset(self, t: float, n: int, surface_ar: ArPredictor | None):
        """(n, ne): minus the surface forecast at the ends of the next n periods over each
        relative heave's peak limit (0 for angles; surface_ar: the run's predictor); None
        without probes."""
        if not self.probes:
            return None
        eta = np.zeros((n, len(self.probes)))
        if self.forecast == "known":           # the oracle sees the future surface too
            times = t + self.dt * np.arange(1, n + 1)
            eta = np.column_stack([probe.elevation(times) for probe, _ in self.probes])
        elif surface_ar is not None:
            predicted = surface_ar.forecast(n, midpoints=False)
            eta = predicted if predicted is not None else eta
        out = np.zeros((n, len(self.items)))
        for j, (_, k) in enumerate(self.probes):
            out[:, k] = -eta[:, j] / self.limits[k]
        return out

    def report(self) -> dict:
        """describe()'s view."""
        return {"quantities": [{"name": i.name, "limit": i.limit, "peak_limit": float(L),
                                "source": i.source,
                                "surface": "probed at the body, forecast like the excitation"
                                if i.relative else None}
                               for i, L in zip(self.items, self.limits)],
                "why": "the range where the linear model holds (analysis.envelope): soft "
                       "constraints at every step of the horizon"}
