"""The coverage frame (sim/tb/bulk_frame.py) through the pipelines of the built-in scenes
that no other test of make test streams it through: ``diffuse`` (no specular term),
``flat`` (no map: the polygon registers), ``textured`` (the colour texture blended with the
shading) and ``two-lights`` (two illumination units and their sum). The default and palette
scenes stream it in tests/sim/tb/test_bulk.py, the full scene in
tests/sim/tb/test_tb_pipeline.py (every cycle from cocotb). This is the frame and the four
traffic patterns the netlist mutants of these scenes run (tests/mutants/netlist.py), so a
mutant that frame kills is killed by make test."""

import json

import numpy as np
import pytest

from bumprtl.gen.render.rtl import emit_pipeline, scene_stimulus, scene_texels
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk import run_bulk
from bumprtl.sim.tb.bulk_frame import coverage_frame
from bumprtl.sim.traffic import PATTERNS

TRAFFIC = tuple(PATTERNS)


@pytest.mark.parametrize("name", ["diffuse", "flat", "textured", "two-lights"])
def test_scene_coverage_frame_equals_golden(name, build_dir):
    scene = load_scene_config(name)
    _, words, _, table, base = scene_stimulus(scene, 16)
    texels = scene_texels(scene, base)
    v, j = emit_pipeline(scene, words, texels, build_dir, None)
    meta = json.loads(j.read_text())
    frame = coverage_frame(scene, words, texels)
    golden = frame.expected(meta)
    assert set(golden) == set(meta["ports"]["o__payload"]["fields"])
    r = run_bulk("icarus", v, j, build_dir / "bulk", TRAFFIC, inputs=frame.inputs,
                 expected=golden, setup=frame.setup(meta))
    assert r.checked
    for pattern in TRAFFIC:
        assert r.pixels[pattern] == len(frame.inputs["tag"]), pattern
        assert np.array_equal(r.outputs[pattern]["tag"], frame.inputs["tag"]), pattern
        for field, want in golden.items():
            assert np.array_equal(r.outputs[pattern][field], want), (pattern, field)
