"""make mutate-py's draw (tests/mutants/pymut.py) covers every package: each Python file of
rtl/, gen/ and sim/ that defines a function is mutated (MUTATE) and falls in a named area (AREAS, never "other"),
every area holds a file, the stratified draw gives each area its floor, and
docs/mutation.md lists the areas the tool draws from."""

import fnmatch
import re
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pymut  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _modules():
    """{repository path: the mutant-name prefix mutmut gives its functions}."""
    out = {}
    for top in ("rtl", "gen", "sim"):
        for f in sorted((ROOT / top).rglob("*.py")):
            if not re.search(r"^\s*(async )?def ", f.read_text(), re.M):
                continue                      # no function: mutmut makes no mutant of it
            rel = f.relative_to(ROOT)
            mod = "bumprtl." + ".".join(rel.with_suffix("").parts)
            out[str(rel)] = mod.removesuffix(".__init__") + ".x_f__mutmut_1"
    return out


def test_every_file_of_the_three_packages_is_mutated_and_in_a_named_area():
    mods = _modules()
    assert len(mods) > 50, "the packages were not found"
    for path, name in mods.items():
        as_mutmut = "bumprtl/" + path      # the layout mutmut's copy has (pymut.lay_out)
        assert any(fnmatch.fnmatch(as_mutmut, g) for g in pymut.MUTATE), f"{path} is not mutated"
        assert pymut.area(name) != "other", f"{path} is in no area"
    used = Counter(pymut.area(n) for n in mods.values())
    assert set(used) == set(pymut.AREAS), f"areas holding no file: {set(pymut.AREAS) - set(used)}"


def test_the_draw_gives_every_area_its_floor():
    names = [f"{prefix}x_f__mutmut_{i}" for label, prefix in pymut.AREAS.items()
             for i in range(1, (200 if label == "sim/golden" else 12) + 1)]
    sample = pymut.draw(names, 160, 7, 5)
    assert len(sample) == 160 and len(set(sample)) == 160
    got = Counter(pymut.area(n) for n in sample)
    assert all(got[l] >= 5 for l in pymut.AREAS), got
    assert sample == pymut.draw(names, 160, 7, 5)              # the seed fixes the draw
    assert sample != pymut.draw(names, 160, 8, 5)


def test_docs_list_the_areas():
    text = (ROOT / "docs" / "mutation.md").read_text()
    line = next((l for l in text.splitlines() if l.startswith("Areas of `make mutate-py`")), None)
    assert line is not None, "docs/mutation.md has no line 'Areas of `make mutate-py` ...'"
    assert re.findall(r"`([^`]+)`", line)[1:] == list(pymut.AREAS)


def test_the_draw_runs_make_tests_tests_but_the_toolings_own():
    """Every test file of make test is in the selection mutmut picks each mutant's tests from
    (pymut.TESTS), but tests/mutants and tests/tools, which check this tooling, not the
    package: a mutant only those tests would kill counts as a survivor."""
    files = {str(f.relative_to(ROOT)) for f in (ROOT / "tests").rglob("test_*.py")}
    covered = {f for f in files if any(f == t or f.startswith(t + "/") for t in pymut.TESTS)}
    left = {f for f in files - covered if not f.startswith(("tests/mutants/", "tests/tools/"))}
    assert not left, f"test files outside pymut.TESTS: {sorted(left)}"
    assert all((ROOT / t).exists() for t in pymut.TESTS)
