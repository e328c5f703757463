"""Generated pages record the configuration they were made at, and it is today's default.

Every ``Made at: angle_bits=A, frac_bits=B ...`` line in docs/ and the README must name
today's default Config (rtl/config.Config()): a page generated at other widths is stale,
regenerate it with the command GENERATED names (``make docs`` runs the quick ones). Each
generated page must carry such a line; the pages whose generator does not write one yet are
LACKING, expected failures that turn into failures as soon as the record appears (then
take the page off the list). docs/architecture.md's stated defaults follow Config too.
"""

import re
from pathlib import Path

import pytest

from bumprtl.rtl.config import Config

ROOT = Path(__file__).resolve().parents[1]
MADE_AT = re.compile(r"Made at: angle_bits=(\d+), frac_bits=(\d+)")

# page -> the command that regenerates it
GENERATED = {
    "docs/integration.md": "bumprtl report integration (make docs)",
    "docs/timing.md": "bumprtl report timing (make docs)",
    "docs/table1.md": "bumprtl report table1 --samples 100000 (make docs)",
    "docs/stability.md": "bumprtl bench stress --samples 100000 --seed 1 (make docs)",
    "docs/report.md": "bumprtl report fpga --device LFE5U-85F --samples 100000 --seeds 1,2,3",
    "docs/formal.md": "make formal",
    "docs/mutation.md": "make mutate",
    "docs/scenes.md": "python -m bumprtl.gen.render.rtl --doc docs/scenes.md (make docs)",
    "docs/memory.md": "bumprtl bench memory --doc docs/memory.md",
}
# Generated pages whose generator does not write the record yet.
LACKING = set()


def _pages():
    return sorted([*ROOT.glob("docs/*.md"), ROOT / "README.md"])


def test_every_made_at_line_names_todays_default():
    want = Config()
    stale = []
    for page in _pages():
        for n, line in enumerate(page.read_text().splitlines(), 1):
            for a, b in MADE_AT.findall(line):
                if (int(a), int(b)) != (want.angle_bits, want.frac_bits):
                    cmd = GENERATED.get(str(page.relative_to(ROOT)), "its generator")
                    stale.append(f"{page.relative_to(ROOT)}:{n} made at {a} / {b}, the default is "
                                 f"{want.angle_bits} / {want.frac_bits}: regenerate with {cmd}")
    assert not stale, "\n".join(stale)


def test_the_check_can_fail(tmp_path, monkeypatch):
    page = tmp_path / "docs" / "x.md"
    page.parent.mkdir()
    page.write_text(f"Made at: angle_bits={Config().angle_bits - 1}, frac_bits={Config().frac_bits}\n")
    monkeypatch.setattr(f"{__name__}.ROOT", tmp_path)
    monkeypatch.setattr(f"{__name__}._pages", lambda: [page])
    with pytest.raises(AssertionError, match="regenerate"):
        test_every_made_at_line_names_todays_default()


@pytest.mark.parametrize("page", [pytest.param(p, marks=pytest.mark.xfail(
    reason="its generator does not write a Made at: line yet", strict=True))
    if p in LACKING else p for p in GENERATED])
def test_generated_page_records_its_config(page):
    assert MADE_AT.search((ROOT / page).read_text()), \
        f"{page} has no 'Made at: angle_bits=..., frac_bits=...' line ({GENERATED[page]})"


def test_architecture_states_the_default_widths():
    """docs/architecture.md's 'the defaults are k = ..., B = ... (N-bit angles)' and every
    '(default N bits' follow Config: angle_bits = k + 2."""
    text = (ROOT / "docs" / "architecture.md").read_text()
    cfg = Config()
    m = re.search(r"the defaults are k = (\d+), B = (\d+) \((\d+)-bit\s+angles\)", text)
    assert m, "docs/architecture.md no longer states the defaults as 'k = .., B = .. (..-bit angles)'"
    assert (int(m[1]) + 2, int(m[2]), int(m[3])) == (cfg.angle_bits, cfg.frac_bits, cfg.angle_bits)
    for bits in re.findall(r"\(default (\d+) bits", text):
        assert int(bits) == cfg.angle_bits
    for a, b in re.findall(r"At the defaults \((\d+)-bit angles, B = (\d+)", text):
        assert (int(a), int(b)) == (cfg.angle_bits, cfg.frac_bits)
