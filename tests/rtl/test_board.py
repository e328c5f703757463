"""rtl/board.py's elastic buffer (the pipeline's own credit FIFO) at its derived least
depth and the light table's wrap, in the Amaranth simulator.

The buffer (docs/board.md, "The elastic buffer"): the display taking pixel n at clock t
returns a credit; the source issues pixel n + D with it one clock later (the registered
credit count), the pipeline gives it back L clocks after that (its ``latency``), and
the credit edge's FIFO (rtl/pipe.CreditFIFO: memory, prefetch register, output register)
shows an entry FIFO_DELAY clocks after its write. The display wants
pixel n + D at clock t + D, so on a line longer than the buffer D >= 1 + L + FIFO_DELAY is
needed and enough: rtl/pipe.min_fifo_depth, below which the pipeline refuses the depth. The reduced mode's 32-pixel lines hide a shallow buffer (a line is over
before the shortage shows), so the check runs a mode with lines longer than the buffer and
blanking shorter than the pipeline.

The light table: the source's frame counter steps through the table and returns to entry 0
after its last; the payload of every pixel of frames 0 .. 2 x steps must carry table[f %
steps], the golden model's frame inputs (sim/golden/board.frame_inputs) too.
"""

import dataclasses

import numpy as np
import pytest
from amaranth.hdl import Module, Signal
from amaranth.sim import Simulator

from bumprtl.gen.flow.board import board_data
from bumprtl.rtl.board import BoardCore, PixelSource, buffer_depth, payload_field
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipe import CreditFIFO, min_fifo_depth
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.video import MODES
from bumprtl.sim.golden.board import STEPS, frame_inputs, light_table
from bumprtl.sim.scenes.config import load_scene_config

SMALL = {"angle_bits": 10, "texture_size": 16}
FIFO_DELAY = 3        # CreditFIFO: an entry written to an empty queue is read 3 clocks later


@pytest.fixture(scope="module")
def scene_data():
    scene = load_scene_config("default", SMALL)
    words, texels, constants, table = board_data(scene)
    return scene, (words, constants, table[:4], texels)


def unelaborated_pipeline(scene):
    """A BumpPipeline read for its latency and ports only, never elaborated."""
    pipeline = BumpPipeline(scene.hardware)
    for unit in (pipeline, *pipeline.units.values()):
        unit._MustUse__silence = True
    return pipeline


def test_fifo_delay_is_what_the_derivation_takes():
    fifo = CreditFIFO(8, 8)
    seen = []

    async def bench(ctx):
        ctx.set(fifo.w_data, 0x5A)
        ctx.set(fifo.w_en, 1)
        await ctx.tick()
        ctx.set(fifo.w_en, 0)
        for _ in range(5):
            seen.append(ctx.get(fifo.r_rdy))
            await ctx.tick()

    sim = Simulator(fifo)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    assert seen.index(1) + 1 == FIFO_DELAY, seen      # written in clock 0, readable in clock 3


def long_line_mode(depth, latency):
    """The reduced mode with lines longer than the buffer and horizontal blanking shorter
    than the pipeline: two active lines, three blanking lines (the start-up fill)."""
    base = MODES["test"]
    mode = dataclasses.replace(base, h_active=depth + 24, v_active=2, v_front=1, v_sync=1,
                               v_back=1)
    assert mode.h_active > depth and mode.h_total - mode.h_active < latency
    assert (mode.v_total - mode.v_active) * mode.h_total > depth + latency   # fills at start-up
    return mode


def run_core(scene, data, mode, depth=None):
    """(underflow, order_error) after one frame of BoardCore in ``mode`` with the buffer
    ``depth`` deep (its own depth when None)."""
    words, constants, table, texels = data
    core = BoardCore(scene.hardware, mode, words, constants, table, texels, depth=depth)
    flags = []

    async def bench(ctx):
        await ctx.tick().repeat(mode.frame_clocks + mode.h_total)
        flags.extend([ctx.get(core.underflow), ctx.get(core.order_error)])

    sim = Simulator(core)          # the shift domain (serializer) has no clock: not needed here
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return tuple(flags)


def test_buffer_at_its_least_depth_keeps_long_lines_fed_and_one_below_is_refused(scene_data):
    scene, data = scene_data
    latency = unelaborated_pipeline(scene).latency
    least = 1 + latency + FIFO_DELAY
    assert min_fifo_depth(latency) == least
    mode = long_line_mode(least, latency)
    assert run_core(scene, data, mode, least) == (0, 0)
    words, constants, table, texels = data
    with pytest.raises(BumpError, match=f"fifo_depth must be an int >= {least}.*got {least - 1}$"):
        BoardCore(scene.hardware, mode, words, constants, table, texels, depth=least - 1)


def test_board_buffer_depth_keeps_long_lines_fed(scene_data):
    scene, data = scene_data
    latency = unelaborated_pipeline(scene).latency
    assert run_core(scene, data, long_line_mode(buffer_depth(latency), latency)) == (0, 0)
    assert buffer_depth(latency) >= 1 + latency + FIFO_DELAY


def collect_payloads(src, keys, need, seed, parts=(), each=None):
    """The payload fields ``keys`` of the first ``need`` pixels the source ``src`` hands its
    pipeline, under random ``allow`` and ``ready``: {key: [value, ...]}, with the light step
    register (``step``); ``parts``: further elaboratables beside it; ``each(ctx, got)``: a
    call every clock for more records."""
    p = src.pipeline.i
    got = {k: [] for k in [*keys, "step"]}
    rng = np.random.default_rng(seed)
    m = Module()
    m.submodules.src = src
    for n, part in enumerate(parts):
        m.submodules[f"part{n}"] = part
    ready = Signal()
    m.d.comb += p.ready.eq(ready)

    async def bench(ctx):
        while len(got[keys[0]]) < need:
            ctx.set(src.allow, int(rng.random() < 0.8))
            ctx.set(ready, int(rng.random() < 0.7))
            if ctx.get(p.valid) and ctx.get(ready):
                for k in keys:
                    got[k].append(ctx.get(payload_field(p.payload, k)))
                got["step"].append(ctx.get(src.frame))
            if each is not None:
                each(ctx, got)
            await ctx.tick()

    sim = Simulator(m)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    return got


def source_payloads(scene, mode, table, frames, seed):
    """The payload fields of every pixel PixelSource issues over ``frames`` frames."""
    src = PixelSource(unelaborated_pipeline(scene), mode, {"n.phi": 0, "n.theta": 0}, table)
    return collect_payloads(src, ["u", "v", "tag", *table[0]], frames * mode.pixels, seed)


@pytest.mark.parametrize("steps", [5, STEPS])
def test_light_table_wraps_to_its_first_entry(steps):
    scene = load_scene_config("default", SMALL)
    table = light_table(scene, steps)
    mode = dataclasses.replace(MODES["test"], h_active=2, v_active=1)   # 2 pixels a frame
    frames = steps + 3
    got = source_payloads(scene, mode, table, frames, seed=steps)
    n = mode.pixels
    for f in range(frames):
        want = table[f % steps]                      # the frame after the last: entry 0
        golden = frame_inputs(scene, mode, f, table)
        for k, code in want.items():
            assert got[k][f * n:(f + 1) * n] == [code] * n, (f, k)
            assert list(golden[k]) == [code] * n, (f, k)
        assert got["step"][f * n:(f + 1) * n] == [f % steps] * n, f
        for k in ("u", "v", "tag"):
            assert got[k][f * n:(f + 1) * n] == list(golden[k]), (f, k)
