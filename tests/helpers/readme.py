"""Reading the documents the way a test checks them: README.md (the front door) and
notebooks/guide.md (the reference it points to), their tables, code blocks and commands.

Tests that check a number the documents quote read it from here, not from a copy, so they
cannot drift from what the code computes: edit either and the test says which. Both files are
read as one text (README first); `where` names the file and line of a line of that text.
"""
from __future__ import annotations

import re
import shlex
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
GUIDE = ROOT / "notebooks" / "guide.md"
DOCUMENTS = (README, GUIDE)
NUMBER = re.compile(r"[-+]?\d[\d,]*\.?\d*(?:e[-+]?\d+)?")


def text() -> str:
    return "".join(path.read_text() for path in DOCUMENTS)


def where(line: int) -> str:
    """'notebooks/guide.md line 12' for line `line` of text()."""
    for path in DOCUMENTS:
        count = len(path.read_text().splitlines())
        if line <= count:
            return f"{path.relative_to(ROOT)} line {line}"
        line -= count
    return f"line {line} past the documents"


def tables() -> list[tuple[int, list[list[str]]]]:
    """Every Markdown table: (line number of its header, rows of cells, header first; the
    |---| line dropped)."""
    found, rows, start = [], [], None
    for number, line in enumerate(text().splitlines(), 1):
        if line.startswith("|"):
            if start is None:
                start, rows = number, []
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not all(set(c) <= set("-: ") for c in cells):
                rows.append(cells)
        elif start is not None:
            found.append((start, rows))
            start = None
    return found


def table(header: str, with_header: bool = False) -> list[list[str]]:
    """The one table whose first header cell is `header`: its rows after the header (and the
    header first, with_header)."""
    hits = [rows for _, rows in tables() if rows[0][0] == header]
    if len(hits) != 1:
        raise AssertionError(f"README.md and notebooks/guide.md: expected one table headed "
                             f"{header!r}, found {len(hits)}")
    return hits[0] if with_header else hits[0][1:]


def row(header: str, first_cell: str) -> list[str]:
    """The row of table `header` whose first cell is `first_cell`, or starts with it and a
    space or a comma ("rm3" is not "rm3_moored")."""
    hits = [r for r in table(header) if r[0] == first_cell
            or r[0].startswith((first_cell + " ", first_cell + ","))]
    if len(hits) != 1:
        raise AssertionError(f"table {header!r} (README.md, notebooks/guide.md): expected one row starting "
                             f"{first_cell!r}, found {len(hits)}")
    return hits[0]


def numbers(cell: str) -> list[float]:
    """The numbers in a cell, in order ("1,705 MWh" -> [1705.0]; "21 (79.8 %)" -> [21, 79.8])."""
    return [float(n.replace(",", "")) for n in NUMBER.findall(cell)]


def code_blocks(language: str) -> list[str]:
    """The fenced blocks of `language` ("bash", "python", "" for plain ones)."""
    blocks, current, tag = [], None, None
    for line in text().splitlines(keepends=True):
        if line.startswith("```"):
            if current is None:
                current, tag = [], line[3:].strip()
            else:
                if tag == language:
                    blocks.append("".join(current))
                current = None
        elif current is not None:
            current.append(line)
    return blocks


def commands() -> list[list[str]]:
    """Each command line of the bash blocks, continuations joined, comments dropped, split
    into words."""
    found = []
    for block in code_blocks("bash"):
        heredoc = None
        for line in block.replace("\\\n", " ").splitlines():
            if heredoc is not None:                 # a file written by `cat <<'EOF'`
                heredoc = None if line.strip() == heredoc else heredoc
                continue
            if "<<'" in line:
                heredoc = line.split("<<'")[1].split("'")[0]
            line = line.split(" #")[0].strip()
            if line and not line.startswith("#"):
                found.append(shlex.split(line.split(" <<")[0]))
    return found
