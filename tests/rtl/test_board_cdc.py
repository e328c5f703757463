"""rtl/board.py with the source and pipeline in their own clock domain (``pipe_hz``): the
asynchronous FIFO between it and the pixel clock (docs/board.md, The pipeline in its own
clock domain), in the Amaranth simulator with two unrelated clocks.

The display must see exactly the pixels it sees with one clock (the crossing loses,
repeats or reorders none and changes no bit), on lines longer than the pipeline's buffer and
the crossing together, with no underflow; the depth is the derivation's, checked against the
arithmetic written out here; a pipeline clock below the pixel clock is refused."""

import pytest
from amaranth.sim import Simulator

from bumprtl.rtl.board import CDC_SYNC_STAGES, BoardCore, cdc_depth, pll_params, pll_pipe_divider
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.video import MODES
from tests.rtl.test_board import long_line_mode, unelaborated_pipeline

PIXEL_NS = 10.0


@pytest.fixture(scope="module")
def scene_data():
    from bumprtl.gen.flow.board import board_data
    from bumprtl.sim.scenes.config import load_scene_config
    scene = load_scene_config("default", {"angle_bits": 10, "texture_size": 16})
    words, texels, constants, table = board_data(scene)
    return scene, (words, constants, table[:4], texels)


def shown(scene, data, mode, pipe_ratio=None, phase_ns=0.0, display_buffer=None):
    """(pixels the encoders get over one frame and a line, underflow, order_error) of a
    BoardCore in ``mode``; ``pipe_ratio``: the pipe clock over the pixel clock (None: one
    domain), its first edge ``phase_ns`` after the pixel clock's; ``display_buffer``: the
    FIFO ahead of the crossing."""
    words, constants, table, texels = data
    pipe_hz = None if pipe_ratio is None else mode.pixel_hz * pipe_ratio
    core = BoardCore(scene.hardware, mode, words, constants, table, texels, pipe_hz=pipe_hz,
                     display_buffer=display_buffer)
    seen = []

    async def bench(ctx):
        for _ in range(mode.frame_clocks + mode.h_total):
            seen.append(ctx.get(core.pixel))
            await ctx.tick()
        seen.extend([ctx.get(core.underflow), ctx.get(core.order_error)])

    sim = Simulator(core)
    sim.add_clock(PIXEL_NS * 1e-9)
    if pipe_ratio is not None:
        sim.add_clock(PIXEL_NS / pipe_ratio * 1e-9, phase=phase_ns * 1e-9, domain="pipe")
    sim.add_testbench(bench)
    sim.run()
    return seen[:-2], seen[-2], seen[-1]


@pytest.mark.parametrize("ratio, phase, ahead", [
    (1.0, 3.3, None),                               # equal rates: the deepest need
    (1.0, 3.3, 32),                                 # a FIFO ahead of the crossing
    pytest.param(1.37, 0.0, None, marks=pytest.mark.regress)])
def test_the_crossing_shows_the_single_clock_pixels(scene_data, ratio, phase, ahead):
    scene, data = scene_data
    latency = unelaborated_pipeline(scene).latency
    # lines longer than every buffer together
    mode = long_line_mode(latency + 8 + cdc_depth(1, ratio) + (ahead or 0), latency)
    one, under, order = shown(scene, data, mode)
    assert (under, order) == (0, 0) and any(one)
    two, under, order = shown(scene, data, mode, ratio, phase, ahead)
    assert (under, order) == (0, 0)
    assert two == one, f"{sum(a != b for a, b in zip(two, one, strict=True))} pixels differ"


def test_depth_is_the_round_trip_written_out():
    # read side: pointer register + synchronizer + the entry's register, 3 + 2 pixel clocks;
    # write side: 2 + 2 pipe clocks (+ the pipeline's longest pause), scaled to pixel clocks;
    # one more entry; the next power of two
    assert CDC_SYNC_STAGES == 2
    assert cdc_depth(74.25e6, 74.25e6) == 16            # 5 + 4 + 1 = 10
    assert cdc_depth(74.25e6, 2 * 74.25e6) == 8         # 5 + 2 + 1 = 8
    assert cdc_depth(25e6, 100e6) == 8                  # 5 + 1 + 1 = 7
    assert cdc_depth(74.25e6, 2 * 74.25e6, stall_cycles=60) == 64    # 5 + 32 + 1 = 38
    assert cdc_depth(74.25e6, 1.5 * 74.25e6, stall_cycles=0) == 16   # 5 + ceil(8/3) + 1 = 9


def test_a_pipe_clock_below_the_pixel_clock_is_refused():
    with pytest.raises(BumpError, match=r"^pipe clock must be at least the pixel clock 25 MHz.*got 24\.9 MHz$"):
        cdc_depth(25e6, 24.9e6)
    with pytest.raises(BumpError, match=r"stall_cycles must be an int >= 0, got -1"):
        cdc_depth(25e6, 50e6, stall_cycles=-1)


def test_the_pll_gives_the_pipe_clock_from_its_vco_never_below_the_request():
    mode = MODES["640x480"]
    div, hz = pll_pipe_divider(mode.pixel_hz, 150e6)
    params = pll_params(mode.pixel_hz, pipe_hz=150e6)
    vco = 25e6 / params["p_CLKI_DIV"] * params["p_CLKFB_DIV"] * params["p_CLKOP_DIV"]
    assert params["p_CLKOS2_DIV"] == div and hz == vco / div >= 150e6 > vco / (div + 1)
    assert params["p_CLKOS2_CPHASE"] == div - 1
    assert "p_CLKOS2_DIV" not in pll_params(mode.pixel_hz)          # one domain: no CLKOS2
    with pytest.raises(BumpError, match=r"^pipe clock must be in \[.* MHz.*got 500 MHz$"):
        pll_pipe_divider(mode.pixel_hz, 500e6)
