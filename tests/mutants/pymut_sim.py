"""pytest plugin of the mutmut record (tests/mutants/pymut.py): hits from subprocesses.

mutmut credits a function to a test when the function's trampoline runs in the pytest
process during that test. A cocotb bench runs in the simulator's process, so the functions
of sim/tb's benches (and whatever they call there) were credited to no test and their
mutants reported "no tests". During the record (``MUTANT_UNDER_TEST=stats``) this plugin
names a hits file in ``PYMUT_SIM_HITS`` (inherited by every subprocess: the simulator's
Python appends to it through tests/mutants/pymut_sitecustomize.py) and, at each test's
teardown, before mutmut's own collector reads them, adds the names the file holds to
mutmut's hits of that test and empties the file.
"""

import os
import tempfile
from pathlib import Path

import pytest


def _recording():
    return os.environ.get("MUTANT_UNDER_TEST") == "stats" and os.environ.get("PYMUT_SIM_HITS")


def pytest_configure(config):
    if os.environ.get("MUTANT_UNDER_TEST") == "stats":
        fd, path = tempfile.mkstemp(prefix="pymut-sim-hits-", suffix=".txt")
        os.close(fd)
        os.environ["PYMUT_SIM_HITS"] = path


def take_hits(path):
    """The function names the hits file holds (each once), the file emptied."""
    p = Path(path)
    names = set(p.read_text().split()) if p.exists() else set()
    p.write_text("")
    return names


@pytest.hookimpl(tryfirst=True)      # before mutmut's StatsCollector reads the hits
def pytest_runtest_teardown(item, nextitem):
    if not _recording():
        return
    from mutmut.state import state
    state()._stats.update(take_hits(os.environ["PYMUT_SIM_HITS"]))


def pytest_unconfigure(config):
    path = os.environ.pop("PYMUT_SIM_HITS", None)
    if path:
        Path(path).unlink(missing_ok=True)
