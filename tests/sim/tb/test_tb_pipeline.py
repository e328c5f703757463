"""The emitted pipeline under cocotb: a small render equals the fixed-point golden render
byte for byte, one pixel per clock without stalls, and under random backpressure and input
gaps every pixel comes out once, in order, bit-exact. One build per simulator."""

import numpy as np
import pytest

from bumprtl.gen.render.rtl import (golden_render, render_rtl, run_pipeline, scene_stimulus,
                                    scene_texels)
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.traffic import PATTERNS


# make test: the full scene on Icarus (a build costs little there); the default scene's
# per-cycle run is in make regress, since make test streams that scene's pipeline on Icarus
# under the same traffic patterns through the bulk path (tests/sim/tb/test_bulk.py: the
# coverage frame, then this render frame); make regress: the full scene's build on Verilator
# too (a minute of C++ compilation for 768 pixels).
@pytest.mark.parametrize("sim, name", [("icarus", "full"),
                                       pytest.param("icarus", "default", marks=pytest.mark.regress),
                                       pytest.param("verilator", "full", marks=pytest.mark.regress)])
def test_pipeline_stream_cocotb(sim, name, build_dir):
    """``full``: two lights, mip levels and the colour texture (RGB out)."""
    scene = load_scene_config(name)
    inputs, words, polygon, table, base = scene_stimulus(scene, 16)
    texels = scene_texels(scene, base)
    outs, cycles, _ = run_pipeline(scene, inputs, words, polygon, table, sim, build_dir,
                                   patterns=list(PATTERNS), progress=False, texels=texels)
    golden = pipeline_fixed(inputs, scene, words, polygon, texels)
    assert ("color.r" in golden) == scene.texture
    n = len(inputs["tag"])
    latency = scene_latency(build_dir)
    for pattern in PATTERNS:
        out = outs[pattern]
        assert out["tag"].tolist() == inputs["tag"].tolist(), pattern     # each once, in order
        for field, want in golden.items():
            assert np.array_equal(out[field], want), (pattern, field)
    assert cycles["no_stall"] / n <= 1 + (latency + 1) / n
    assert cycles["backpressure"] > n


def scene_latency(build_dir):
    import json
    return json.loads((build_dir / "rtl" / "pipeline.json").read_text())["latency"]


def test_render_rtl_equals_golden_bytes(build_dir):
    """The image render --rtl writes equals the golden render byte for byte (Icarus build:
    this test shares no build with the one above). A flat map with a colour texture: the
    polygon registers and the texture RAM (RGB out, no compose)."""
    scene = load_scene_config({"name": "flat-textured", "bump_map": "flat", "texture": True})
    r = render_rtl(scene, 16, "icarus", build_dir, progress=False)
    assert r.image.tobytes() == golden_render(scene, 16).tobytes()
    assert r.image.tobytes() == r.golden.tobytes()
    assert len(np.unique(r.image.reshape(-1, 3), axis=0)) > 8      # the texture shows


def test_texture_needs_an_image_with_a_colour_texture():
    from bumprtl.rtl.config import BumpError
    with pytest.raises(BumpError, match="texture = true needs an image with a colour texture"):
        golden_render(load_scene_config({"name": "t", "texture": True, "image": "moon"}), 16)
