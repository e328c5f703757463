"""The emitted pipeline under cocotb, every cycle driven from Python (sim/tb/tb_pipeline.py):
the coverage frame (sim/tb/bulk_frame.py) and a small render through one build, one pixel per
clock without stalls, and under random backpressure and input gaps every pixel comes out
once, in order, bit-exact with the golden model; render --rtl's image equals the golden
render byte for byte (the bulk path, and the per-cycle path on two 16 x 16 frames, in make
test). One build per simulator."""


import numpy as np
import pytest

from bumprtl.gen.render.rtl import (
    emit_pipeline,
    golden_render,
    render_rtl,
    run_pipeline_emitted,
    scene_stimulus,
    scene_texels,
)
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.bulk_frame import PIXELS, coverage_frame
from bumprtl.sim.traffic import PATTERNS


# make regress: the per-cycle runs of the coverage frame. make test streams the same coverage frames on
# Icarus under the same traffic patterns through the bulk path, every output field against
# the golden model: the full scene's (tests/sim/tb/test_bulk_scene_frames.py) and the
# default scene's, then its render frame (tests/sim/tb/test_bulk.py). Here: the render frame
# behind the coverage frame, and the full scene's build on Verilator too (a minute of C++
# compilation).
@pytest.mark.parametrize("sim, name, render", [
    pytest.param("icarus", "full", False, marks=pytest.mark.regress),
    pytest.param("icarus", "full", True, marks=pytest.mark.regress),
    pytest.param("icarus", "default", True, marks=pytest.mark.regress),
    pytest.param("verilator", "full", True, marks=pytest.mark.regress)])
def test_pipeline_stream_cocotb(sim, name, render, build_dir):
    """``full``: two lights, mip levels and the colour texture (RGB out). One build and one
    run of sim/tb/tb_pipeline.py: under each traffic pattern the host writes the coverage
    frame's map and texture words (sim/tb/bulk_frame.py, the frame the netlist mutants of
    pipeline:full and pipeline:two-lights stream: two-lights is this datapath without the
    texture and the mip levels), then the frame's pixels stream, then the rendered 16 x 16
    frame's (``render``); every output field equals the golden model's on the memories as
    the host left them (2 of the render's 256 pixels read a word the host wrote; the others'
    outputs are the golden render's)."""
    scene = load_scene_config(name)
    inputs, words, polygon, table, base = scene_stimulus(scene, 16)
    texels = scene_texels(scene, base)
    v, j = emit_pipeline(scene, words, texels, build_dir, None, write_port=True)
    meta = load_sidecar(j)
    frame = coverage_frame(scene, words, texels)
    assert sorted(frame.inputs) == sorted(inputs)
    assert len(frame.inputs["tag"]) > PIXELS                  # the table-sensitivity pixels
    stream = {k: np.concatenate([frame.inputs[k], inputs[k]]) if render else frame.inputs[k]
              for k in inputs}
    outs, cycles, _ = run_pipeline_emitted(v, j, stream, polygon, table, sim, build_dir,
                                           list(PATTERNS), progress=False,
                                           setup=frame.setup(meta))
    golden = pipeline_fixed(stream, scene, frame.words, frame.polygon, frame.texels)
    assert ("color.r" in golden) == scene.texture
    assert all(np.array_equal(golden[k][:len(frame.inputs["tag"])], frame.golden[k]) for k in golden)
    n = len(stream["tag"])
    for pattern in PATTERNS:
        assert outs[pattern]["tag"].tolist() == stream["tag"].tolist(), pattern  # once, in order
        for field, want in golden.items():
            assert np.array_equal(outs[pattern][field], want), (pattern, field)
    latency = meta.latency
    assert cycles["no_stall"] / n <= 1 + (latency + 1) / n
    assert cycles["backpressure"] > n


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


def test_render_rtl_of_a_palette_scene_writes_its_table_first(build_dir):
    """The palette scene through render --rtl's bulk path: its colour table reaches the
    LUT through the host port before the first pixel (the set-up writes), so the image is
    the golden render's, byte for byte, and holds more than one colour."""
    scene = load_scene_config("palette")
    r = render_rtl(scene, 16, "icarus", build_dir, progress=False)
    assert r.image.tobytes() == golden_render(scene, 16).tobytes()
    assert r.image.tobytes() == r.golden.tobytes()
    assert len(np.unique(r.image.reshape(-1, 3), axis=0)) > 8


@pytest.mark.parametrize("name, load", [("palette", "port"), ("flat", "initial")])
def test_render_rtl_per_cycle_equals_golden_bytes(name, load, build_dir, capfd):
    """The per-cycle path of render --rtl (``--per-cycle``: every pixel driven from cocotb,
    tb_pipeline.py) on a 16 x 16 frame, on Icarus: the palette scene with its map written
    through the host port (``--load port``) and its colour table by the host, the flat
    scene with its polygon registers; the image equals the golden render byte for byte and
    the progress bar counts the pixels."""
    scene = load_scene_config(name)
    r = render_rtl(scene, 16, "icarus", build_dir, per_cycle=True, load=load)
    assert r.image.tobytes() == golden_render(scene, 16).tobytes() == r.golden.tobytes()
    assert len(np.unique(r.image.reshape(-1, r.image.shape[-1]), axis=0)) > 1
    assert "256/256" in capfd.readouterr().err        # rtl: 256 pixels of 256

