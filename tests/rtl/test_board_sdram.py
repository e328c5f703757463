"""The board with its map in the SDRAM (rtl/board.BoardCore with ``sdram`` and ``flash``;
docs/board.md): after reset the FlashLoader copies the map's image from the SPI flash
(sim/flash_model.py) into the SDRAM (sim/sdram_model.py, the datasheet model, which fails on
any illegal command or timing) through the SdramController, then the pipeline's texel
cache reads it from there. In the Amaranth simulator, the pipeline at 4 x the pixel clock:
the first frames shown equal the golden frames (the map in block RAM's), nothing underflows
or comes out of order, and neither model saw a rule broken; once with the controller's pins
the chip's, once with them registered as the ULX3S top's I/O does (``pin_cycles`` 2). Opt-in
(``make regress``): the load and two frames take about a minute of simulation each.

In ``make test``: the preload that simulations without the flash copy start the SDRAM's
model with (gen/flow/board.sdram_preload) against what the controller writes, and the
memory parts' refusals."""

import numpy as np
import pytest
from amaranth.hdl import Elaboratable, Module, Signal
from amaranth.sim import Simulator

from bumprtl.gen.flow.board import board_data, sdram_preload
from bumprtl.rtl.board import SDRAM_PIN_CYCLES, BoardCore
from bumprtl.rtl.cache import scene_geometry, scene_levels, tiled_image
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.flash import FlashConfig
from bumprtl.rtl.sdram import SdramConfig
from bumprtl.rtl.video import MODES
from bumprtl.sim.flash_model import SpiFlash
from bumprtl.sim.golden.board import golden_frame
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.sdram_bench import run
from bumprtl.sim.sdram_model import SdramModel

PIPE_MHZ = 100
OFFSET = 0x2000              # the map's place in the flash (the bitstream before it)


def board_parts(scene, pin_cycles=0):
    """(SdramConfig, FlashConfig, flash bytes) of ``scene``'s map: its tiled image at
    OFFSET of the flash, copied to the cache's base in bursts of one SDRAM burst."""
    geom = scene_geometry(scene.hardware)
    words, _, _, _ = board_data(scene)
    image = tiled_image(geom, scene_levels(scene.hardware, words))
    sdram = SdramConfig(freq_mhz=PIPE_MHZ, powerup_cycles=40, init_refreshes=2,
                        data_bits=geom.data_bits, addr_bits=geom.addr_bits,
                        pin_cycles=pin_cycles)
    flash = FlashConfig(offset=OFFSET, length=len(image), base=geom.base,
                        addr_bits=geom.addr_bits, data_bits=geom.data_bits, burst=4,
                        half_period=2)
    rng = np.random.default_rng(3)              # whatever else the flash holds
    contents = rng.integers(0, 256, OFFSET + len(image) + 64, dtype=np.uint8).tobytes()
    return sdram, flash, contents[:OFFSET] + image + contents[OFFSET + len(image):]


class BoardIO(Elaboratable):
    """``core`` with its SDRAM pins as the ULX3S top's I/O makes them, in whole ``pipe``
    cycles (tests/rtl/test_board_top.py, docs/sdram.md): every output registered once
    more, DQ registered once more on its way back; ``pins`` is what the chip sees."""

    def __init__(self, core):
        self.core = core
        self.pins = core.sdram_pins.signature.create(path=("chip",))

    def elaborate(self, platform):
        m, inner = Module(), self.core.sdram_pins
        m.submodules.core = self.core
        idle = {"cke": 1, "cs_n": 1, "ras_n": 1, "cas_n": 1, "we_n": 1}   # deselected at reset
        for name in ("cke", "cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o", "dq_oe"):
            reg = Signal.like(getattr(inner, name), init=idle.get(name, 0), name=f"io_{name}")
            m.d.pipe += reg.eq(getattr(inner, name))
            m.d.comb += getattr(self.pins, name).eq(reg)
        m.d.pipe += inner.dq_i.eq(self.pins.dq_i)
        return m


@pytest.mark.regress
@pytest.mark.parametrize("pin_cycles", [0, SDRAM_PIN_CYCLES])
def test_frames_from_the_map_in_sdram_equal_the_golden_frames(pin_cycles):
    """``pin_cycles`` 0: the controller's pins are the chip's; SDRAM_PIN_CYCLES: the pins as
    the ULX3S top registers them (BoardIO), the controller told so."""
    scene = load_scene_config("default", {"angle_bits": 10, "texture_size": 16,
                                          "map_memory": "axi"})
    mode = MODES["test"]
    words, texels, constants, table = board_data(scene)
    table = table[:4]
    sdram, flash_cfg, contents = board_parts(scene, pin_cycles)
    core = BoardCore(scene.hardware, mode, None, constants, table, texels,
                     pipe_hz=PIPE_MHZ * 1e6, sdram=sdram, flash=flash_cfg)
    top = BoardIO(core) if pin_cycles else core
    chip_pins = top.pins if pin_cycles else core.sdram_pins
    model = SdramModel(sdram.variant, PIPE_MHZ, powerup_ns=40 * 1000 / PIPE_MHZ,
                       init_refreshes=2)
    flash = SpiFlash(contents, min_phase=flash_cfg.half_period, delay=flash_cfg.half_period - 1)
    frames, seen, result = 2, [], {}

    async def flash_pins(ctx):          # each pipe clock: the pins after the edge, MISO for it
        spi = core.spi
        while True:
            await ctx.tick("pipe")
            ctx.set(spi.miso, flash.step(ctx.get(spi.cs_n), ctx.get(spi.sclk), ctx.get(spi.mosi)))

    async def display(ctx):
        t = core.timing
        limit = 400_000
        for _ in range(limit):
            if ctx.get(t.de) and ctx.get(core.shows):
                seen.append(ctx.get(core.pixel))
            if len(seen) >= frames * mode.pixels:
                break
            await ctx.tick()
        result.update(underflow=ctx.get(core.underflow), order=ctx.get(core.order_error),
                      done=ctx.get(core.loader.done), error=ctx.get(core.loader.error))

    sim = Simulator(top)
    sim.add_clock(1 / mode.pixel_hz)
    sim.add_clock(1e-6 / PIPE_MHZ, domain="pipe")
    async def sdram_pins(ctx):
        await model.process(ctx, chip_pins, "pipe")

    sim.add_process(sdram_pins)
    sim.add_testbench(flash_pins, background=True)
    sim.add_testbench(display)
    sim.run()
    assert model.error is None, model.error
    assert flash.errors == [] and flash.reads == [(OFFSET, flash_cfg.length)]
    assert result == {"underflow": 0, "order": 0, "done": 1, "error": 0}
    px = np.array(seen, np.int64)
    rgb = np.stack([(px >> 16) & 255, (px >> 8) & 255, px & 255], -1)
    got = rgb.reshape(frames, mode.v_active, mode.h_active, 3)
    for f in range(frames):
        want = golden_frame(scene, mode, f, table, words, texels)
        assert np.array_equal(got[f], want), \
            f"frame {f}: {np.count_nonzero(np.any(got[f] != want, -1))} pixels differ"


def test_the_memory_parts_must_agree():
    """A map in the SDRAM without the memory parts, or the parts with a map in block RAM,
    or data widths that differ, is refused naming the parameter."""
    axi = load_scene_config("default", {"angle_bits": 10, "texture_size": 16,
                                        "map_memory": "axi"})
    bram = load_scene_config("default", {"angle_bits": 10, "texture_size": 16})
    sdram, flash, _ = board_parts(axi)
    mode = MODES["test"]
    words, texels, constants, table = board_data(bram)
    with pytest.raises(BumpError) as e:
        BoardCore(axi.hardware, mode, None, constants, table, texels, pipe_hz=1e8)
    assert e.value.field == "map_memory"
    with pytest.raises(BumpError) as e:
        BoardCore(bram.hardware, mode, words, constants, table, texels, pipe_hz=1e8,
                  sdram=sdram, flash=flash)
    assert e.value.field == "map_memory"
    wide = SdramConfig(freq_mhz=PIPE_MHZ, powerup_cycles=40, data_bits=64)
    with pytest.raises(BumpError) as e:
        BoardCore(axi.hardware, mode, None, constants, table, texels, pipe_hz=1e8,
                  sdram=wide, flash=flash)
    assert e.value.field == "data_bits" and "64" in str(e.value)


def test_the_preload_holds_what_the_controller_writes():
    """gen/flow/board.sdram_preload (the SDRAM model's contents for a simulation without
    the flash copy) against the controller itself: images written through its AXI port in
    the loader's bursts (one SDRAM burst each), one across a bank's and a row's end, one
    across the chip's end (the address wraps), land in the datasheet model at exactly the
    [bank, row, column] words the preload puts them, and nowhere else."""
    cfg = SdramConfig(powerup_cycles=20, init_refreshes=2)
    step = 2 * cfg.burst                        # bytes a loader's AXI burst writes
    rng = np.random.default_rng(5)
    row_bytes = cfg.chip.cols * 2               # one row of one bank
    images = {cfg.chip.banks * row_bytes - 256: rng.integers(0, 256, 512, np.uint8).tobytes(),
              cfg.chip.bytes - 64: rng.integers(0, 256, 128, np.uint8).tobytes()}
    ops = [("w", base + at, image[at:at + step], [(1 << cfg.data_bits // 8) - 1] * (step * 8 // cfg.data_bits))
           for base, image in images.items() for at in range(0, len(image), step)]
    # a read last: run() waits for its data, so the last WRITE burst has reached the chip
    _, _, model = run(cfg, [*ops, ("r", 1 << 20, step)])
    pre = sum(sdram_preload(cfg, base, image).astype(np.int64) for base, image in images.items())
    assert len(model.mem) == sum(len(i) for i in images.values()) // 2
    for where, word in model.mem.items():
        assert pre[where] == word, f"{where}: preload {pre[where]:#06x}, written {word:#06x}"
    assert np.count_nonzero(pre) == np.count_nonzero(list(model.mem.values()))
    # the model reads the preload where nothing was written since
    chip = SdramModel(cfg.variant, cfg.freq_mhz, preload=pre.astype(np.uint16))
    where = next(iter(model.mem))
    assert chip.word(where) == model.mem[where] and chip.word((0, 5, 5)) == 0
