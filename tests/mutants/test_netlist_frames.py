"""The netlist mutants' stimulus descriptions (tests/mutants/netlist.py) say which suite
streams each built-in scene's coverage frame: held here to the markers of the tests that
stream them, so that moving a scene's test between make test and make regress cannot leave
docs/mutation.md naming the wrong one."""

import importlib.util
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import netlist  # noqa: E402


def _scene_params():
    """{scene: True when make test runs it} of the file's coverage-frame tests (the
    built-in scenes' and the palette scenes')."""
    path = HERE.parent / "sim" / "tb" / "test_bulk_scene_frames.py"
    spec = importlib.util.spec_from_file_location("bulk_scene_frames_markers", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = {}
    for mark in (*mod.test_scene_coverage_frame_equals_golden.pytestmark,
                 *mod.test_bulk_palette_frame_equals_golden.pytestmark):
        if mark.name != "parametrize":
            continue
        for p in mark.args[1]:
            values, marks = (p.values, p.marks) if hasattr(p, "values") else ((p,), ())
            out[values[0]] = not any(m.name == "regress" for m in marks)
    return out


def test_the_frames_named_for_make_test_are_make_tests():
    params = _scene_params()
    bulk = "tests/sim/tb/test_bulk_scene_frames.py"
    for name, where in netlist.MAKE_TEST_FRAMES.items():
        if where == bulk:
            assert params.get(name) is True, f"{name}: not streamed by make test in {bulk}"
    for name, where in netlist.REGRESS_FRAMES.items():
        assert where == bulk and params.get(name) is False, f"{name}: not make regress's"
    # every built-in scene the tests stream is named, in the suite that streams it
    for name, in_make_test in params.items():
        if name == "palette-textured":          # a scene of the test's own, no netlist target
            continue
        named = netlist.MAKE_TEST_FRAMES if in_make_test else netlist.REGRESS_FRAMES
        assert named.get(name) == bulk, name


@pytest.mark.parametrize("name, suite", [("full", "make test"), ("flat", "make test"),
                                          ("textured", "make regress")])
def test_the_stimulus_names_the_suite(name, suite):
    text = netlist._stimulus_words(f"pipeline:{name}", 0, "icarus")
    assert f"as {suite} streams it through the {name} scene" in text
