"""Docstrings and comments state contracts, never a figure measured once.

A clock rate, a run time or a CPU time written in a comment goes stale the day the code
changes; the generated pages in docs/ hold measurements, each with the command that made
it (docs/contributing.md). This test reads every comment and docstring of rtl/, gen/ and
sim/ (tokenize and ast, so string literals that a report writes into a page are not read)
and fails on a measured-looking figure: a decimal MHz, a time in s/ms of CPU, "took N s".
"""

import ast
import io
import re
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("rtl", "gen", "sim")
MEASURED = re.compile(
    r"\b\d+\.\d+ ?MHz"                           # 154.7 MHz (a design's clock is an integer or a
                                                 # standard's, e.g. 25.175, matched below)
    r"|\b\d+(\.\d+)? ?(s|ms|seconds|minutes) of CPU"
    r"|\btook \d+(\.\d+)? ?(s|ms|seconds|minutes)\b"
    r"|\b\d+(\.\d+)? ?ns\b, as the worst path",
    re.I)
# Frequencies that are standards or the board's crystal, not measurements.
STANDARD = re.compile(r"\b(25\.175|74\.25|371\.25|148\.5|125\.875) ?MHz")


def comments_and_docstrings(path):
    text = path.read_text()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT:
            yield tok.start[0], tok.string
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                yield node.body[0].lineno, doc


def findings(paths):
    bad = []
    for path in paths:
        for line, text in comments_and_docstrings(path):
            for m in MEASURED.finditer(STANDARD.sub("", text)):
                bad.append(f"{path.relative_to(ROOT)}:{line}: {m.group(0)!r}")
    return sorted(bad)


def test_no_measured_figure_in_a_comment_or_docstring():
    paths = sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py"))
    assert paths
    assert findings(paths) == []


def test_the_check_sees_a_planted_figure(tmp_path):
    planted = tmp_path / "x.py"
    planted.write_text('"""Runs at 154.7 MHz."""\n\n'
                       "X = 1  # emission took 9.9 s instead of 3.8\n"
                       'Y = "a page may say 154.7 MHz"\n'
                       "# the VESA mode's 25.175 MHz pixel clock is a standard\n")
    global ROOT
    saved, ROOT = ROOT, tmp_path
    try:
        got = findings([planted])
    finally:
        ROOT = saved
    assert got == ["x.py:1: '154.7 MHz'", "x.py:3: 'took 9.9 s'"], got
