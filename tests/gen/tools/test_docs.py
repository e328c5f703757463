"""Generated pages (gen/tools/docs.py): the one marked-section writer every generator uses,
and the ``Made at:`` record tests/test_docs_made_at.py reads back."""

from pathlib import Path
from types import SimpleNamespace

from bumprtl.gen.formal.doc import SECTION
from bumprtl.gen.formal.doc import write_doc as write_formal_doc
from bumprtl.gen.tools.docs import made_at, markers, write_section
from bumprtl.rtl.config import Config


def test_made_at_records_both_widths_and_a_note_only_when_given():
    """made_at is the one line a generated page names its configuration with: both widths,
    then the note in parentheses, and nothing after the widths without a note."""
    cfg = Config(angle_bits=12, frac_bits=13)
    assert made_at(cfg) == "Made at: angle_bits=12, frac_bits=13"
    assert made_at(cfg, "palette scene") == "Made at: angle_bits=12, frac_bits=13 (palette scene)"


def test_write_section_keeps_other_sections(tmp_path):
    doc = tmp_path / "bench.md"
    write_section(doc, "sweep", "one")
    write_section(doc, "skip", "two")
    write_section(doc, "sweep", "three")
    text = doc.read_text()
    assert "three" in text and "two" in text and "one" not in text
    assert text.index("three") < text.index("two")
    assert text.startswith("# Benchmarks\n\n<!-- sweep:begin -->\nthree\n<!-- sweep:end -->")


def test_write_section_replaces_only_between_its_markers(tmp_path):
    """The prose before and after a section stays byte for byte; a new page gets its title."""
    begin, end = markers("table")
    doc = tmp_path / "sub" / "page.md"
    assert write_section(doc, "table", "first", title="# Proofs") == doc
    assert doc.read_text() == f"# Proofs\n\n{begin}\nfirst\n{end}\n"
    doc.write_text(f"intro\n\n{begin}\nold\n{end}\ntail, kept\n")
    write_section(doc, "table", "new")
    assert doc.read_text() == f"intro\n\n{begin}\nnew\n{end}\ntail, kept\n"


def test_the_formal_table_is_a_marked_section(tmp_path):
    """docs/formal.md's table goes through the same writer: the prose around it is kept,
    the record names today's default Config, a --merge run says which rows it re-checked."""
    row = SimpleNamespace(unit="sincos", prop="order", result="proved", depth=2, latency=3,
                          lemmas=1, seconds=1.5)
    begin, end = markers(SECTION)
    doc = tmp_path / "formal.md"
    doc.write_text(f"# Formal proofs\n\nprose\n\n{begin}\nstale\n{end}\n\nmore prose\n")
    write_formal_doc(doc, [row], "sincos --merge")
    text = doc.read_text()
    assert text.startswith("# Formal proofs\n\nprose\n\n") and text.endswith(f"{end}\n\nmore prose\n")
    assert "stale" not in text and "| sincos | order | proved | 2 | 3 | 1 | 1.5 |" in text
    assert made_at(Config(), "the default; each proof runs at the small widths of "
                             "sim/formal/targets.py") + ":" in text
    assert "re-checked by `python -m bumprtl.gen.formal.run sincos --merge`" in text


def test_the_formal_page_keeps_its_markers():
    """docs/formal.md carries the section markers write_doc replaces between."""
    text = (Path(__file__).resolve().parents[3] / "docs" / "formal.md").read_text()
    begin, end = markers(SECTION)
    assert text.count(begin) == 1 and text.count(end) == 1 and text.index(begin) < text.index(end)
