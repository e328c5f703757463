"""cocotb testbench: the TextureCache (rtl/cache.py) reading through the SdramController
(rtl/sdram.py) from the datasheet model of the chip (sim/sdram_model.py), in place of
sim/tb/tb_cache.py's AxiRamRead. The map's tiled image (rtl/cache.tiled_image) is first
written through the controller's AXI write port by cocotbext-axi's ``AxiMasterWrite``, as
the board loads it; then the unit is reset (the controller initialises the chip again, the
model keeps its words) and pixels stream in with random gaps and out under random
backpressure (sim/tb/stream.run_stream), every texel compared bit for bit with the golden
cache model (sim/golden/cache.py). The model raises on any command the datasheet forbids.

Environment: BUMPRTL_CACHE (the CacheGeometry's fields as JSON), BUMPRTL_SDRAM (the
SdramConfig's), BUMPRTL_SAMPLES, BUMPRTL_PATTERN, BUMPRTL_SEED.
"""

import json
import os

import cocotb
from amaranth.hdl import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from cocotb.clock import Clock
from cocotb.triggers import RisingEdge
from cocotbext.axi import AxiMasterWrite, AxiWriteBus

from bumprtl.rtl.cache import CacheGeometry, TextureCache, tiled_image
from bumprtl.rtl.sdram import SdramConfig, SdramController, axi_write_signature, sdram_signature
from bumprtl.sim.tb.stream import run_stream
from bumprtl.sim.tb.tb_cache import TAG_BITS, cache_case
from bumprtl.sim.tb.tb_sdram import AXI_INPUTS, SdramPins, model_for


class CacheOnSdram(wiring.Component):
    """A TextureCache whose AXI read port is an SdramController's: the cache's ``i`` and
    ``o``, the controller's write port ``wr`` and its pins ``sdram``."""

    def __init__(self, geom: CacheGeometry, cfg: SdramConfig):
        self.cache = TextureCache(geom, extra={"tag": TAG_BITS})
        self.ctrl = SdramController(cfg)
        members = self.cache.signature.members
        super().__init__({"i": members["i"], "o": members["o"],
                          "wr": In(axi_write_signature(cfg.addr_bits, cfg.data_bits)),
                          "sdram": Out(sdram_signature(cfg))})

    def elaborate(self, platform):
        m = Module()
        m.submodules.cache, m.submodules.ctrl = self.cache, self.ctrl
        wiring.connect(m, self.cache.axi, self.ctrl.rd)
        wiring.connect(m, wiring.flipped(self.i), self.cache.i)
        wiring.connect(m, self.cache.o, wiring.flipped(self.o))
        wiring.connect(m, wiring.flipped(self.wr), self.ctrl.wr)
        wiring.connect(m, self.ctrl.sdram, wiring.flipped(self.sdram))
        return m


async def load_image(dut, cfg, base, image):
    """Write ``image`` at ``base`` through the write port, on a clock of our own that is
    stopped afterwards (run_stream starts its own); returns the model on the pins."""
    dut.rst.value = 1
    for name in AXI_INPUTS:
        if name.startswith("wr__"):
            getattr(dut, name).value = 0
    dut.i__valid.value = 0
    dut.o__ready.value = 0
    clock = cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    writer = AxiMasterWrite(AxiWriteBus.from_prefix(dut, "wr_"), dut.clk, dut.rst)
    pins = SdramPins(dut, model_for(cfg))
    cocotb.start_soon(pins.run())
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    await writer.write(base, image, awid=0)
    for _ in range(20):             # B comes with the last WRITE command: its data follows
        await RisingEdge(dut.clk)
    assert pins.error is None, pins.error
    clock.cancel()
    return pins


@cocotb.test(timeout_time=50, timeout_unit="ms")
async def cache_matches_golden_on_sdram(dut):
    geom, n, pattern, seed, levels, (u, v, level), golden, meta = cache_case()
    cfg = json.loads(os.environ["BUMPRTL_SDRAM"])

    pins = await load_image(dut, cfg, geom.base, tiled_image(geom, levels))
    inputs = [{"u": int(u[k]), "v": int(v[k]), "level": int(level[k]), "tag": k % (1 << TAG_BITS)}
              for k in range(n)]
    index = {id(px): k for k, px in enumerate(inputs)}

    def model(accepted):
        return [{"texel": int(golden.texel[index[id(px)]]), "tag": px["tag"]} for px in accepted]

    # the controller initialises the chip again after run_stream's reset: budget for it
    init = (cfg.get("powerup_cycles") or 20000) + 200
    cycles = await run_stream(dut, meta, inputs, model, pattern, seed,
                              timeout_factor=2 * (4 * geom.beats + 40) + init // n + 1)
    assert pins.error is None, pins.error
    dut._log.info("%d pixels bit-exact through the SDRAM (hit rate %.3f, %d line fills) in "
                  "%d cycles; SDRAM commands %s", n, golden.hit_rate, len(golden.requests),
                  cycles, pins.model.commands)
