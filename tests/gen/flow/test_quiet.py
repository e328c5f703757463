"""gen/flow/quiet.tool_log: the tools' output (this process and its children) goes to the
log, the terminal gets the label; on a failure the log is shown in full; --verbose lets
everything through."""

import subprocess
import sys

import pytest

from bumprtl.gen.flow.quiet import tool_log

_CHILD = """
import subprocess, sys
from pathlib import Path
from bumprtl.gen.flow.quiet import tool_log
log, fail, verbose = Path(sys.argv[1]), sys.argv[2] == "1", sys.argv[3] == "1"
print("before")
with tool_log(log, "working", verbose):
    print("python says hello")
    subprocess.run(["sh", "-c", "echo g++ -O2 from a child; echo banner >&2"])
    if fail:
        raise SystemExit(3)
print("after")
"""


def _run(tmp_path, fail, verbose=False):
    return subprocess.run([sys.executable, "-c", _CHILD, str(tmp_path / "t.log"), str(int(fail)),
                           str(int(verbose))], capture_output=True, text=True)


def test_tool_output_goes_to_the_log(tmp_path):
    r = _run(tmp_path, fail=False)
    assert r.returncode == 0
    assert "g++" not in r.stdout + r.stderr and "hello" not in r.stdout and "banner" not in r.stderr
    assert r.stdout.startswith("before\n") and r.stdout.rstrip().endswith("after")
    assert f"working (tool output: {tmp_path / 't.log'})" in r.stderr   # progress: stderr
    log = (tmp_path / "t.log").read_text()
    assert "python says hello" in log and "g++ -O2 from a child" in log and "banner" in log


def test_a_failure_shows_the_log_in_full(tmp_path):
    r = _run(tmp_path, fail=True)
    assert r.returncode == 3
    assert "g++ -O2 from a child" in r.stderr and "banner" in r.stderr and "hello" in r.stderr


def test_verbose_lets_everything_through(tmp_path):
    r = _run(tmp_path, fail=False, verbose=True)
    assert "g++ -O2 from a child" in r.stdout and "banner" in r.stderr
    assert not (tmp_path / "t.log").exists()


_PY = """
import subprocess, sys
from pathlib import Path
from bumprtl.gen.flow.quiet import tool_log
with tool_log(Path(sys.argv[1]), "bench x", python=True):
    print("| header |")
    print("progress", file=sys.stderr)
    subprocess.run(["sh", "-c", "echo g++ -O2 from a child; echo banner >&2"])
print("after")
"""


def test_python_mode_keeps_the_table_on_the_terminal(tmp_path):
    """A bench's table (print) and progress (sys.stderr) reach the terminal; only the child
    processes' output goes to the log."""
    r = subprocess.run([sys.executable, "-c", _PY, str(tmp_path / "b.log")], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout == "| header |\nafter\n"
    assert "progress" in r.stderr and "g++" not in r.stdout + r.stderr and "banner" not in r.stderr
    log = (tmp_path / "b.log").read_text()
    assert "g++ -O2 from a child" in log and "banner" in log and "header" not in log


_CMD = """
import argparse, subprocess, sys
from bumprtl.gen.cli.quiet import quiet_commands
p = argparse.ArgumentParser()
kinds = p.add_subparsers(dest="kind")
k = kinds.add_parser("work")
k.set_defaults(func=lambda a: print("| table |") or subprocess.run(["sh", "-c", "echo yosys says"]).returncode)
quiet_commands(kinds, sys.argv[1])
args = p.parse_args(sys.argv[2:])
sys.exit(args.func(args))
"""


@pytest.mark.parametrize("verbose", [False, True])
def test_quiet_commands_wrap_every_subcommand(tmp_path, verbose):
    r = subprocess.run([sys.executable, "-c", _CMD, str(tmp_path / "logs"), "work",
                        *(["--verbose"] if verbose else [])], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "| table |" in r.stdout
    assert ("yosys says" in r.stdout) == verbose
    assert (tmp_path / "logs" / "work.log").exists() != verbose


def test_python_mode_leaves_a_tests_capture_alone(tmp_path, capsys):
    """Under pytest's capsys (sys.stdout not on fd 1) the table still reaches the capture."""
    with tool_log(tmp_path / "c.log", "bench y", python=True):
        print("| captured |")
        subprocess.run(["sh", "-c", "echo child"])
    out = capsys.readouterr()
    assert "| captured |" in out.out and "child" not in out.out
    assert "child" in (tmp_path / "c.log").read_text()
