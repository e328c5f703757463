"""The mutation check's own tests (tests/mutants/curated.py, ``make mutate``): the curated list
parses and every mutant still applies to the code as it stands, every unit and shared helper
has one, a mutant is restored byte for byte (also after an exception), and the runner tells a
killed mutant from a survivor on a tiny project of its own."""

import hashlib
import re

import pytest

from tests.mutants import curated as mutate
from tests.mutants.curated import (
    Edit,
    Mutant,
    MutantError,
    RestoreError,
    applied,
    check_applies,
    load_mutants,
    markdown,
    run_mutants,
)

ROOT = mutate.ROOT
# Every unit and every shared helper has at least one mutant (the file it edits).
COVERED = ("rtl/sincos.py", "rtl/exact.py", "rtl/lee.py", "rtl/baselines/peercy.py",
           "rtl/baselines/kim.py", "rtl/palette.py", "rtl/bumpfetch.py", "rtl/texture.py",
           "rtl/pipeline.py", "rtl/shade.py", "rtl/pipe.py", "rtl/fixed.py", "rtl/tables.py",
           "gen/flow/resources.py", "rtl/config.py", "sim/scenes/config.py", "rtl/targets.py",
           "rtl/ecp5.py")


@pytest.fixture(scope="module")
def mutants():
    return load_mutants(ROOT / mutate.DEFAULT_LIST)


def test_every_mutant_applies_to_the_code_as_it_stands(mutants):
    """Each original text occurs exactly once in its file (else: update the list)."""
    for m in mutants:
        check_applies(m, ROOT)
    assert len({m.id for m in mutants}) == len(mutants)


def test_every_guard_names_an_existing_test(mutants):
    for m in mutants:
        for guard in m.guards:
            path, _, node = guard.partition("::")
            assert (ROOT / path).is_file(), (m.id, guard)
            if node:
                name = re.match(r"\w+", node).group()
                assert re.search(rf"^def {name}\(", (ROOT / path).read_text(), re.M), (m.id, guard)


def test_every_unit_and_helper_has_a_mutant(mutants):
    files = {e.file for m in mutants if not m.equivalent for e in m.edits}
    assert set(COVERED) <= files, set(COVERED) - files
    assert any(m.equivalent for m in mutants)          # the format's third case is in use


@pytest.mark.parametrize("text, message", [
    ('[[mutant]]\nid = "a"\nmodels = "x"\nfile = "f"\noriginal = "o"\nreplacement = "r"\n',
     "no guards"),
    ('[[mutant]]\nid = "a"\nmodels = "x\\ny"\nfile = "f"\noriginal = "o"\nreplacement = "r"\n'
     'guards = ["t"]\n', "one line"),
    ('[[mutant]]\nid = "a"\nmodels = "x"\nfile = "f"\noriginal = "o"\nreplacement = "o"\n'
     'guards = ["t"]\n', "equals original"),
    ('[[mutant]]\nid = "a"\nmodels = "x"\nfile = "f"\noriginal = "o"\nreplacement = "r"\n'
     'guards = ["t"]\ncolour = 1\n', "unknown key"),
    ('', "no [[mutant]]"),
])
def test_bad_list_is_refused_in_one_line(text, message):
    with pytest.raises(MutantError, match=re.escape(message)) as e:
        load_mutants(text=text)
    assert "\n" not in str(e.value)


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_apply_and_restore_byte_for_byte(tmp_path):
    f = tmp_path / "m.py"
    f.write_text("def f(x):\n    return (x + 1) >> 1\n")
    before = _sha(f)
    m = Mutant("t", "x", ("t",), (Edit("m.py", "(x + 1) >> 1", "x >> 1"),))
    with applied(m, tmp_path):
        assert f.read_text() == "def f(x):\n    return x >> 1\n"
    assert _sha(f) == before
    with pytest.raises(ZeroDivisionError):
        with applied(m, tmp_path):
            _ = 1 / 0
    assert _sha(f) == before


def test_an_edit_by_someone_else_is_kept_and_reported(tmp_path):
    f = tmp_path / "m.py"
    f.write_text("a = 1\nb = 2\n")
    m = Mutant("t", "x", ("t",), (Edit("m.py", "b = 2", "b = 3"),))
    with pytest.raises(RestoreError, match="m.py"):
        with applied(m, tmp_path):
            f.write_text(f.read_text().replace("a = 1", "a = 10"))
    assert f.read_text() == "a = 10\nb = 2\n"


@pytest.mark.parametrize("text, found", [("x = 1\n", "no longer occurs"), ("y = 2\ny = 2\n", "occurs 2 times")])
def test_an_original_text_not_found_once_names_the_file(tmp_path, text, found):
    (tmp_path / "m.py").write_text(text)
    m = Mutant("t", "x", ("t",), (Edit("m.py", "y = 2", "y = 3"),))
    with pytest.raises(MutantError, match=f"{found} in m.py"):
        check_applies(m, tmp_path)


def test_runner_kills_survives_and_reports(tmp_path):
    """A tiny project: one mutant its test catches, one it cannot see, one equivalent, one
    whose text is gone."""
    (tmp_path / "halve.py").write_text("def halve(x):\n    return (x + 1) // 2\n\n\nUNUSED = 1\n")
    (tmp_path / "test_halve.py").write_text(
        "from halve import halve\n\n\ndef test_rounds_up():\n    assert halve(3) == 2\n")
    edit = lambda a, b: (Edit("halve.py", a, b),)
    mutants = [Mutant("killed", "x", ("test_halve.py",), edit("(x + 1) // 2", "x // 2")),
               Mutant("survived", "x", ("test_halve.py",), edit("UNUSED = 1", "UNUSED = 2")),
               Mutant("equivalent", "x", (), edit("UNUSED = 1", "UNUSED = 3"), "never read"),
               Mutant("gone", "x", ("test_halve.py",), edit("x * 2", "x * 3"))]
    before = _sha(tmp_path / "halve.py")
    lines = []
    outcomes = run_mutants(mutants, tmp_path, timeout=120, progress=lambda *a, **k: lines.append(a))
    assert [o.status for o in outcomes] == ["killed", "survived", "equivalent", "error"]
    assert "no longer occurs" in outcomes[3].detail and _sha(tmp_path / "halve.py") == before
    assert len(lines) == 2 * len(mutants)                    # a progress line per mutant
    table = markdown(outcomes, "make mutate", 1.0)
    assert "1 of 3 mutants killed" in table and "| `survived` |" in table
