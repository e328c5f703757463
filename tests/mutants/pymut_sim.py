"""pytest plugin of the mutmut record (tests/mutants/pymut.py): hits from subprocesses.

mutmut credits a function to a test when the function's trampoline runs in the pytest
process during that test. A cocotb bench runs in the simulator's process, so the functions
of sim/tb's benches (and whatever they call there) were credited to no test and their
mutants reported "no tests". During the record (``MUTANT_UNDER_TEST=stats``) this plugin
names a hits file in ``PYMUT_SIM_HITS`` (inherited by every subprocess: the simulator's
Python appends to it through tests/mutants/pymut_sitecustomize.py) and, at each test's
teardown, before mutmut's own collector reads them, adds the names the file holds to
mutmut's hits of that test and empties the file. It also credits what the set-up of a
fixture wider than a test hit to every test that uses that fixture, not only to the first
(in whose set-up it ran).
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


# What the set-up of each fixture wider than a test (module, class, package, session scope)
# hit, by fixture definition: mutmut credits a function to the test in whose protocol its
# trampoline runs, so what a module fixture calls was credited to the first test using it
# only, and a mutant there ran only that test (seed 33: a table the module's fixture writes,
# checked by another test of the module, survived).
_FIXTURE_HITS = {}


@pytest.hookimpl(hookwrapper=True)
def pytest_fixture_setup(fixturedef, request):
    if not _recording() or fixturedef.scope == "function":
        yield
        return
    from mutmut.state import state
    before = set(state()._stats)
    yield
    hits = (set(state()._stats) - before) | take_hits(os.environ["PYMUT_SIM_HITS"])
    state()._stats.update(hits)
    _FIXTURE_HITS[id(fixturedef)] = hits


def fixture_hits(item, hits_by_def=_FIXTURE_HITS):
    """The names the set-ups of ``item``'s wider-scoped fixtures hit (wherever they ran)."""
    out = set()
    for defs in getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {}).values():
        for fixturedef in defs:
            out |= hits_by_def.get(id(fixturedef), set())
    return out


@pytest.hookimpl(tryfirst=True)      # before mutmut's StatsCollector reads the hits
def pytest_runtest_teardown(item, nextitem):
    if not _recording():
        return
    from mutmut.state import state
    state()._stats.update(take_hits(os.environ["PYMUT_SIM_HITS"]))
    state()._stats.update(fixture_hits(item))


def pytest_unconfigure(config):
    path = os.environ.pop("PYMUT_SIM_HITS", None)
    if path:
        Path(path).unlink(missing_ok=True)
