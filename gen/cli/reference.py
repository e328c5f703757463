"""docs/cli.md: every command and option of ``bumprtl``, written from the parsers themselves
(gen/cli/main.build_parser), so that the page and ``--help`` cannot disagree.

``python -m bumprtl.gen.cli.reference docs/cli.md`` writes the page; with ``--check`` it
writes nothing and exits 1 when the page is not what the parsers say now. Each command is a
section: its one-line help, its description, then a table of its options (flags, the value
they take, their help text as ``--help`` prints it). The page is generated with every extra
installed; a command whose extra is missing is written as a placeholder and refused.
"""

import argparse
import sys
from pathlib import Path

from bumprtl.gen.cli.main import build_parser

__all__ = ["reference", "subcommands", "options", "main"]

HEAD = ("# Command-line reference\n\n"
        "Every command of `bumprtl` and its options, as `bumprtl COMMAND --help` prints them. "
        "Written by `python -m bumprtl.gen.cli.reference docs/cli.md` from the parsers "
        "themselves; tests/gen/cli/test_reference.py fails when this page and the parsers "
        "differ.\n")


def subcommands(parser):
    """``(name, one-line help, parser)`` of each subcommand of ``parser``, in order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, child in action.choices.items():
                yield name, helps.get(name, ""), child


def _own(parser):
    """The options and arguments of ``parser`` itself (not ``--help``, not its subcommands)."""
    return [a for a in parser._actions
            if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))]


def options(parser, path=()):
    """``(command path, action)`` of every option and argument of ``parser`` (path ``()``)
    and of its subcommands, depth first; ``--help`` left out."""
    for action in _own(parser):
        yield path, action
    for name, _help, child in subcommands(parser):
        yield from options(child, (*path, name))


def _cell(text):
    return " ".join(str(text).split()).replace("|", "\\|")


def _value(action):
    """What an option takes: its choices, its metavar or its destination in capitals."""
    if action.nargs == 0:
        return ""
    if action.choices is not None:
        word = "{" + ",".join(map(str, action.choices)) + "}"
    elif isinstance(action.metavar, tuple):
        word = " ".join(action.metavar)
    else:
        word = action.metavar or action.dest.upper()
    return {"+": f"{word} [{word} ...]", "*": f"[{word} ...]", "?": f"[{word}]"}.get(action.nargs, word)


def _section(name, help_text, parser):
    lines = [f"## `{name}`", ""]
    if help_text:
        lines += [_cell(help_text[0].upper() + help_text[1:]) + ".", ""]
    if parser.description and parser.description != help_text:
        lines += [_cell(parser.description), ""]
    rows = []
    for action in _own(parser):
        flags = ", ".join(f"`{f}`" for f in action.option_strings) or f"`{action.dest}`"
        value = _value(action)
        rows.append(f"| {flags} | {'`' + _cell(value) + '`' if value else ''} | {_cell(action.help or '')} |")
    if rows:
        lines += ["| option | takes | what it does |", "| --- | --- | --- |", *rows, ""]
    for child, help_text, child_parser in subcommands(parser):
        lines += _section(f"{name} {child}", help_text, child_parser)
    return lines


def reference():
    """The page's text."""
    parser = build_parser()
    lines = [HEAD, _cell(parser.description), ""]
    commands = list(subcommands(parser))
    lines += ["| command | what it does |", "| --- | --- |"]
    lines += [f"| [`{c}`](#bumprtl-{c}) | {_cell(h)} |" for c, h, _ in commands]
    lines.append("")
    for command, help_text, child in commands:
        lines += _section(f"bumprtl {command}", help_text, child)
    return "\n".join(lines).rstrip() + "\n"


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m bumprtl.gen.cli.reference",
                                description="Write docs/cli.md from the parsers of bumprtl.")
    p.add_argument("page", type=Path, nargs="?", default=Path("docs/cli.md"),
                   help="the page (default: docs/cli.md)")
    p.add_argument("--check", action="store_true",
                   help="write nothing; exit 1 if the page differs from what the parsers say")
    a = p.parse_args(argv)
    text = reference()
    if a.check:
        same = a.page.is_file() and a.page.read_text() == text
        print(f"{a.page}: {'current' if same else 'differs from the parsers; write it again'}")
        return 0 if same else 1
    a.page.write_text(text)
    print(f"wrote {a.page}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
