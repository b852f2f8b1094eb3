"""MoorDyn input files: read, check, and write the copy a run gives MoorDyn.

A `[[mooring]] type = "moordyn"` names a MoorDyn input file (MoorDyn v2, or v1 as WEC-Sim's
examples are: converted on reading). The file is data: every value is checked as it is read
(numbers are numbers, names are plain words, points and line types that lines refer to
exist), and the copy MoorDyn runs (`run_text`) is written anew from those values, never by
pasting the user's text, so nothing in the file reaches MoorDyn but a checked table.

Supported: line types, points (Fixed, Free, Coupled; v1's Fix, Connect, Vessel) and lines
between points, and the options section. Bodies, rods and failures are refused by name: couple
points to the scene's body instead.

Frames: MoorDyn's global frame is z-up with its origin on the still-water level; the scene's
n-frame is NED (z down). A point (x, y, z) in one is (x, -y, -z) in the other (`TO_MOORDYN`).
Coupled points follow a scene body; their coordinates in the file are in that body's frame
(MoorDyn's axes, origin at the body's CoG at rest) unless the scene says `coupled = "global"`.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SceneError

TO_MOORDYN = np.array([1.0, -1.0, -1.0])   # n-frame (NED) <-> MoorDyn (z-up), per axis
_WORD = re.compile(r"^[A-Za-z0-9_.+-]{1,64}$")
_KINDS = {"fixed": "fixed", "fix": "fixed", "anchor": "fixed", "coupled": "coupled",
          "vessel": "coupled", "cpld": "coupled", "free": "free", "connect": "free",
          "point": "free", "con": "free"}
# options MoorDyn reads as numbers (lower case); others pass as words (tScheme)
_WORD_OPTIONS = {"tscheme"}
_TYPE_COLUMNS = ("diameter (m)", "mass per metre (kg/m)", "EA (N)", "BA/-zeta", "EI (N m^2)", "Cd",
                 "Ca", "CdAx", "CaAx")
_OURS = {"writelog", "disableoutput", "disableouttime", "dtout", "fileic", "icfile",
         "seafloorfile"}       # set by the run, or files we do not pass on


@dataclass(frozen=True)
class LineType:
    name: str
    values: tuple[str, ...]     # Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx (v2 order)

    @property
    def diameter(self) -> float:
        return float(self.values[0])

    @property
    def mass_per_length(self) -> float:
        return float(self.values[1])

    @property
    def EA(self) -> float:
        return float(self.values[2])


@dataclass(frozen=True)
class Point:
    id: int
    kind: str                   # "fixed" | "free" | "coupled"
    position: tuple[float, float, float]    # m, as in the file (MoorDyn axes)
    mass: float = 0.0           # kg (clump weight)
    volume: float = 0.0         # m^3 (float)
    cda: float = 0.0            # m^2
    ca: float = 0.0


@dataclass(frozen=True)
class Line:
    id: int
    type: str
    attach_a: int               # point ID at end A (MoorDyn: the anchor end)
    attach_b: int               # point ID at end B (the fairlead end)
    length: float               # m, unstretched
    segments: int
    row: int = field(default=0, compare=False)    # its line in the file, for messages


@dataclass(frozen=True)
class MoorDynInput:
    """A checked MoorDyn input file."""
    path: str
    version: int                            # 1 or 2, as read
    line_types: tuple[LineType, ...]
    points: tuple[Point, ...]
    lines: tuple[Line, ...]
    options: dict = field(default_factory=dict)   # lower-case name -> value (str)

    def point(self, point_id: int) -> Point:
        return next(p for p in self.points if p.id == point_id)

    @property
    def coupled(self) -> tuple[Point, ...]:
        return tuple(p for p in self.points if p.kind == "coupled")

    def option(self, name: str, default: float | None = None) -> float | None:
        value = self.options.get(name.lower())
        return default if value is None else float(value)

    def end_kind(self, line: Line, end: str) -> str:
        return self.point(line.attach_a if end == "A" else line.attach_b).kind


def _section(header: str) -> str | None:
    text = header.upper()
    for key, name in (("LINE DICTIONARY", "types"), ("LINE TYPES", "types"),
                      ("ROD TYPES", "refused"), ("BODIES", "refused"), ("RODS", "refused"),
                      ("FAILURE", "refused"), ("NODE PROPERTIES", "points"),
                      ("CONNECTION PROPERTIES", "points"), ("POINT", "points"),
                      ("CONNECTION", "points"), ("LINE PROPERTIES", "lines"), ("LINES", "lines"),
                      ("OPTIONS", "options"), ("OUTPUT", "outputs"), ("NEED THIS LINE", "end")):
        if key in text:
            return name
    return "other"


def read_moordyn(path: str | Path, where: str = "") -> MoorDynInput:
    """Read and check a MoorDyn input file; SceneError naming the file, its line number, the
    column and what was expected. `where`: the scene field that named it, for messages."""
    path = Path(path)
    try:
        text = path.read_text(errors="replace")
    except OSError as exc:
        raise SceneError(f"{where}: cannot read the MoorDyn file {path}: {exc.strerror}") from None
    sections: dict[str, list[tuple[int, list[str]]]] = {}
    current, skip = None, 0
    for number, raw in enumerate(text.splitlines(), start=1):
        if "---" in raw:
            current = _section(raw)
            if current == "refused":
                raise SceneError(f"{path}:{number}: {raw.strip('- ').strip()!r}: MoorDyn bodies, "
                                 f"rods and failures are not coupled here; expected lines between "
                                 f"Fixed, Free and Coupled points (the scene's body is the body)")
            skip = 2 if current in ("types", "points", "lines") else 0
            sections.setdefault(current, [])
            continue
        if current is None or not raw.strip():
            continue
        if skip:
            skip -= 1
            continue
        sections[current].append((number, raw.split()))
    reading = _Reading(path)
    version = 1 if any(len(e) == 9 for _, e in sections.get("types", [])) else 2
    types = tuple(reading.line_type(n, e, version) for n, e in sections.get("types", []))
    points = tuple(reading.point(n, e, version) for n, e in sections.get("points", []))
    lines = tuple(reading.line(n, e, version) for n, e in sections.get("lines", []))
    options = {}
    for n, entries in sections.get("options", []):
        if len(entries) >= 2:
            options[entries[1].lower()] = reading.option(n, entries[1], entries[0])
    result = MoorDynInput(str(path), version, types, points, lines, options)
    reading.check(result)
    return result


class _Reading:
    """Checks one row at a time, naming the file and line."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, number: int, what: str):
        raise SceneError(f"{self.path}:{number}: {what}")

    def number(self, number: int, entries, i: int, column: str) -> float:
        try:
            value = float(entries[i])
        except (IndexError, ValueError):
            got = repr(entries[i]) if i < len(entries) else "nothing"
            self.fail(number, f"column {i + 1} ({column}): expected a number, got {got}")
        if not math.isfinite(value):
            self.fail(number, f"column {i + 1} ({column}): expected a finite number, got {value}")
        return value

    def word(self, number: int, value: str, column: str) -> str:
        if not _WORD.match(value):
            self.fail(number, f"{column}: expected a plain word (letters, digits, _ . + -), got "
                              f"{value[:40]!r}")
        return value

    def line_type(self, number: int, e, version: int) -> LineType:
        if len(e) < 9 or (version == 2 and len(e) < 10):
            self.fail(number, f"line type: expected {9 if version == 1 else 10} columns (name, "
                              f"diameter, mass/m, EA, BA/-zeta, ...), got {len(e)}")
        name = self.word(number, e[0], "line type name")
        head = [self.number(number, e, i, c) for i, c in enumerate(_TYPE_COLUMNS[:4], start=1)]
        if min(head[:3]) <= 0:
            self.fail(number, f"line type {name}: expected diameter, mass/m and EA > 0, got "
                              f"{head[0]}, {head[1]}, {head[2]}")
        if version == 1:           # ... Can Cat Cdn Cdt -> ... EI Cd Ca CdAx CaAx
            can, cat, cdn, cdt = (self.number(number, e, i, c) for i, c in
                                  ((5, "Can"), (6, "Cat"), (7, "Cdn"), (8, "Cdt")))
            rest = [0.0, cdn, can, cdt, cat]
        else:
            rest = [self.number(number, e, i, c) for i, c in
                    enumerate(_TYPE_COLUMNS[4:], start=5)]
        values = tuple(repr(v) for v in head + rest)
        return LineType(name, tuple(values))

    def point(self, number: int, e, version: int) -> Point:
        if len(e) < (12 if version == 1 else 9):
            self.fail(number, f"point: expected {12 if version == 1 else 9} columns (ID, type, "
                              f"X, Y, Z, mass, volume, ...), got {len(e)}")
        kind = _KINDS.get(e[1].lower())
        if kind is None:
            self.fail(number, f"point {e[0]}: type {e[1][:40]!r} is not coupled here; expected "
                              f"Fixed, Free or Coupled (v1: Fix, Connect, Vessel)")
        values = [self.number(number, e, i, c) for i, c in
                  ((0, "ID"), (2, "X (m)"), (3, "Y (m)"), (4, "Z (m)"), (5, "mass (kg)"),
                   (6, "volume (m^3)"))]
        cda, ca = (10, 11) if version == 1 else (7, 8)
        return Point(int(values[0]), kind, tuple(values[1:4]), values[4], values[5],
                     self.number(number, e, cda, "CdA (m^2)"), self.number(number, e, ca, "Ca"))

    def line(self, number: int, e, version: int) -> Line:
        if len(e) < 6:
            self.fail(number, f"line: expected ID, type, the two points, length and segments, "
                              f"got {len(e)} columns")
        # v1: ID type length segments anchor fairlead; v2: ID type A B length segments
        a, b, length, segments = (4, 5, 2, 3) if version == 1 else (2, 3, 4, 5)
        for i in (a, b):
            if not e[i].isdigit():
                self.fail(number, f"line {e[0]}: attachment {e[i][:40]!r}: expected a point "
                                  f"ID (rod and body ends are not coupled here)")
        n_seg = self.number(number, e, segments, "segments")
        if n_seg < 1 or n_seg != int(n_seg):
            self.fail(number, f"line {e[0]}: segments: expected a whole number >= 1, got {e[segments]}")
        length_m = self.number(number, e, length, "unstretched length (m)")
        if length_m <= 0:
            self.fail(number, f"line {e[0]}: unstretched length: expected > 0 m, got {length_m}")
        return Line(int(self.number(number, e, 0, "ID")), self.word(number, e[1], "line type"),
                    int(e[a]), int(e[b]), length_m, int(n_seg), number)

    def option(self, number: int, name: str, value: str) -> str:
        self.word(number, name, "option name")
        if name.lower() in _WORD_OPTIONS:
            return self.word(number, value, f"option {name}")
        return repr(self.number(number, [value], 0, f"option {name}"))

    def check(self, data: MoorDynInput) -> None:
        where = f"{self.path}"
        if not data.lines:
            raise SceneError(f"{where}: no lines found; expected a LINES (v1: LINE PROPERTIES) "
                             f"section with one line per row")
        ids = [p.id for p in data.points]
        if ids != list(range(1, len(ids) + 1)) or [l.id for l in data.lines] != \
                list(range(1, len(data.lines) + 1)):
            raise SceneError(f"{where}: point and line IDs must run 1, 2, 3, ... in order "
                             f"(MoorDyn's rule); got points {ids}")
        names = {t.name for t in data.line_types}
        for line in data.lines:
            if line.type not in names:
                raise SceneError(f"{where}:{line.row}: line {line.id}: line type {line.type!r} is "
                                 f"not in the LINE TYPES section "
                                 f"({', '.join(sorted(names)) or 'empty'})")
            for end in (line.attach_a, line.attach_b):
                if end not in ids:
                    raise SceneError(f"{where}:{line.row}: line {line.id}: point {end} is not in "
                                     f"the POINTS section (IDs 1..{len(ids)})")
        if not data.coupled:
            raise SceneError(f"{where}: no Coupled (v1: Vessel) point; expected at least one "
                             f"fairlead that follows the scene's body")


def run_text(data: MoorDynInput, coupled_at_rest: np.ndarray, overrides: dict,
             drag_scale: float = 1.0) -> str:
    """The MoorDyn v2 input MoorDyn runs: the checked tables, coupled points at their rest
    positions (MoorDyn frame, m; one row per coupled point, in file order), the file's options
    with `overrides` (lower-case name -> number or word) and ours: no console or file output.
    drag_scale multiplies every drag coefficient (lines' Cd and CdAx, points' CdA): a
    heavily damped twin settles to rest fast (mbcontrol.plant.moordyn_system)."""
    rows = ["--------------------- MoorDyn Input File ------------------------------------",
            "written by mbcontrol from " + re.sub(r"[^\w./+-]", "_", Path(data.path).name),
            "----------------------- LINE TYPES ------------------------------------------",
            "TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx", "(name) (m) (kg/m) (N) "
            "(N-s/-) (N-m^2) (-) (-) (-) (-)"]
    for t in data.line_types:           # Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
        values = list(t.values)
        for i in (5, 7):
            values[i] = repr(float(values[i]) * drag_scale)
        rows.append(" ".join((t.name, *values)))
    rows += ["---------------------- POINTS --------------------------------",
             "ID Attachment X Y Z Mass Volume CdA Ca", "(#) (-) (m) (m) (m) (kg) (m^3) (m^2) (-)"]
    coupled = iter(np.asarray(coupled_at_rest, float))
    for p in data.points:
        position = next(coupled) if p.kind == "coupled" else p.position
        rows.append(" ".join([str(p.id), p.kind.capitalize(), *(repr(float(v)) for v in position),
                              *(repr(float(v)) for v in (p.mass, p.volume, p.cda * drag_scale,
                                                         p.ca))]))
    rows += ["---------------------- LINES ----------------------------------------",
             "ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs",
             "(#) (name) (#) (#) (m) (-) (-)"]
    rows += [f"{l.id} {l.type} {l.attach_a} {l.attach_b} {l.length!r} {l.segments} -"
             for l in data.lines]
    options = {k: v for k, v in data.options.items() if k not in _OURS}
    options.update({k.lower(): str(v) for k, v in overrides.items()})
    options.update({"writelog": "0", "disableoutput": "1", "disableouttime": "1"})
    rows.append("---------------------- OPTIONS -----------------------------------------")
    rows += [f"{value} {name}" for name, value in options.items()]
    rows.append("------------------------- need this line --------------------------------------")
    return "\n".join(rows) + "\n"
