"""docs/formal.md's two tables against the runner that wrote them: every check make formal
runs has its row, in the runner's order, in the section gen/formal/doc.py puts it in, and
gen/formal/doc.table writes the committed rows back character for character. A column, a
heading, an order or a section rule changed without the page fails here."""

import re
from pathlib import Path

import pytest

from bumprtl.gen.formal import doc as fdoc
from bumprtl.gen.formal import run as fr
from bumprtl.sim.formal import axi
from bumprtl.sim.formal.mutants import MUTANTS
from bumprtl.sim.formal.targets import TARGETS

PAGE = Path(__file__).resolve().parents[3] / "docs" / "formal.md"


def _section(name):
    text = PAGE.read_text()
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)<!-- {name}:end -->", text, flags=re.S)
    assert m, name
    body = m.group(1)
    return body[body.index("| unit |"):].rstrip("\n")


def _rows(block):
    rows = []
    for line in block.splitlines()[2:]:
        unit, prop, result, depth, latency, lemmas, seconds = (c.strip() for c in line.strip("|").split("|"))
        rows.append(fr.Row(unit, prop, result, int(depth), float(seconds), int(latency), int(lemmas)))
    return rows


MAIN, AXI = _rows(_section(fdoc.SECTION)), _rows(_section(fdoc.AXI_SECTION))


@pytest.mark.parametrize("name, rows", [(fdoc.SECTION, MAIN), (fdoc.AXI_SECTION, AXI)])
def test_the_table_writes_the_committed_rows_back(name, rows):
    assert fdoc.table(rows) == _section(name)


def test_each_row_is_in_its_section():
    assert MAIN and AXI
    assert not any(fdoc.axi_unit(r.unit) for r in MAIN)
    assert all(fdoc.axi_unit(r.unit) for r in AXI)


def test_the_page_has_a_row_for_every_check_make_formal_runs_in_the_runners_order():
    want = [(name, prop) for name in TARGETS for prop in TARGETS[name].props]
    want += [(f"mutant {name}", prop) for name, (_cls, prop) in MUTANTS.items()]
    want += [(f"mutant axi_{name}", "axi") for name in axi.MUTANTS]
    rows = MAIN + AXI
    assert sorted((r.unit, r.prop) for r in rows) == sorted(want)
    for part in (MAIN, AXI):
        assert [(r.unit, r.prop) for r in fr._ordered(part)] == [(r.unit, r.prop) for r in part]


def test_every_row_of_the_page_passed():
    assert all(r.ok for r in MAIN + AXI), [r for r in MAIN + AXI if not r.ok]
    assert {r.result for r in MAIN + AXI} <= {"proved", "bounded", "covered", "fails as expected"}
    assert all(r.result == "fails as expected" for r in MAIN + AXI if r.unit.startswith("mutant "))


def test_a_broken_units_row_has_no_lemmas_and_a_units_cover_none_either():
    for r in MAIN + AXI:
        if r.unit.startswith("mutant ") or r.result == "covered":
            assert r.lemmas == 0, r


@pytest.mark.parametrize("command, says", [
    ("--from-results --out build/formal", "Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 --doc docs/formal.md`; `bumprtl formal` is the same command)"),
    ("-j 2 --doc docs/formal.md", "Produced by `make formal` (`python -m bumprtl.gen.formal.run -j 2 --doc docs/formal.md`; `bumprtl formal` is the same command)"),
    ("", "Produced by `make formal` ("),
    ("sincos --prop hold", "Produced by `python -m bumprtl.gen.formal.run sincos --prop hold` (`make formal` runs these"),
    ("sincos --merge", "the rows it names re-checked by `python -m bumprtl.gen.formal.run sincos --merge`")])
def test_the_page_names_the_command_its_rows_came_from(tmp_path, command, says):
    """A table reprinted from saved results (``--from-results``) or written by make formal's
    own flags names make formal; a run of some checks names its command; a merged run names
    both."""
    page = tmp_path / "formal.md"
    fdoc.write_doc(page, MAIN[:2], command)
    text = page.read_text()
    assert says in text, text[:400]
    assert fdoc.table(MAIN[:2]) in text
