"""docs/report.md and docs/table1.md's ECP5 section against the placement rows they were
written from (docs/data/fpga.json, which ``bumprtl report fpga`` saves beside its page and
``report table1`` reads): written again from those rows, without placing anything, they are
the committed text. A row, a column or a heading changed in the writers, or a page whose
rows were placed again without the other page following, fails here."""

import json
import shlex
from dataclasses import replace
from pathlib import Path

import pytest

from bumprtl.gen.cli.main import build_parser
from bumprtl.gen.cli.report import fpga_run_of
from bumprtl.gen.report.fpga import write_report
from bumprtl.gen.report.table1 import fpga_section
from bumprtl.rtl.config import Config

DOCS = Path(__file__).resolve().parents[2] / "docs"
DATA = DOCS / "data" / "fpga.json"


def _run(command, out):
    """The FpgaRun the saved command line names, parsed by the command's own parser, its
    page written to ``out``."""
    args = build_parser().parse_args(shlex.split(command)[1:])
    return replace(fpga_run_of(args), out=out)


def test_table1s_ecp5_section_is_the_fpga_runs():
    assert fpga_section(DATA) in (DOCS / "table1.md").read_text(), \
        "docs/table1.md's ECP5 section is stale: bumprtl report table1"


def test_the_report_page_is_written_again_from_its_rows(tmp_path, capsys, saved_figures):
    """Everything up to the primitives' ceiling (whose own placements the saved rows do not
    hold) is what write_report makes of the saved rows; its plot puts each design's
    pipeline row (placed) at its LUT4 against its max and mean error, named."""
    data = json.loads(DATA.read_text())
    run = _run(data["command"], tmp_path / "report.md")
    write_report(run, data["rows"], data["accuracy"], Config())
    assert (tmp_path / "data" / "fpga.json").read_text() == DATA.read_text()
    mark = "\n## The primitives' own ceiling"
    ours, page = (tmp_path / "report.md").read_text(), (DOCS / "report.md").read_text()
    assert mark in page
    assert mark not in ours                         # no ceilings given: the notes follow
    assert ours.split("\n## Notes")[0].rstrip() == page.split(mark)[0].rstrip()
    # the plot the page shows is this one: the same picture size (a figure or layout
    # change without writing the page again changes it)
    from PIL import Image
    with Image.open(tmp_path / "img" / "cost_vs_error.png") as ours_png, \
            Image.open(DOCS / "img" / "cost_vs_error.png") as page_png:
        assert ours_png.size == page_png.size
    (ax,) = saved_figures[0].axes
    pipelines = {r["design"]: r["LUT4"] for r in data["rows"] if r["row"] == "pipeline" and "error" not in r}
    assert {t.get_text() for t in ax.texts} == set(pipelines)
    points = sorted(tuple(map(float, xy)) for c in ax.collections for xy in c.get_offsets())
    want = sorted([(float(lut), float(data["accuracy"][d]["max"])) for d, lut in pipelines.items()]
                  + [(float(lut), max(data["accuracy"][d]["mean"], 1e-3)) for d, lut in pipelines.items()])
    assert [x for xy in points for x in xy] == pytest.approx([x for xy in want for x in xy])
    assert f"wrote {tmp_path / 'report.md'}" in capsys.readouterr().out
