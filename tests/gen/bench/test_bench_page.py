"""docs/bench.md's sections that are written from the sweep it ships (docs/data/sweep.json):
the sweep table and its notes, and every `bumprtl recommend` run the page quotes with its
exit status and output. Written again from that file, without measuring anything, they are
the committed text: a column, a rounding, a heading, a ranking or an evidence line changed
in the writers without the page, or a page edited by hand, fails here."""

import re
import shlex
import shutil
from pathlib import Path

import pytest

from bumprtl.gen.bench.sweep import markdown
from bumprtl.gen.cli.main import main

DOCS = Path(__file__).resolve().parents[3] / "docs"
SWEEP = DOCS / "data" / "sweep.json"
PAGE = (DOCS / "bench.md").read_text()


def _section(name):
    return PAGE[PAGE.index(f"<!-- {name}:begin -->\n") + len(f"<!-- {name}:begin -->\n"):
                PAGE.index(f"<!-- {name}:end -->")].rstrip("\n")


def test_the_sweep_section_is_written_again_from_the_shipped_sweep():
    import json
    data = json.loads(SWEEP.read_text())
    plots = [("error against cost and run time", Path("img") / "bench_pareto.png")]
    assert _section("sweep") == "## Error, cost and speed sweep\n\n" + markdown(data, data["command"], plots)


RUNS = re.findall(r"^`(bumprtl recommend [^`]*)` \(exit (\d)\):\n\n```\n(.*?)```", _section("recommend"),
                  flags=re.M | re.S)


def test_the_page_quotes_recommend_runs():
    assert len(RUNS) >= 3


@pytest.mark.parametrize("command, status, output", RUNS, ids=[r[0] for r in RUNS])
def test_each_quoted_recommend_run_is_what_the_command_prints(command, status, output, tmp_path,
                                                               monkeypatch, capsys):
    """Run where the page's run was: the sweep at build/bench/sweep.json of the working
    directory (the path the output names)."""
    (tmp_path / "build" / "bench").mkdir(parents=True)
    shutil.copy(SWEEP, tmp_path / "build" / "bench" / "sweep.json")
    monkeypatch.chdir(tmp_path)
    assert main(shlex.split(command)[1:]) == int(status)
    assert capsys.readouterr().out == output
