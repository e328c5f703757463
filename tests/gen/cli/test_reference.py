"""docs/cli.md is what the parsers say: every command, its description and every option's
flags, value and help text (gen/cli/reference.py). A help text changed without writing the
page again, or a page edited by hand, fails here."""

import re
from pathlib import Path

from bumprtl.gen.cli.main import build_parser
from bumprtl.gen.cli.reference import main, reference, subcommands

PAGE = Path(__file__).resolve().parents[3] / "docs" / "cli.md"


def test_the_page_is_what_the_parsers_say():
    assert PAGE.read_text() == reference(), \
        "docs/cli.md is stale: python -m bumprtl.gen.cli.reference docs/cli.md"


def test_every_command_and_subcommand_has_a_section_and_the_index_links_resolve():
    text = PAGE.read_text()
    headings = re.findall(r"^## `(bumprtl[^`]*)`$", text, flags=re.M)
    for command, _help, child in subcommands(build_parser()):
        assert f"bumprtl {command}" in headings
        assert f"](#bumprtl-{command})" in text
        assert {f"bumprtl {command} {k}" for k, _h, _p in subcommands(child)} <= set(headings)
    assert len(headings) == len(set(headings))


def test_every_option_appears_in_its_commands_table():
    text = PAGE.read_text()
    sections = dict(re.findall(r"^## `(bumprtl[^`]*)`\n(.*?)(?=^## |\Z)", text, flags=re.M | re.S))
    emit = sections["bumprtl emit"]
    for flag in ("--name", "--interface", "--ports", "--load", "--fusesoc", "--out"):
        assert re.search(rf"^\| `{flag}`", emit, flags=re.M), flag
    assert "| `--palettes` | `PALETTES [PALETTES ...]` |" in sections["bumprtl bench palette"]
    assert "`{verilator,icarus}`" in sections["bumprtl demo"]


def test_check_says_current_or_stale_and_writes_nothing(tmp_path, capsys):
    page = tmp_path / "cli.md"
    assert main([str(page), "--check"]) == 1 and not page.exists()
    assert capsys.readouterr().out == f"{page}: differs from the parsers; write it again\n"
    assert main([str(page)]) == 0 and page.read_text() == reference()
    assert capsys.readouterr().out == f"wrote {page}\n"
    assert main([str(page), "--check"]) == 0
    assert capsys.readouterr().out == f"{page}: current\n"
    page.write_text(page.read_text().replace("output directory", "output folder", 1))
    before = page.read_text()
    assert main([str(page), "--check"]) == 1
    assert page.read_text() == before
    assert "differs from the parsers" in capsys.readouterr().out
