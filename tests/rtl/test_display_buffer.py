"""The board's display buffer (rtl/board.DisplayBuffer; docs/board.md, What holds at 1280 x
720): a FIFO in block RAM read through its output register into a small queue. In the
Amaranth simulator: every word comes out once, in order, under random writes and reads;
it holds exactly depth + OUT_SLOTS words when nothing is read; written and read every
cycle, a word a cycle flows through; a depth that is not a power of two is refused."""

import numpy as np
import pytest
from amaranth.sim import Simulator

from bumprtl.rtl.board import DisplayBuffer
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipe import RAM_LATENCY


def run(buf, cycles, w_pattern, r_pattern):
    """(words written, words read, w_rdy per cycle) over ``cycles`` with w_en and r_en
    from the two patterns (functions of the cycle)."""
    written, read, rdy = [], [], []

    async def bench(ctx):
        word = 0
        for t in range(cycles):
            w, r = w_pattern(t), r_pattern(t)
            ctx.set(buf.w_en, w)
            ctx.set(buf.w_data, word)
            ctx.set(buf.r_en, r)
            await ctx.delay(1e-9)
            rdy.append(ctx.get(buf.w_rdy))
            if w and ctx.get(buf.w_rdy):
                written.append(word)
                word = (word + 1) % (1 << buf.width)
            if r and ctx.get(buf.r_rdy):
                read.append(ctx.get(buf.r_data))
            await ctx.tick()

    sim = Simulator(buf)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    return written, read, rdy


@pytest.mark.parametrize("depth, seed", [(16, 1), (2, 2), (64, 3)])
def test_every_word_once_in_order_under_random_traffic(depth, seed):
    rng = np.random.default_rng(seed)
    w, r = rng.random(3000) < 0.6, rng.random(3000) < 0.55
    r[2000:] = True                                          # then drain it
    w[2600:] = False
    written, read, _ = run(DisplayBuffer(12, depth), 3000, lambda t: int(w[t]),
                           lambda t: int(r[t]))
    assert len(written) > 1000 and read == written


@pytest.mark.parametrize("depth", [2, 16])
def test_holds_depth_and_its_queue_when_nothing_is_read(depth):
    written, read, rdy = run(DisplayBuffer(8, depth), depth + 40, lambda t: 1, lambda t: 0)
    assert read == [] and len(written) == depth + DisplayBuffer.OUT_SLOTS
    assert rdy[-1] == 0
    # then read: it gives back exactly those words, in order
    buf = DisplayBuffer(8, depth)
    held = depth + DisplayBuffer.OUT_SLOTS
    written, read, _ = run(buf, 3 * held + 40, lambda t: int(t < held + 20),
                           lambda t: int(t >= held + 20))
    assert read == written and len(written) == held


def test_a_word_a_cycle_flows_through(monkeypatch):
    written, read, _ = run(DisplayBuffer(8, 16), 300, lambda t: 1, lambda t: 1)
    # every cycle after the first word's way through (its count, its read, the queue)
    assert len(written) == 300 and len(read) >= 300 - (RAM_LATENCY + 4)
    assert read == written[:len(read)]
    # a slot fewer in the queue loses cycles
    monkeypatch.setattr(DisplayBuffer, "OUT_SLOTS", RAM_LATENCY + 2)
    _, fewer, _ = run(DisplayBuffer(8, 16), 300, lambda t: 1, lambda t: 1)
    assert len(fewer) < 300 - 40


@pytest.mark.filterwarnings("ignore::amaranth.hdl.UnusedElaboratable")
@pytest.mark.parametrize("depth", [0, 1, 3, 48, True, 16.0])
def test_a_depth_not_a_power_of_two_is_refused(depth):
    with pytest.raises(BumpError) as e:
        DisplayBuffer(8, depth)
    assert e.value.field == "display_buffer" and "power of two >= 2" in str(e.value)
