"""The board's turning globe (rtl/board.GlobeSource, rtl/board.globe_config; docs/board.md):
its frames in the Amaranth simulator equal the golden frames (sim/golden/board.py) pixel for
pixel; its source's payload stream equals the golden frame inputs under random credits,
through the light table's wrap and the rotation's steps; the golden frames themselves are
checked against facts written here (the disc the globe covers, black outside, the lit side
facing the light), so that a frame convention wrong in both the RTL and the model still
fails."""

import dataclasses

import numpy as np
import pytest
from amaranth.sim import Simulator

from bumprtl.gen.flow.board import board_core, board_data
from bumprtl.rtl.board import (
    GlobeSource,
    globe_config,
    globe_offsets,
    globe_turn_step,
)
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.globe import GlobeGeometry
from bumprtl.rtl.video import MODES
from bumprtl.sim.golden.board import STEPS, frame_inputs, golden_frame, light_table
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import load_scene_config
from tests.rtl.test_board import collect_payloads, unelaborated_pipeline

SMALL = {"angle_bits": 10, "texture_size": 16, "image": "globe"}


@pytest.fixture(scope="module")
def globe_scene():
    scene = load_scene_config("default", SMALL)
    words, texels, constants, table = board_data(scene)
    return scene, (words, texels, constants, table[:4])


def shown_frames(core, mode, frames):
    """The (v_active, h_active, 3) RGB frames the encoders are given, frames 0 .. frames - 1
    from the first active pixel on, and the sticky flags at the end."""
    seen = []

    async def bench(ctx):
        while len(seen) < frames * mode.pixels:
            if ctx.get(core.timing.de):
                seen.append(ctx.get(core.pixel))
            await ctx.tick()
        seen.extend([ctx.get(core.underflow), ctx.get(core.order_error)])

    sim = Simulator(core)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    px = np.array(seen[:-2], np.int64)
    rgb = np.stack([(px >> 16) & 255, (px >> 8) & 255, px & 255], -1)     # bytes: b, g, r
    return rgb.reshape(frames, mode.v_active, mode.h_active, 3), seen[-2], seen[-1]


def test_globe_frames_equal_the_golden_frames(globe_scene):
    scene, data = globe_scene
    mode = MODES["test"]
    words, texels, _, table = data
    got, underflow, order = shown_frames(board_core(scene, mode, data=data), mode, 2)
    assert (underflow, order) == (0, 0)
    for f in range(2):
        want = golden_frame(scene, mode, f, table, words, texels)
        assert np.array_equal(got[f], want), \
            f"frame {f}: {np.count_nonzero(np.any(got[f] != want, -1))} pixels differ"


def test_globe_frame_with_mip_levels_equals_the_golden_frame():
    """With mip levels the globe picks each pixel's level (rtl/globe.py) and the source
    hands it to the pipeline's fetch: a 64 x 32 map in 6 levels at R = 11, whose disc reads
    level 0 in its middle and coarser levels towards the rim. The frame equals the golden
    frame, and the golden frame is not the one every pixel at level 0 would give."""
    scene = load_scene_config("default", {**SMALL, "texture_size": 64, "texture_height": 32,
                                          "mip_levels": 6})
    words, texels, constants, table = board_data(scene)
    mode = MODES["test"]
    levels = frame_inputs(scene, mode, 0, table)["level"]
    assert levels.max() >= 2 and np.count_nonzero(levels == 0) > mode.pixels // 4
    got, underflow, order = shown_frames(board_core(scene, mode, data=(words, texels,
                                                                       constants, table[:2])),
                                         mode, 1)
    assert (underflow, order) == (0, 0)
    want = golden_frame(scene, mode, 0, table, words, texels)
    assert np.array_equal(got[0], want), \
        f"{np.count_nonzero(np.any(got[0] != want, -1))} pixels differ"
    base = frame_inputs(scene, mode, 0, table)
    inside = (base["tag"] >> (scene.tag_bits - 1) & 1) == 1
    base["level"] = np.zeros_like(base["level"])
    at0 = pipeline_fixed(base, scene, words, None, texels)["color"]
    assert np.count_nonzero(want[..., 0].ravel()[inside] != at0[inside]) > 10, \
        "the levels change nothing here"


def test_golden_globe_covers_the_disc_and_is_black_outside(globe_scene):
    """The pixels shown are exactly those with x**2 + y**2 < R**2 about the screen's centre
    (x right, y up), R = 7/15 of the height; every pixel outside is black; most inside are
    not. globe_offsets is the same function the hardware elaborates."""
    scene, (words, texels, _, table) = globe_scene
    mode = dataclasses.replace(MODES["test"], h_active=40, v_active=30)
    R = 30 * 7 // 15
    assert globe_config(scene.hardware, mode).radius == R == 14
    yy, xx = np.mgrid[0:30, 0:40]
    disc = (xx - 20) ** 2 + (15 - yy) ** 2 < R * R
    assert [a.tolist() for a in globe_offsets(np.array([0, 39]), np.array([0, 29]), mode)] == \
        [[-20, 19], [15, -14]]
    frame = golden_frame(scene, mode, 0, table, words, texels)
    inside = frame_inputs(scene, mode, 0, table)["tag"] >> (scene.tag_bits - 1) & 1
    assert np.array_equal(inside.reshape(30, 40).astype(bool), disc)
    assert not frame[~disc].any()
    assert np.count_nonzero(frame[disc].any(-1)) > 0.9 * disc.sum()


@pytest.mark.parametrize("step, quadrant", [(0, (1, 1)), (STEPS // 2, (-1, -1))])
def test_golden_globe_is_lit_on_the_side_facing_the_light(step, quadrant):
    """Light 0 sits at azimuth 30 degrees (up and to the right of the viewing axis) in frame
    0 and at 210 degrees (down and to the left) half a turn later: the brightness-weighted
    centre of the disc lies in that quadrant of the screen. A normal in another frame than
    the lights' (the pole toward the viewer, y flipped, phi off by a quarter turn) moves it."""
    scene = load_scene_config("default", {**SMALL, "texture_size": 64})
    words, texels, _, table = board_data(scene)
    mode = dataclasses.replace(MODES["test"], h_active=96, v_active=96)
    grey = golden_frame(scene, mode, step, table, words, texels)[..., 0].astype(float)
    yy, xx = np.mgrid[0:96, 0:96]
    x, y = xx - 48, 48 - yy                      # right and up from the screen's centre
    cx, cy = (grey * x).sum() / grey.sum(), (grey * y).sum() / grey.sum()
    assert np.sign(cx) == quadrant[0] and np.sign(cy) == quadrant[1], (cx, cy)
    assert min(abs(cx), abs(cy)) > 2


def test_golden_globe_of_a_2_to_1_map_reads_v_over_the_height():
    """A 32 x 16 map (texture_height 16, W = 2H: equirectangular) on the globe: v runs over
    the colatitude in H rows, u over the longitude in W columns. floor(x H) is
    floor(floor(x 2H) / 2) exactly, so the frame equals the square 32 x 32 map's frame with
    each of the 2:1 map's rows written twice (row v' of the square map = row v' >> 1); v
    spans the rows from near the north pole to near the south pole, never past the last."""
    keys = {**SMALL, "texture_size": 32}
    wide = load_scene_config("default", {**keys, "texture_height": 16})
    square = load_scene_config("default", keys)
    mode = dataclasses.replace(MODES["test"], h_active=48, v_active=40)
    assert (globe_config(wide.hardware, mode).map_width,
            globe_config(wide.hardware, mode).map_height) == (32, 16)
    words, texels, _, table = board_data(wide)
    assert len(words) == 32 * 16
    doubled = np.repeat(np.asarray(words).reshape(16, 32), 2, axis=0).ravel()
    for frame in (0, 3):
        got = golden_frame(wide, mode, frame, table, words, texels)
        assert np.array_equal(got, golden_frame(square, mode, frame, table, doubled, texels))
        assert got.any()
    inputs = frame_inputs(wide, mode, 0, table)
    inside = (inputs["tag"] >> (wide.tag_bits - 1) & 1) == 1
    assert inputs["v"][inside].min() <= 1 and inputs["v"][inside].max() >= 14
    assert inputs["u"].max() < 32 and inputs["v"].max() < 16
    assert len(np.unique(inputs["u"][inside])) == 16       # the visible half of the longitudes


def source_payloads(scene, mode, table, frames, seed):
    """The payload fields of every pixel GlobeSource hands the pipeline over ``frames``
    frames, under random credits at both ends, and the rotation of every pixel the globe
    takes: {key: [value, ...]}."""
    pipeline = unelaborated_pipeline(scene)
    globe = GlobeGeometry(globe_config(pipeline.scene, mode))
    src = GlobeSource(pipeline, mode, globe, table)

    def rotation(ctx, got):
        if ctx.get(globe.i.valid) and ctx.get(globe.i.ready):
            got.setdefault("rotation", []).append(ctx.get(globe.i.payload.rotation))

    keys = ["u", "v", "n.phi", "n.theta", "tag", *table[0]]
    return collect_payloads(src, keys, frames * mode.pixels, seed, [globe], rotation)


def test_source_stream_follows_the_golden_inputs_through_the_wraps():
    """Frames of 3 x 3 pixels (R = 1: the centre alone is inside) with 5 light steps and the
    rotation one code a frame from 3/4 turn: every payload field of every pixel, the light step returning
    to entry 0 after its last, equal to the golden frame inputs."""
    scene = load_scene_config("default", SMALL)
    steps = 5
    table = light_table(scene, steps)
    mode = dataclasses.replace(MODES["test"], h_active=3, v_active=3)
    assert globe_turn_step(scene.hardware.config) == 1
    frames = steps + 3
    got = source_payloads(scene, mode, table, frames, seed=4)
    n = mode.pixels
    for f in range(frames):
        golden = frame_inputs(scene, mode, f, table)
        for k in ("u", "v", "n.phi", "n.theta", "tag", *table[0]):
            assert got[k][f * n:(f + 1) * n] == list(golden[k]), (f, k)
        assert got["step"][f * n:(f + 1) * n] == [f % steps] * n, f
        # 3/4 turn in frame 0, one code more each frame
        assert got["rotation"][f * n:(f + 1) * n] == [768 + f] * n, f
    # the centre's u follows the rotation: one code a frame is 16 / 1024 of a texel, so it
    # moves only after 64 frames; its inside bit is the only one set
    centre = [got["tag"][f * n + 4] >> (scene.tag_bits - 1) for f in range(frames)]
    assert centre == [1] * frames and sum(t >> (scene.tag_bits - 1) for t in got["tag"]) == frames


def test_globe_source_refuses_a_one_bit_tag():
    scene = load_scene_config("default", {**SMALL, "tag_bits": 1})
    pipeline = unelaborated_pipeline(scene)
    globe = GlobeGeometry(globe_config(pipeline.scene, MODES["test"]))
    globe._MustUse__silence = True
    with pytest.raises(BumpError, match="tag_bits must be >= 2"):
        GlobeSource(pipeline, MODES["test"], globe, [{}])
