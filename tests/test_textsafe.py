"""Each escape of `mbcontrol.textsafe` against a table of hostile strings, judged by the
target's own reader: gcc's preprocessor and a compiled program for C, xml.etree for XML, GNU
make for Makefiles, html.parser for HTML, a table row's column count for Markdown. The old
writers (raw names in a C comment, saxutils.escape in attributes) fail each of these."""
from __future__ import annotations

import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from html.parser import HTMLParser

import casadi as ca
import pytest

from mbcontrol.textsafe import (NAME_MAX, c_comment, c_identifier, c_string, html_text,
                                make_word, md_text, name_problem, plain_text, shown, xml_attr,
                                xml_text)

# the PTO name first; then one of each character class a target treats specially
HOSTILE = [
    'pto*/\n#include\t"/some/file"\n/*',
    "*/", "/*", '"', "'", "<", ">", "&", "$(shell touch pwned)", "a\tb", "nul\x00byte",
    "cr\rlf\n", "\x1b[31mred\x1b[0m", "é ü 漢 \u202e rtl", "\u2028line separator", "??/",
    "trailing\\", "a|b", "`code`", "# heading", "<b>bold</b><!--", "&amp;", "%.o: $$@",
    "x" * 10_000, ("pto*/\n#include <x>\n" * 500)[:10_000],
]
IDS = [f"hostile{i}" for i in range(len(HOSTILE))]
XML_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def _gcc() -> str:
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    return cc


# ------------------------------------------------------------------------------ names

@pytest.mark.parametrize("name", ["a", "pto", "hinge_pto", "B2", "x" * NAME_MAX, "a1_b2_c3"])
def test_the_rule_takes_plain_names(name):
    assert name_problem(name) is None


@pytest.mark.parametrize("name", ["", "1a", "_a", "a_", "a__b", "a.b", "a b", "a-b", "é",
                                  "x" * (NAME_MAX + 1), "__import__", *HOSTILE])
def test_the_rule_refuses_the_rest(name):
    assert name_problem(name)


@pytest.mark.parametrize("text", HOSTILE, ids=IDS)
def test_shown_is_one_short_ascii_line(text):
    out = shown(text)
    assert out.isascii() and out.isprintable()
    # about 80 characters of text, quoted and escaped (each character at most 10 in ascii())
    assert len(out) <= 80 * 10 + 40
    if len(text) > 80:
        assert f"({len(text)} characters)" in out


@pytest.mark.parametrize("text", HOSTILE, ids=IDS)
def test_plain_text_is_one_printable_line(text):
    out = plain_text(text)
    assert out.isascii() and out.isprintable()


# ---------------------------------------------------------------------------------- C

def test_c_comments_hold_any_text(tmp_path):
    """Every hostile text in a comment of its own: the preprocessed file is exactly the
    declarations between the comments (no directive ran, no comment ended early)."""
    lines = [f"/* {c_comment(t)} */\nint ok{i};" for i, t in enumerate(HOSTILE)]
    for out in map(c_comment, HOSTILE):
        assert out.isascii() and out.isprintable() and "*/" not in out and "/*" not in out
    source = tmp_path / "comments.c"
    source.write_text("\n".join(lines) + "\n")
    done = subprocess.run([_gcc(), "-std=c99", "-E", "-P", str(source)], capture_output=True,
                          text=True)
    assert done.returncode == 0, done.stderr
    tokens = done.stdout.split()
    assert tokens == [w for i in range(len(HOSTILE)) for w in ("int", f"ok{i};")]


def test_c_string_literals_round_trip_every_byte(tmp_path):
    """A compiled program prints each literal's bytes (NUL included: sizeof, not strlen);
    they are the text's UTF-8 bytes. -std=c99 turns trigraphs on, so ??/ is tested too."""
    decls = "\n".join(f"static const char s{i}[] = {c_string(t)};" for i, t in enumerate(HOSTILE))
    prints = "\n".join(f"    dump(s{i}, sizeof s{i} - 1);" for i in range(len(HOSTILE)))
    program = tmp_path / "strings.c"
    program.write_text(f"""#include <stdio.h>
{decls}
static void dump(const char *s, size_t n) {{
    for (size_t k = 0; k < n; k++) printf("%02x", (unsigned char)s[k]);
    printf("\\n");
}}
int main(void) {{
{prints}
    return 0;
}}
""")
    exe = tmp_path / "strings"
    built = subprocess.run([_gcc(), "-std=c99", "-Wall", "-o", str(exe), str(program)],
                           capture_output=True, text=True)
    assert built.returncode == 0, built.stderr
    printed = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    assert printed.splitlines() == [t.encode("utf-8").hex() for t in HOSTILE]


@pytest.mark.parametrize("text", HOSTILE + ["a-b", "a_b", "a.b", "a b", "int", "1abc", "a__b"])
def test_c_identifiers_are_valid_for_c_and_casadi(text):
    ident = c_identifier(text)
    assert re.fullmatch(r"[A-Za-z](?:_?[A-Za-z0-9])*", ident) and len(ident) <= 120
    assert ident != "int" and c_identifier(text) == ident           # deterministic
    x = ca.SX.sym("x")
    ca.Function(ident, [x], [x])                 # CasADi takes it,
    ca.Function(f"{ident}_law", [x], [x])        # and joined to another name by one '_'


def test_c_identifiers_do_not_collide_and_keep_plain_names():
    texts = HOSTILE + ["a-b", "a_b", "a.b", "a b", "a__b", "a_", "a"]
    idents = [c_identifier(t) for t in texts]
    assert len(set(idents)) == len(set(texts))
    for name in ("sphere_passive", "hinged_barge_mpc", "a"):
        assert c_identifier(name) == name


# -------------------------------------------------------------------------------- XML

@pytest.mark.parametrize("text", HOSTILE, ids=IDS)
def test_xml_attributes_and_text_parse_and_round_trip(text):
    doc = f"<r a=\"{xml_attr(text)}\" b='{xml_attr(text)}'>{xml_text(text)}</r>"
    assert doc.isascii()                        # whatever encoding the file is written in
    root = ET.fromstring(doc)
    assert set(root.attrib) == {"a", "b"} and len(root) == 0
    if XML_FORBIDDEN.search(text):              # XML 1.0 cannot hold these: shown escaped
        kept = XML_FORBIDDEN.sub(lambda m: ascii(m.group())[1:-1], text)
    else:
        kept = text
    assert root.get("a") == root.get("b") == root.text == kept


# ------------------------------------------------------------------------------- Make

def test_makefile_words_add_no_rule_and_run_nothing(tmp_path):
    if shutil.which("make") is None:
        pytest.skip("no make")
    rules = "".join(f"{make_word(f'lib{t}.so')}: {make_word(t + '.c')}\n\t@echo rule{i}\n\n"
                    for i, t in enumerate(HOSTILE))
    (tmp_path / "Makefile").write_text(f"# {make_word(HOSTILE[0])}\nall:\n\t@echo all\n\n{rules}")
    done = subprocess.run(["make", "-n", "-p", "-f", "Makefile"], cwd=tmp_path,
                          capture_output=True, text=True)
    assert not (tmp_path / "pwned").exists()   # $(shell ...) never ran
    # every target make knows from this file: all and one library per text, no other
    targets = set(re.findall(r"^([^\s#%.][^:=\s]*):", done.stdout, re.M))
    ours = {"all"} | {make_word(f"lib{t}.so") for t in HOSTILE}
    assert ours <= targets and not {t for t in targets if t.startswith("lib")} - ours
    assert make_word("mbc_data.c") == "mbc_data.c" and make_word("libsphere_passive.so") == \
        "libsphere_passive.so"


# --------------------------------------------------------------------- Markdown, HTML

def _cells(row: str) -> list[str]:
    """A GFM table row's cells: split at '|' not escaped by a backslash."""
    return re.split(r"(?<!\\)\|", row.strip().strip("|"))


@pytest.mark.parametrize("text", HOSTILE, ids=IDS)
def test_markdown_cells_keep_the_table(text):
    cell = md_text(text)
    row = f"| {cell} | 1.0 |"
    assert "\n" not in row and "\r" not in row and row.isprintable()
    assert len(_cells(row)) == 2
    assert not re.search(r"(?<!\\)[`<>]", cell)        # no code span, no tag
    assert not cell.startswith("#")


class _Collect(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags, self.data = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)

    def handle_comment(self, data):
        self.tags.append("!--")

    def handle_data(self, data):
        self.data.append(data)


@pytest.mark.parametrize("text", HOSTILE, ids=IDS)
def test_html_text_opens_no_tag(text):
    parser = _Collect()
    parser.feed(f"<td>{html_text(text)}</td>")
    parser.close()
    assert parser.tags == ["td"]
    assert "".join(parser.data) == "".join(ch if ch.isprintable() else ascii(ch)[1:-1]
                                           for ch in text)


# ------------------------------------------------------------------ the report writers

def test_the_demo_summary_keeps_its_table():
    """summary.md (mbcontrol.demo.markdown) with a hostile model name and run labels: one
    heading line, and every table row with the header's five columns."""
    from mbcontrol.demo import markdown
    run = {"ptos": {"hinge_pto": {"mean_power_W": 1e-3, "max_force": 1.0, "max_stroke": 0.1}}}
    report = {"model": HOSTILE[0], "plant": {"states": 3, "hydro_dofs": HOSTILE[:3],
                                             "radiation_states": 2, "radiation_fit_error": 0.01},
              "linear": {"stable": True},
              "validation": {"max_rel_error_time_domain": 0.01, "max_rel_error_state_space": 0.01},
              "design": {"optimal_damping": 1.0, "predicted_power_W": 1e-3,
                         "complex_conjugate_bound_W": 2e-3},
              "closed_loop": {text: run for text in HOSTILE}}
    lines = markdown(report).splitlines()
    rows = [line for line in lines if line.startswith("|")]
    assert len(rows) == 2 + len(HOSTILE)               # header, rule, one row per run
    assert all(len(_cells(row)) == 5 for row in rows)
    assert sum(line.startswith("#") for line in lines) == 1
    assert all(line.isprintable() for line in lines)


def test_the_identification_tables_keep_one_line_per_row():
    """parameters.txt and the error table (studies.identify.report) with hostile parameter,
    channel and label text: one line per parameter or channel, nothing raw."""
    from types import SimpleNamespace

    from mbcontrol.studies.identify import error_table, parameter_table
    fit = [SimpleNamespace(name=t, initial=1.0, lo=0.5, hi=2.0, log=False) for t in HOSTILE]
    result = SimpleNamespace(values={t: 1.1 for t in HOSTILE}, std={}, at_bound={},
                             uncertainty_method="independent\nresiduals", cost_initial=1.0,
                             cost=0.5, simulations=3, wall_time_s=0.1)
    problem = SimpleNamespace(fit=fit, cost="amplitude")
    table = parameter_table(problem, result)
    assert len(table.splitlines()) == 1 + len(HOSTILE) + 2 and table.isascii()
    rows = [{"channel": t, "unit": "m", "model": 1.1, "measured": 1.0, "relative_error": 0.1,
             "group": "g", "omega": 1.0, "incident": 0.1, "run": "r"} for t in HOSTILE[:6]]
    errors = error_table(rows, HOSTILE[0])
    assert len(errors.splitlines()) == 1 + len(set(HOSTILE[:6])) and errors.isascii()
