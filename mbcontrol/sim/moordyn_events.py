"""What happens to a run's MoorDyn lines: breaking loads reached and sea-bed contact, with
time and line.

- **Breaking load.** With `[[mooring]] breaking_load` (N), the first time a line's tension at
  an end reaches it is reported (time, end, tension), once per line; checked every step on the
  tensions the run records. The line does not break in the run: MoorDyn 2.7's own BreakLine,
  called between steps, diverges within a few steps of the release (NaN node positions 0.04 s
  after it, for a single 37 m chain freed at its upper end), so the run goes on with the
  intact system and says so. What follows that time is not the damaged mooring's response.
- **Sea-bed contact.** A line clear of the bed at the start (its lowest node more than
  BED_MARGIN_M above it: a buoy's line, an upper line, a tether) that reaches it is reported,
  first time only; checked every BED_EVERY_STEPS steps (a line's fall lasts longer). Lines that
  lie on the bed at rest (the lower chains) are not reported: touching it is their design.

Slack (tension below a share of its mean) is read from the recorded tensions afterwards
(analysis.mooring_stats). Record: {mooring: {"line<k>": {"breaking_load_at_s", "end",
"tension_N"} and/or {"bed_contact_at_s"}}}, the run's attrs["moordyn_events"].
"""
from __future__ import annotations

import warnings

import numpy as np

BED_MARGIN_M = 0.5
BED_EVERY_STEPS = 10


class LineEvents:
    """Breaking loads reached and bed contact of a MooredRun's lines (module docs)."""

    def __init__(self, plant, moored):
        self.record = {}
        loads = {m.name: m.breaking_load for m in plant.scene.moorings}
        # one limit per recorded tension (moored.names: anchor then fairlead ends of each
        # line, mooring by mooring); inf where no breaking load is given
        self.limits = np.concatenate([np.full(2 * len(s.lines), loads[s.name] or np.inf)
                                      for s in moored.systems])
        self.watch = self.limits < np.inf
        self.breaking_left = bool(self.watch.any())
        self.ends = [(s, j, end, first) for first, s in _offsets(moored.systems)
                     for end in ("anchor", "fairlead") for j in range(len(s.lines))]
        self.clear = [(s, j) for s in moored.systems for j in range(len(s.lines))
                      if s.bed_clearance(j) > BED_MARGIN_M]

    @property
    def watching(self) -> bool:
        """Is anything left to check (a breaking load not yet reached, a line still clear)?"""
        return self.breaking_left or bool(self.clear)

    def after_step(self, i: int, t: float, tensions: np.ndarray) -> None:
        """Check step i, which ended at t (s), with the ends' tensions (N) then."""
        if self.watch.any():
            over = np.flatnonzero(self.watch & (tensions >= self.limits))
            for k in over[np.argsort(-(tensions[over] / self.limits[over]))]:
                if self.watch[k]:                # both ends at once: the more loaded one
                    self._reached(k, t, float(tensions[k]))
        if i % BED_EVERY_STEPS == 0 and self.clear:
            for system, j in [c for c in self.clear if c[0].bed_clearance(c[1]) <= 0.0]:
                self._line(system, j)["bed_contact_at_s"] = t
                self.clear.remove((system, j))

    def _reached(self, k: int, t: float, tension: float) -> None:
        system, j, end, first = self.ends[k]
        n = len(system.lines)
        self.watch[first + j] = self.watch[first + n + j] = False      # once per line
        self.breaking_left = bool(self.watch.any())
        self._line(system, j).update(breaking_load_at_s=t, end=end, tension_N=tension)
        warnings.warn(f"mooring '{system.name}': line {system.data.lines[j].id} reached its "
                      f"breaking load {self.limits[k]:.4g} N at its {end} at t = {t:.4g} s "
                      f"(tension {tension:.4g} N); the run goes on with the line intact "
                      f"(MoorDyn's BreakLine diverges), so what follows is not the damaged "
                      f"mooring's response", RuntimeWarning, stacklevel=3)

    def _line(self, system, j: int) -> dict:
        return self.record.setdefault(system.name, {}).setdefault(
            f"line{system.data.lines[j].id}", {})


def _offsets(systems):
    """(index of the system's first recorded tension, system)."""
    first = 0
    for s in systems:
        yield first, s
        first += 2 * len(s.lines)
