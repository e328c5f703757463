"""docs/integration.md, read as its user reads it, without our source: every name it gives
exists and every example it shows runs.

* every dotted ``bumprtl.*`` name (module, function, class, attribute) imports;
* every fenced block says what it is (python, sh, console, verilog, mermaid); every
  ``python`` block runs, its asserts included (the worked example's numbers are recomputed
  by the golden model there), each in a fresh namespace;
* every ``bumprtl COMMAND [SUBCOMMAND] --flag`` in a code span or a sh/console block names a
  command and flags the command-line parser (gen/cli/main.py) has. A command announced
  before it lands is listed in PENDING, and a test fails once it exists (then take it off).

Each check is a function of the page's text, so the planted-error tests feed it a page with
a wrong name, flag, block or fence and watch it complain.
"""

import argparse
import importlib
import re
import shlex
from pathlib import Path

import pytest

from bumprtl.gen.cli.main import build_parser

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "integration.md"
FENCES = {"python": "runs", "sh": "shell", "console": "shell", "verilog": "text",
          "mermaid": "text"}
# Commands the page points at that another change is adding: each must still be missing.
PENDING = set()

_FENCE = re.compile(r"^```(\S*)\n(.*?)^```$", re.S | re.M)
_NAME = re.compile(r"(?<![\w.])bumprtl(?:\.[A-Za-z_]\w*)+")
_CALL = re.compile(r"(?:^|(?<=[\s/(]))bumprtl ((?:[^`\n#])*)")


def fences(text):
    """``[(language, body)]`` of every fenced block."""
    return [(m.group(1), m.group(2)) for m in _FENCE.finditer(text)]


def unresolved_names(text):
    """The dotted ``bumprtl.*`` names of ``text`` that do not import: the longest module
    prefix is imported, the rest looked up as attributes."""
    bad = []
    for name in sorted(set(_NAME.findall(text))):
        parts = name.split(".")
        obj, n = None, len(parts)
        while n > 1:
            try:
                obj = importlib.import_module(".".join(parts[:n]))
                break
            except ImportError:
                n -= 1
        try:
            for attr in parts[n:]:
                obj = getattr(obj, attr)
        except AttributeError:
            obj = None
        if obj is None:
            bad.append(name)
    return bad


def unmarked_fences(text):
    return [f"```{lang or '(none)'}" for lang, _ in fences(text) if lang not in FENCES]


def failing_blocks(text):
    """``[(block number, error)]`` of the python blocks that raise."""
    bad = []
    for k, (lang, body) in enumerate(fences(text)):
        if lang != "python":
            continue
        try:
            exec(compile(body, f"{DOC.name} block {k}", "exec"), {"__name__": f"doc_block_{k}"})
        except Exception as e:             # noqa: BLE001 -- any error of a block is the finding
            bad.append((k, f"{type(e).__name__}: {e}"))
    return bad


def _command_text(text):
    """The code spans outside fences and the lines of the shell blocks."""
    outside = _FENCE.sub("", text)
    spans = re.findall(r"`([^`\n]+)`", outside)
    return spans + [ln for lang, body in fences(text) if FENCES.get(lang) == "shell"
                    for ln in body.splitlines()]


def _subparsers(parser):
    return next((a.choices for a in parser._actions
                 if isinstance(a, argparse._SubParsersAction)), None)


def command_mentions(text):
    """``[(words, [flags])]`` of every ``bumprtl ...`` call in code spans and shell blocks."""
    out = []
    for chunk in _command_text(text):
        for m in _CALL.finditer(chunk):
            words = shlex.split(m.group(1).split("|")[0].split(";")[0])
            out.append((words, [w.split("=")[0] for w in words if w.startswith("--")]))
    return out


def unknown_commands(text, parser=None, pending=frozenset()):
    """``bumprtl`` calls whose command, subcommand or flags the parser lacks (a command in
    ``pending`` is left out)."""
    parser = parser or build_parser()
    bad = []
    for words, flags in command_mentions(text):
        if not words or words[0].startswith("-"):
            bad += [f"bumprtl {' '.join(words)}: {f}" for f in flags
                    if f not in parser._option_string_actions]
            continue
        if words[0] in pending:
            continue
        sub = _subparsers(parser)
        if words[0] not in sub:
            bad.append(f"bumprtl {words[0]}: no such command")
            continue
        p, name = sub[words[0]], words[0]
        nested = _subparsers(p)
        if nested is not None and len(words) > 1 and not words[1].startswith("-"):
            if words[1] not in nested:
                bad.append(f"bumprtl {name} {words[1]}: no such subcommand")
                continue
            p, name = nested[words[1]], f"{name} {words[1]}"
        bad += [f"bumprtl {name}: no flag {f}" for f in flags if f not in p._option_string_actions]
    return bad


@pytest.fixture(scope="module")
def page():
    return DOC.read_text()


def test_every_bumprtl_name_imports(page):
    assert len(_NAME.findall(page)) >= 10             # the page names the API it uses
    assert unresolved_names(page) == []


def test_every_block_is_marked(page):
    assert unmarked_fences(page) == []


def test_every_python_block_runs(page):
    blocks = [b for lang, b in fences(page) if lang == "python"]
    assert any("assert out ==" in b for b in blocks)     # the worked example is one of them
    assert failing_blocks(page) == []


def test_the_packed_words_are_the_examples_fields_at_the_tables_bits(page):
    """The worked example's packed ``i__payload`` / ``o__payload`` words are its codes and
    outputs placed at the port table's bit positions."""
    block = next(b for lang, b in fences(page) if lang == "python" and "assert out ==" in b)
    scope = {}
    exec(compile(block, "worked example", "exec"), scope)
    rows = re.findall(r"^\| `(in|out)_(\w+)` \| \w+ \| (\d+) \| `([io])__payload\[(\d+):(\d+)\]`",
                      page, re.M)
    for side, values in (("i", scope["codes"]), ("o", scope["out"])):
        names = {k.replace(".", "_"): v for k, v in values.items()}
        fields = [(names[name], int(width), int(lo)) for _, name, width, s, _, lo in rows if s == side]
        assert len(fields) == len(values), side
        word = sum((v & ((1 << w) - 1)) << lo for v, w, lo in fields)
        stated = re.search(rf"`{side}__payload` = (\d+)'h([0-9a-f]+)", page)
        assert stated and int(stated.group(2), 16) == word, (side, hex(word))


def test_every_command_and_flag_exists(page):
    mentions = command_mentions(page)
    assert any(w[:2] == ["emit", "pipeline"] and "--ports" in f for w, f in mentions)
    assert unknown_commands(page, pending=PENDING) == []


def test_the_pending_commands_are_still_pending(page):
    """A command of PENDING that the parser now has: take it off PENDING, so that its flags
    are checked too."""
    announced = {w[0] for w, _ in command_mentions(page) if w}
    assert PENDING <= announced
    assert PENDING.isdisjoint(_subparsers(build_parser()))


def test_the_checks_find_planted_errors():
    planted = "\n".join([
        "The encoder is `bumprtl.rtl.methods.encode_pixels`, not `bumprtl.sim.golden.methods.nope`.",
        "Run `bumprtl emit pipeline --ports named --no-such-flag`, `bumprtl report nosuch`,",
        "`bumprtl frobnicate --x` and `bumprtl emit pipeline --load port`.",
        "```", "plain", "```",
        "```python", "assert 1 + 1 == 3", "```",
        "```python", "from bumprtl.rtl.config import Config", "assert Config().angle_bits > 0", "```",
        "```sh", "bumprtl render --rtl --no-such-option", "```", ""])
    assert unresolved_names(planted) == ["bumprtl.rtl.methods.encode_pixels",
                                         "bumprtl.sim.golden.methods.nope"]
    assert unmarked_fences(planted) == ["```(none)"]
    assert [k for k, _ in failing_blocks(planted)] == [1]
    assert sorted(unknown_commands(planted)) == sorted([
        "bumprtl emit: no flag --no-such-flag", "bumprtl report nosuch: no such subcommand",
        "bumprtl frobnicate: no such command", "bumprtl render: no flag --no-such-option"])
    assert unknown_commands(planted.replace("frobnicate", "vectors"), pending={"vectors"}) == [
        e for e in unknown_commands(planted) if "frobnicate" not in e]
