"""The mutmut record follows the cocotb benches into the simulator's Python
(tests/mutants/pymut_sim.py, pymut_sitecustomize.py): a trampoline's hit in another
process lands in the hits file, the plugin hands the file's names over once, and the runner
lays both files out where the simulator's Python and mutmut's pytest find them."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pymut  # noqa: E402
import pymut_sim  # noqa: E402

HERE = Path(__file__).resolve().parent
PROBE = ("import mutmut.mutation.trampoline as t, mutmut.stats as s\n"
         "if t.record_trampoline_hit is s.record_trampoline_hit: print('unpatched')\n"
         "else: t.record_trampoline_hit('bumprtl.sim.tb.tb_x.x_model', caller='c')\n")


def _probe(tmp_path, mode):
    site = tmp_path / "site"
    site.mkdir(exist_ok=True)
    shutil.copy(HERE / "pymut_sitecustomize.py", site / "sitecustomize.py")
    hits = tmp_path / "hits.txt"
    env = {k: v for k, v in os.environ.items() if k not in ("MUTANT_UNDER_TEST", "PYMUT_SIM_HITS")}
    env.update(PYTHONPATH=str(site), PYMUT_SIM_HITS=str(hits), MUTANT_UNDER_TEST=mode)
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout
    return out, hits.read_text() if hits.exists() else ""


def test_a_hit_in_another_process_lands_in_the_file(tmp_path):
    out, hits = _probe(tmp_path, "stats")
    assert out == "" and hits.split() == ["bumprtl.sim.tb.tb_x.x_model"]


def test_outside_the_record_nothing_is_patched(tmp_path):
    # a mutant's run: the trampolines must stay mutmut's own
    out, hits = _probe(tmp_path, "bumprtl.sim.tb.tb_x.x_model__mutmut_3")
    assert out.strip() == "unpatched" and hits == ""


def test_hits_are_handed_over_once(tmp_path):
    f = tmp_path / "hits.txt"
    f.write_text("a.x_f\nb.x_g\na.x_f\n")
    assert pymut_sim.take_hits(f) == {"a.x_f", "b.x_g"}
    assert pymut_sim.take_hits(f) == set() and f.read_text() == ""
    assert pymut_sim.take_hits(tmp_path / "none.txt") == set()


def test_the_runner_lays_the_recorder_out(tmp_path):
    src = tmp_path / "src"
    files = ["rtl/config.py", *[f"tests/mutants/{n}" for n in pymut.SIM_RECORD]]
    for name in files:
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(HERE.parents[1] / name, src / name)
    dest = tmp_path / "tree"
    pymut.lay_out(dest, src, files)
    assert (dest / "sitecustomize.py").read_text() == (HERE / "pymut_sitecustomize.py").read_text()
    assert (dest / "pymut_sim.py").read_text() == (HERE / "pymut_sim.py").read_text()
    assert not (dest / "tests" / "mutants").exists()
    pymut.configure(dest, [])
    cfg = (dest / "setup.cfg").read_text().splitlines()
    args = cfg[cfg.index("pytest_add_cli_args =") + 1:]
    assert ["    -p", "    pymut_sim"] == [a for a in args if a.strip() in ("-p", "pymut_sim")][-2:]
    copied = cfg[cfg.index("also_copy =") + 1:]
    assert "    sitecustomize.py" in copied and "    pymut_sim.py" in copied


PROJECT = {
    "conftest.py": (
        "import json, os\n"
        "from mutmut.state import state\n"
        "CREDITS = {}\n"
        "def pytest_runtest_teardown(item, nextitem):\n"      # mutmut's StatsCollector, in short
        "    CREDITS[item.name] = sorted(state()._stats)\n"
        "    state()._stats.clear()\n"
        "def pytest_sessionfinish(session):\n"
        "    open(os.environ['CREDITS_OUT'], 'w').write(json.dumps(CREDITS))\n"),
    "test_m.py": (
        "import pytest\n"
        "from mutmut.state import state\n"
        "@pytest.fixture(scope='module')\n"
        "def table():\n"
        "    state()._stats.add('pkg.x_write_table')\n"      # a trampoline's hit in the set-up
        "    return 1\n"
        "def test_first(table):\n"
        "    state()._stats.add('pkg.x_first')\n"
        "def test_second(table):\n"
        "    pass\n"
        "def test_without(tmp_path):\n"
        "    pass\n"),
}


def test_what_a_module_fixture_calls_is_credited_to_every_test_using_it(tmp_path):
    """mutmut credits a hit to the test in whose protocol it happens: a module fixture's
    set-up runs in its first test's. The plugin credits it to each test that uses the
    fixture (test_second too), and to no other."""
    for name, text in PROJECT.items():
        (tmp_path / name).write_text(text)
    env = {k: v for k, v in os.environ.items() if k not in ("PYMUT_SIM_HITS",)}
    env.update(MUTANT_UNDER_TEST="stats", CREDITS_OUT=str(tmp_path / "credits.json"),
               PYTHONPATH=str(HERE))
    subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p",
                    "no:xdist", "-p", "pymut_sim", "test_m.py"], cwd=tmp_path, env=env,
                   check=True, capture_output=True, text=True)
    import json
    credits = json.loads((tmp_path / "credits.json").read_text())
    assert credits == {"test_first": ["pkg.x_first", "pkg.x_write_table"],
                       "test_second": ["pkg.x_write_table"], "test_without": []}
