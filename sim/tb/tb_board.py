"""cocotb testbench of the board top (rtl/board.SimTop; docs/board.md): the frames on its
TMDS lanes, captured by a DVI sink we did not write (cocotbext-dvi's ``DVISink``).

The testbench drives ``clk`` (pixel) and ``shift_clk`` (5 x pixel, edges aligned) in place
of the PLL, resets both domains, and lets ``DVISink`` decode the serial lanes
``tmds_data_p`` (lane k on bit k) against the clock lane ``tmds_clk_p`` with its own TMDS
tables. Its frames (``rgb_out.frames``, from one vertical sync to the next, pixel values
red << 16 | green << 8 | blue) are written to ``BOARD_RESULT`` as (H, W, 3) arrays
``frame0``, ... for the caller to compare with the golden frames; the sink's own pixel
check against an image file is off (its one image cannot follow the turning light).
Once a word, on the clock lane's rising edge, the testbench records the sink's decoded
``de``, ``hsync``, ``vsync`` and checks their run lengths against the mode's table
(``BOARD_TIMING``: h active, front, sync, back, v active, front, sync, back, h negative,
v negative); the disagreements go to ``timing_errors``.

Environment: BOARD_RESULT (npz path), BOARD_FRAMES (frames to capture), BOARD_TIMING,
BOARD_PIXEL_PS (pixel clock period, ps, a multiple of 10); BOARD_PIPE_PS (the pipe clock's period, ps, when
the pipeline has its own domain).

With the map in the SDRAM (BOARD_SDRAM: the chip's variant; BOARD_FLASH: the flash array's
file; BOARD_FLASH_PHASE: the loader's SCLK half period in pipe clocks) the testbench runs
the datasheet model (sim/sdram_model.SdramModel, told the simulated pipe period exactly) on
the ``sdram__*`` pins and the flash model (sim/flash_model.SpiFlash) on the ``spi__*``
pins, both on ``pipe_clk``: the model's pins read after each rising edge, its DQ driven
after the next (as tb_sdram's), MISO driven at the falling edge between (so it is there
``delay`` = half period - 1 pipe clocks after the step that saw SCLK fall, the most the
loader allows). The display starts at a frame's first pixel once the map is loaded
(``display_shows``); the sink starts in the next frame's vertical front porch, so the
captured frames are golden frames 1, 2, ... (``first`` = 1 in the result). A model
violation, a flash rule broken or a READ other than the one copy fails the test.

BOARD_PRELOAD (a .npy of the SDRAM's words, [bank, row, column], in place of BOARD_FLASH):
the top has no flash loader; the model starts holding what the loader would have written
(gen/flow/board.sdram_preload), the source starts once the controller's initialisation is
done, and the display's domain is held in reset until then and BOARD_HOLD_LINES lines more
(default 4; time for the buffers to fill), so that the display starts at its first frame
(the frames captured are still golden frames 1, 2, ...).
"""

import os
import time
from fractions import Fraction
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge
from cocotb.utils import get_sim_time
from cocotbext.dvi import DVIBus, DVISink

from bumprtl.sim.flash_model import SpiFlash
from bumprtl.sim.sdram_model import SdramModel

__all__ = ["runs", "timing_errors"]

# the SDRAM's pins the model samples (sim/tb/tb_sdram.py's)
PINS = ("cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o", "dq_oe", "cke")


def runs(seq):
    """(value, start, length) of each run of equal values of ``seq``."""
    seq = np.asarray(seq, np.int8)
    edges = np.flatnonzero(np.diff(seq)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [len(seq)]])
    return [(int(seq[s]), int(s), int(e - s)) for s, e in zip(starts, ends, strict=False)]


def timing_errors(de, hs, vs, t):
    """Disagreements of the recorded ``de``/``hsync``/``vsync`` (one sample a pixel) with the
    mode ``t`` over the whole frames between the first two vertical sync pulses."""
    ha, hf, hsw, hb, va, vf, vsw, vb, hneg, vneg = t
    htot, vtot = ha + hf + hsw + hb, va + vf + vsw + vb
    hs_on = np.asarray(hs) ^ hneg
    vs_on = np.asarray(vs) ^ vneg
    de = np.asarray(de)
    errors = []
    pulses = [(s, n) for v, s, n in runs(vs_on) if v == 1 and s > 0]
    if len(pulses) < 2:
        return [f"fewer than two vertical sync pulses seen ({len(pulses)})"]
    (p0, n0), (p1, _) = pulses[0], pulses[1]
    if p1 - p0 != htot * vtot:
        errors.append(f"frame period {p1 - p0} pixel clocks, expected {htot * vtot}")
    if n0 != vsw * htot:
        errors.append(f"vsync pulse {n0} clocks, expected {vsw * htot} ({vsw} lines)")
    lo, hi = p0, p1
    de_runs = [(s, n) for v, s, n in runs(de[lo:hi]) if v == 1]
    hs_runs = [(s, n) for v, s, n in runs(hs_on[lo:hi]) if v == 1 and s > 0 and s + n < hi - lo]
    if len(de_runs) != va:
        errors.append(f"{len(de_runs)} active lines a frame, expected {va}")
    if any(n != ha for _, n in de_runs):
        errors.append(f"active line lengths {sorted({n for _, n in de_runs})}, expected {ha}")
    if any(n != hsw for _, n in hs_runs):
        errors.append(f"hsync pulse lengths {sorted({n for _, n in hs_runs})}, expected {hsw}")
    starts = [s for s, _ in hs_runs]
    if any(b - a != htot for a, b in zip(starts, starts[1:], strict=False)):
        errors.append(f"hsync periods {sorted({b - a for a, b in zip(starts, starts[1:], strict=False)})}, "
                      f"expected {htot}")
    # porches: front = active end -> hsync start, back = hsync end -> active start
    for s, n in de_runs:
        end = s + n
        nxt = [h for h in starts if h >= end]
        if nxt and nxt[0] - end != hf:
            errors.append(f"horizontal front porch {nxt[0] - end}, expected {hf}")
            break
        prev = [h + hsw for h in starts if h + hsw <= s]
        if prev and s - prev[-1] != hb:
            errors.append(f"horizontal back porch {s - prev[-1]}, expected {hb}")
            break
    if de_runs:
        first = de_runs[0][0]                       # after the pulse's end
        if first - n0 != vb * htot:
            errors.append(f"vertical back porch {first - n0} clocks, expected {vb * htot}")
        last = de_runs[-1][0] + de_runs[-1][1]
        if (hi - lo) - last != (htot - ha) + vf * htot:
            errors.append(f"vertical front porch {(hi - lo) - last} clocks, expected "
                          f"{(htot - ha) + vf * htot}")
    return errors


class Memories:
    """The SDRAM model on ``sdram__*`` and the flash model on ``spi__*``, on ``pipe_clk``
    (module docstring); ``errors`` collects what either reports. With BOARD_PRELOAD (the
    SDRAM's power-on contents, [bank, row, column]) there is no flash and no flash model."""

    def __init__(self, dut, pipe_ps):
        self.dut = dut
        preload = os.environ.get("BOARD_PRELOAD")
        self.sdram = SdramModel(os.environ["BOARD_SDRAM"], Fraction(10**6, pipe_ps),
                                preload=None if preload is None else np.load(preload))
        self.flash = None
        if preload is None:
            phase = int(os.environ["BOARD_FLASH_PHASE"])
            self.flash = SpiFlash(Path(os.environ["BOARD_FLASH"]).read_bytes(),
                                  min_phase=phase, delay=phase - 1)
        self.errors = []

    async def sdram_pins(self):
        dut, model = self.dut, self.sdram
        drive, value = False, 0
        pins = {name: getattr(dut, "sdram__" + name) for name in PINS}
        command = [pins[name] for name in ("cs_n", "ras_n", "cas_n", "we_n")]
        dq_i, rst, edge, settle = dut.sdram__dq_i, dut.pipe_rst, RisingEdge(dut.pipe_clk), ReadOnly()
        idle = {"ba": 0, "a": 0, "dqm": 0, "dq_o": 0, "dq_oe": 0, "cke": 1}
        in_reset = True
        while True:
            await edge
            dq_i.value = value if drive else 0
            await settle
            if in_reset:                  # the reset is held once, at the start
                if str(rst.value) != "0":
                    model.reset()
                    drive = False
                    continue
                in_reset = False
            try:
                cmd = [int(h.value) for h in command]
                # a NOP or DESELECT cycle with no burst word: the other pins do not matter
                # to the model but DQ's enable (the chip's read data must not meet it)
                if (cmd[0] or cmd[1:] == [1, 1, 1]) and model.n not in model.writes:
                    quiet = dict(idle, dq_oe=int(pins["dq_oe"].value)) if model.n in model.reads \
                        else idle
                    drive, value = model.cycle(*cmd, **quiet)
                    continue
                raw = {name: int(v.value) for name, v in pins.items()}
            except ValueError:            # X or Z: not an integer
                self.errors.append(f"SDRAM cycle {model.n}: X or Z on the pins")
                return
            try:
                drive, value = model.cycle(**raw)
            except AssertionError as e:           # the model's SdramViolation
                self.errors.append(f"SDRAM: {e}")
                return

    async def flash_pins(self):
        dut, flash = self.dut, self.flash
        while True:
            await RisingEdge(dut.pipe_clk)
            await ReadOnly()
            miso = flash.step(int(dut.spi__cs_n.value), int(dut.spi__sclk.value),
                              int(dut.spi__mosi.value))
            await FallingEdge(dut.pipe_clk)
            dut.spi__miso.value = miso


async def underflow_watch(dut, period, htot, vtot, where):
    """From the display's first pixel on: where (frame shown, line, column) the sticky
    ``underflow`` rises, into ``where``."""
    start = get_sim_time("ps")
    await RisingEdge(dut.underflow)
    clocks = int(get_sim_time("ps") - start) // period
    frame, rest = divmod(clocks, htot * vtot)
    where.extend([frame, rest // htot, rest % htot])
    dut._log.info(f"underflow in frame {frame}, line {rest // htot}, column {rest % htot}")


@cocotb.test()
async def board_frames(dut):
    timing = [int(x) for x in os.environ["BOARD_TIMING"].split(",")]
    frames = int(os.environ["BOARD_FRAMES"])
    period = int(os.environ["BOARD_PIXEL_PS"])
    ha, va = timing[0], timing[4]
    htot, vtot = sum(timing[0:4]), sum(timing[4:8])
    cocotb.start_soon(Clock(dut.clk, period, unit="ps").start())
    cocotb.start_soon(Clock(dut.shift_clk, period // 5, unit="ps").start())
    pipe_ps = os.environ.get("BOARD_PIPE_PS")     # the pipeline in its own clock domain
    resets = [dut.rst, dut.shift_rst] + ([dut.pipe_rst] if pipe_ps else [])
    if pipe_ps:
        cocotb.start_soon(Clock(dut.pipe_clk, int(pipe_ps), unit="ps").start())
    memories = Memories(dut, int(pipe_ps)) if os.environ.get("BOARD_SDRAM") else None
    preloaded = memories is not None and memories.flash is None
    if memories is not None:
        dut.sdram__dq_i.value = 0
        cocotb.start_soon(memories.sdram_pins())
        if not preloaded:
            dut.spi__miso.value = 0
            cocotb.start_soon(memories.flash_pins())
    for r in resets:
        r.value = 1
    await ClockCycles(dut.clk, 4)
    for r in resets:           # preloaded: the display's domain stays in reset (below)
        if not (preloaded and r is dut.rst):
            r.value = 0
    first = 0
    where = []                 # the display's first underflow: frame, line, column
    if preloaded:
        # The map is in the SDRAM from the start: the source starts once the controller's
        # initialisation is done. The display's (pixel) domain stays in reset until then
        # and BOARD_HOLD_LINES lines more, the buffers filling meanwhile, so that its first frame is the
        # one it starts with (on the board it would start at the next frame's first pixel
        # with the buffers as full, after an idle frame this skips).
        waited = 0
        while memories.sdram.state != "ready" and not memories.errors and waited < 10**6:
            await ClockCycles(dut.pipe_clk, 256)
            waited += 256
        assert not memories.errors, memories.errors
        assert memories.sdram.state == "ready", "the SDRAM was not initialised"
        await ClockCycles(dut.clk, int(os.environ.get("BOARD_HOLD_LINES", 4)) * htot)
        await FallingEdge(dut.clk)
        dut.rst.value = 0
    if memories is not None:    # the display's first frame: wait for it (the copy, then a frame)
        waited, limit = 0, int(os.environ.get("BOARD_START_LIMIT", 2_000_000))
        while True:
            await RisingEdge(dut.clk)
            await ReadOnly()
            if str(dut.display_shows.value) == "1" or memories.errors or waited > limit:
                break
            waited += 1
        assert not memories.errors, memories.errors
        assert waited <= limit, f"the display did not start in {limit} pixel clocks"
        cocotb.start_soon(underflow_watch(dut, period, htot, vtot, where))
        # at its first pixel (x = 0 of line 0): on to the first front-porch line, below
        await ClockCycles(dut.clk, va * htot)
        first = 1
    # The sink's frame parser must first see a horizontal sync pulse's end while the
    # vertical sync is inactive (it keeps the pulse it measures in a local variable made at
    # that edge, and fails on a pulse's start before it). The raster starts at x = 0 of the
    # first front-porch line, so the sink starts in the middle of that line's hsync pulse
    # (the wire lags the raster by the encoder's 3 stages and the serializer's few cycles).
    await ClockCycles(dut.clk, timing[0] + timing[1] + timing[2] // 2)
    sink = DVISink(dut, DVIBus.from_prefix(dut, "tmds"), height=va, width=ha)
    sink.verification = False                 # the pixels are compared by the caller
    sink.rgb_out.img.width, sink.rgb_out.img.height = ha, va
    rec = {"de": [], "hs": [], "vs": []}

    async def monitor():
        out = sink.rgb_out
        while True:
            await RisingEdge(dut.tmds_clk_p)
            rec["de"].append(int(bool(out.de.value)))
            rec["hs"].append(int(bool(out.hsync.value)))
            rec["vs"].append(int(bool(out.vsync.value)))

    cocotb.start_soon(monitor())
    done = lambda: [f for f in sink.rgb_out.frames if len(f.data)]
    limit = (frames + 2) * htot * vtot
    waited, t0 = 0, time.perf_counter()
    while len(done()) < frames and waited < limit:
        await ClockCycles(dut.clk, htot)
        waited += htot
        if waited % (64 * htot) == 0:     # progress: a long mode's frame takes a while
            dut._log.info(f"sink: {waited // htot} lines, {len(done())} frames, "
                          f"{time.perf_counter() - t0:.0f} s")
    got = done()
    assert len(got) >= frames, f"the DVI sink completed {len(got)} frames in {waited} clocks"
    arrays = {}
    for k, f in enumerate(got[:frames]):
        px = np.asarray([int(v) for v in f.data], np.int64)
        rgb = np.stack([(px >> 16) & 255, (px >> 8) & 255, px & 255], -1).astype(np.uint8)
        if len(px) == ha * va:
            rgb = rgb.reshape(va, ha, 3)
        arrays[f"frame{k}"] = rgb
    errors = timing_errors(rec["de"], rec["hs"], rec["vs"], timing)
    if memories is not None:
        errors += memories.errors
        if memories.flash is not None:
            errors += [f"flash: {e}" for e in memories.flash.errors]
            reads = memories.flash.reads
            if len(reads) != 1:
                errors.append(f"flash: {len(reads)} READ commands, expected the one copy: {reads}")
    np.savez(os.environ["BOARD_RESULT"], **arrays, timing_errors=np.array(errors, dtype=str),
             underflow=int(dut.underflow.value), order_error=int(dut.order_error.value),
             samples=len(rec["de"]), first=first,
             underflow_at=np.array(where[:3] if where else [-1, -1, -1]))
