"""A second commit laid over a copy mutmut has mutated (tests/mutants/pymut.update_tree):
only the files the commit changed are made newer than their mutated copies (mutmut mutates
a file again when its source is newer), a file the commit removed goes from both copies,
and the old commit's results and test record are dropped while its mutant names stay."""

import json
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pymut  # noqa: E402

OLD = 1_000_000_000.0            # the first layout's times, long before the update


def _commit(src, files):
    for name, text in files.items():
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        (src / name).write_text(text)
    (src / "tests" / "mutants").mkdir(parents=True, exist_ok=True)
    for name in pymut.SIM_RECORD:
        (src / "tests" / "mutants" / name).write_text("# record\n")
    return sorted(files) + [f"tests/mutants/{n}" for n in pymut.SIM_RECORD]


def test_update_touches_only_what_the_commit_changed(tmp_path):
    first = {"rtl/a.py": "def f():\n    return 1\n", "rtl/b.py": "def g():\n    return 2\n",
             "sim/w.v": "module w; endmodule\n",
             "sim/c.py": "def h():\n    return 3\n", "tests/test_a.py": "def test_a():\n    pass\n"}
    src, tree = tmp_path / "src", tmp_path / "out" / "tree"
    pymut.lay_out(tree, src, _commit(src, first))
    mutants = tree / "mutants" / "bumprtl"
    (tree / "setup.cfg").write_text("[mutmut]\n")
    for f in [p for p in tree.rglob("*") if p.is_file()]:
        os.utime(f, (OLD, OLD))
    for name in ("rtl/a.py", "rtl/b.py", "sim/c.py"):      # mutmut's copies and results
        path = mutants / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("mutated\n")
        meta = {"exit_code_by_key": {f"bumprtl.{name[:-3].replace('/', '.')}.x_f__mutmut_1": 1},
                "hash_by_function_name": {"x_f": "h"}}
        Path(f"{path}.meta").write_text(json.dumps(meta))
    (mutants / "sim" / "w.v").write_text(first["sim/w.v"])            # copied when made
    (tree / "mutants" / "mutmut-stats.json").write_text("{}")

    second = {**first, "rtl/a.py": "def f():\n    return 5\n", "gen/d.py": "def k():\n    return 4\n",
              "sim/w.v": "module w(input a); endmodule\n"}
    del second["sim/c.py"]
    src2 = tmp_path / "src2"
    files = _commit(src2, second)
    for f in [p for p in src2.rglob("*") if p.is_file()]:
        os.utime(f, (OLD - 10, OLD - 10))      # git archive's times: the commit's, maybe older
    changed = pymut.update_tree(tree, src2, files)

    assert sorted(changed) == ["bumprtl/gen/d.py", "bumprtl/rtl/a.py", "bumprtl/sim/c.py (removed)",
                               "bumprtl/sim/w.v"]
    newer = {str(p.relative_to(tree)) for p in tree.rglob("*")
             if p.is_file() and "mutants" not in p.parts and p.stat().st_mtime > OLD}
    assert newer == {"bumprtl/gen/d.py", "bumprtl/rtl/a.py", "bumprtl/sim/w.v"}
    # mutmut does not copy a file it does not mutate again: the runner puts it there
    assert (mutants / "sim" / "w.v").read_text() == second["sim/w.v"]
    assert (tree / "bumprtl" / "rtl" / "a.py").read_text() == second["rtl/a.py"]
    assert not (tree / "bumprtl" / "sim" / "c.py").exists()
    assert not (mutants / "sim" / "c.py").exists() and not (mutants / "sim" / "c.py.meta").exists()
    assert (mutants / "rtl" / "b.py").read_text() == "mutated\n"          # unchanged: kept
    assert (tree / "setup.cfg").read_text() == "[mutmut]\n"               # mutmut's own: kept
    assert not (tree / "mutants" / "mutmut-stats.json").exists()
    assert not (tree.parent / "tree.new").exists()
    kept = json.loads((mutants / "rtl" / "b.py.meta").read_text())
    assert kept["exit_code_by_key"] == {"bumprtl.rtl.b.x_f__mutmut_1": None}
    assert kept["hash_by_function_name"] == {"x_f": "h"}
    assert pymut.all_results(tree) == {"bumprtl.rtl.a.x_f__mutmut_1": None,
                                       "bumprtl.rtl.b.x_f__mutmut_1": None}
