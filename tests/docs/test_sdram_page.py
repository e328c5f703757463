"""docs/sdram.md's read bandwidth is what ``python -m bumprtl.sim.sdram_bench`` prints: the
table's three numbers for the default part, and the 64 MB part's sentence for the command
named in it (the SDRAM controller on the chip's model in the Amaranth simulator)."""

import re
from pathlib import Path

import pytest

from bumprtl.sim.sdram_bench import main

PAGE = Path(__file__).resolve().parents[2] / "docs" / "sdram.md"


def printed(argv, capsys):
    """(hit, miss, latency) as the bench prints them."""
    main(argv)
    out = capsys.readouterr().out
    hit = re.search(r"lines in one open row: +([\d.]+) cycles per 16 bytes", out).group(1)
    miss = re.search(r"each line in a new row \(miss\): ([\d.]+) cycles per 16 bytes", out).group(1)
    latency = re.search(r"first AR to its first R beat: (\d+) cycles", out).group(1)
    return hit, miss, latency


def section():
    text = PAGE.read_text()
    return text[text.index("## Read bandwidth"):text.index("\n## ", text.index("## Read bandwidth") + 3)]


def test_the_table_is_the_default_run(capsys):
    page = section()
    assert "`python -m bumprtl.sim.sdram_bench` (Amaranth simulator" in page
    assert "| 32 MB, 100 MHz, CL 2, burst 8, 32-bit AXI | cycles per 16 bytes |" in page
    hit, miss, latency = printed([], capsys)
    assert f"| lines in one open row (row hits) | {hit} |" in page
    assert f"| each line in another row of the same bank (a miss a line) | {miss} |" in page
    assert f"| first AR to its first R beat, row closed | {latency} cycles |" in page


@pytest.mark.parametrize("argv", [["--variant", "64mb", "--freq-mhz", "133", "--cas-latency", "3"]])
def test_the_64mb_sentence_is_its_run(argv, capsys):
    page = " ".join(section().split())
    hit, miss, latency = printed(argv, capsys)
    claim = (f"gives {hit} and {miss} cycles and {latency} cycles of latency (CL 3: one more) "
             f"(`python -m bumprtl.sim.sdram_bench {' '.join(argv)}`)")
    assert claim in page
