"""docs/globe.md quotes the globe model's check against float64
(``python -m bumprtl.sim.golden.globe``): every quoted output block is what the command
named before it prints, line for line (the page's ``...`` stands for that command's start).
The widths, latency, error bounds, measured maxima and level counts the page reasons from
are the model's, not copied by hand."""

import re
from pathlib import Path

import pytest

from bumprtl.sim.golden.globe import main

PAGE = Path(__file__).resolve().parents[2] / "docs" / "globe.md"
COMMAND = re.compile(r"`(?:\.venv/bin/python -m bumprtl\.sim\.golden\.globe|\.\.\.)([^`]*)`")


def quoted_runs():
    """[(argv, quoted lines)]: each plain ``` block of the page with the last globe command
    named between it and the block before it."""
    text = PAGE.read_text()
    runs, before, block, fence = [], [], [], None
    for line in text.splitlines():
        if line.startswith("```"):
            if fence is None:                # an opening fence: "```" or "```sh"
                fence, block = line[3:], []
                continue
            commands = COMMAND.findall("\n".join(before))
            if fence == "" and commands:
                runs.append((commands[-1].split(), block))
            fence, before = None, []
        elif fence is None:
            before.append(line)
        else:
            block.append(line)
    return runs


RUNS = quoted_runs()


def test_the_page_quotes_every_run_it_names():
    """The parser finds the page's five quoted runs (a reworded command would otherwise
    drop its block from the check below)."""
    assert len(RUNS) == 5, [argv for argv, _ in RUNS]
    assert ["--rotations", "0", "--radius", "26", "--map-width", "128", "--frac-bits", "4",
            "--mip-levels", "4"] in [argv for argv, _ in RUNS]


@pytest.mark.parametrize("argv, lines", RUNS, ids=[" ".join(a) or "defaults" for a, _ in RUNS])
def test_every_quoted_line_is_the_models_output(argv, lines, capsys):
    assert main(argv) == 0                   # no violation of the stated bounds
    printed = capsys.readouterr().out.splitlines()
    missing = [ln for ln in lines if ln not in printed]
    assert not missing, f"`{' '.join(argv)}` does not print: {missing}"
