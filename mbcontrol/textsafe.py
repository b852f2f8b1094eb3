"""Text that leaves the toolbox: the name rule, and one escape per target language.

Scene names reach generated C, FMI XML, Makefiles, CasADi Function names, reports and
terminal messages. `name_problem` is the one name rule (checked at scene load, `scene.checks`);
the escapes below do not rely on it (defence in depth): each turns *any* string into text
that is inert in its target, so a name that slipped past the rule (an object built in Python,
a file name, a plant from another tool) still cannot end a comment, open a directive, add a
Make rule or break a document.

Targets: `c_comment`, `c_string`, `c_identifier`, `xml_attr` / `xml_text`, `make_word`,
`md_text` (Markdown, table cells included), `html_text`, `plain_text` (one line of a text
report) and `shown` (a value inside an error or log message).
"""
from __future__ import annotations

import hashlib
import html
import re

NAME_MAX = 64
NAME_RULE = ("a name is an ASCII letter followed by ASCII letters, digits and single "
             f"underscores, at most {NAME_MAX} characters: no '__' (the toolbox's separator, "
             "as in body__Heave), no trailing '_', no dots, spaces, quotes or other characters")
_NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9])*")


def name_problem(value) -> str | None:
    """None if `value` obeys NAME_RULE, else what is wrong with it (a short phrase)."""
    if not isinstance(value, str):
        return f"expected a string, got {type(value).__name__}"
    if not value:
        return "empty"
    if len(value) > NAME_MAX:
        return f"{len(value)} characters, more than {NAME_MAX}"
    if _NAME.fullmatch(value):
        return None
    if not value[0].isascii() or not value[0].isalpha():
        return "does not start with an ASCII letter"
    if "__" in value:
        return "contains '__'"
    if value.endswith("_"):
        return "ends with '_'"
    bad = next(ch for ch in value if not (ch.isascii() and (ch.isalnum() or ch == "_")))
    return f"contains {shown(bad)}"


def shown(value, limit: int = 80) -> str:
    """`value` as it may appear in a message: ascii() of its text (quotes around it; newlines,
    escape sequences and non-ASCII as backslash escapes, so nothing reaches a terminal raw),
    cut to about `limit` characters with the full length said."""
    text = value if isinstance(value, str) else str(value)
    if len(text) <= limit:
        return ascii(text)
    return f"{ascii(text[:limit])}... ({len(text)} characters)"


def _escaped(text: str) -> str:
    """Printable ASCII kept; every other character as a backslash escape (\\n, \\x07, \\u2028)."""
    out = []
    for ch in text:
        if " " <= ch <= "~":
            out.append(ch)
        else:
            out.append({"\n": "\\n", "\t": "\\t", "\r": "\\r"}.get(ch) or ascii(ch)[1:-1])
    return "".join(out)


def plain_text(text, limit: int | None = None) -> str:
    """One line of a plain-text report: control and non-ASCII characters escaped (a newline
    cannot start a row, an escape sequence cannot reach a terminal); cut to `limit`."""
    out = _escaped(str(text))
    return out if limit is None or len(out) <= limit else out[:max(limit - 3, 0)] + "..."


# ------------------------------------------------------------------------------------- C

def c_comment(text) -> str:
    """Text for inside a C block comment: one line of printable ASCII (a newline could start a
    preprocessor directive), with every '*/' and '/*' split so the comment neither ends early
    nor nests."""
    out = _escaped(str(text))
    while "*/" in out or "/*" in out:
        out = out.replace("*/", "* /").replace("/*", "/ *")
    return out


def c_string(text) -> str:
    """A C string literal (quotes included) holding `text`'s UTF-8 bytes: backslash, quote
    and '?' (trigraphs such as ??/ under -std=c99) escaped, every byte outside printable ASCII
    as a three-digit octal escape (hex escapes would swallow the hex digits after them)."""
    out = []
    for byte in str(text).encode("utf-8", "surrogatepass"):
        ch = chr(byte)
        if ch in '\\"?':
            out.append("\\" + ch)
        elif " " <= ch <= "~":
            out.append(ch)
        else:
            out.append(f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


_C_KEYWORDS = frozenset(
    "auto break case char const continue default do double else enum extern float for goto if "
    "inline int long register restrict return short signed sizeof static struct switch "
    "typedef union unsigned void volatile while _Bool _Complex _Imaginary _Alignas _Alignof "
    "_Atomic _Generic _Noreturn _Static_assert _Thread_local bool true false".split())


def _tag(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:8]


IDENTIFIER_MAX = 120   # room for "lib<identifier>_<function>.so" in a 255-byte file name


def c_identifier(text, prefix: str = "m") -> str:
    """A C identifier and CasADi Function name for `text`, deterministically: text that is
    already one (ASCII letter first, then letters, digits, single underscores, no trailing '_',
    not a keyword, at most IDENTIFIER_MAX characters) is kept; otherwise other characters
    become '_', runs of '_' one, a leading non-letter gets `prefix`, the rest is cut to 80
    characters and a hash of the original text is appended, so two different texts never map
    to one identifier silently. A kept identifier joined to another by one '_' is again one."""
    text = str(text)
    if _NAME.fullmatch(text) and len(text) <= IDENTIFIER_MAX and text not in _C_KEYWORDS:
        return text
    clean = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9]", "_", text[:400])).strip("_")[:80]
    if not clean[:1].isalpha():
        clean = f"{prefix}_{clean}".rstrip("_")
    return f"{clean}_{_tag(text)}"


# ----------------------------------------------------------------------------------- XML

_XML_REFS = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&apos;",
             "\t": "&#9;", "\n": "&#10;", "\r": "&#13;"}


def _xml_allowed(code: int) -> bool:
    """XML 1.0's Char production: no control characters but tab, newline and return."""
    return (code in (0x9, 0xA, 0xD) or 0x20 <= code <= 0xD7FF or 0xE000 <= code <= 0xFFFD
            or 0x10000 <= code <= 0x10FFFF)


def xml_attr(text) -> str:
    """An XML 1.0 attribute value (for inside "..." or '...'): markup characters and both
    quotes as entities; tab, newline and return as character references (a parser would
    otherwise normalise them to spaces); non-ASCII as character references (the file stays
    ASCII whatever the writer's encoding); characters XML 1.0 cannot hold at all (NUL, other
    controls, lone surrogates) as visible escapes such as \\x00."""
    out = []
    for ch in str(text):
        code = ord(ch)
        if ch in _XML_REFS:
            out.append(_XML_REFS[ch])
        elif not _xml_allowed(code):
            out.append(ascii(ch)[1:-1])
        elif code > 0x7E:
            out.append(f"&#{code};")
        else:
            out.append(ch)
    return "".join(out)


def xml_text(text) -> str:
    """XML 1.0 element content: the same escapes as an attribute value (safe in both)."""
    return xml_attr(text)


# ---------------------------------------------------------------------------------- Make

_MAKE_SAFE = re.compile(r"[A-Za-z0-9._+/-]+")


def make_word(text) -> str:
    """A word for a Makefile target, prerequisite, variable value or comment. Make has no
    escape that works in every position ('$', '#', ':', '=', '%', wildcards, spaces, and a
    newline or a trailing backslash that ends or continues a line), so words are mapped, not
    escaped: text of [A-Za-z0-9._+/-] is kept; any other becomes that set with a hash of the
    original appended (as `c_identifier` does)."""
    text = str(text)
    if _MAKE_SAFE.fullmatch(text) and len(text) <= 200:
        return text
    clean = re.sub(r"_+", "_", re.sub(r"[^A-Za-z0-9._+/-]", "_", text))[:100].strip("_")
    return f"{clean or 'x'}_{_tag(text)}"


# ------------------------------------------------------------------------ Markdown, HTML

_MD_SPECIAL = re.compile(r"([\\`*_\[\]|#~!])")


def _one_line(text) -> str:
    """Printable characters kept (non-ASCII too); newlines, controls, line separators escaped."""
    text = str(text)
    return text if text.isprintable() else "".join(
        ch if ch.isprintable() else _escaped(ch) for ch in text)


def md_text(text) -> str:
    """Inline Markdown (a table cell, a heading's text, a list item): one line (a newline
    would end the row), '|' and the other inline markup characters ('#', backticks, '*', '_',
    brackets, backslash) backslash-escaped, then HTML's special characters as entities (no
    tag, no comment, no entity of the text's own)."""
    return html.escape(_MD_SPECIAL.sub(r"\\\1", _one_line(text)), quote=True)


def html_text(text) -> str:
    """HTML text or attribute value (quoted): &, <, >, both quotes as entities; control
    characters (which HTML forbids) as visible escapes."""
    return html.escape(_one_line(text), quote=True)
