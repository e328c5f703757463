"""cocotb testbench for the emitted SdramController (rtl/sdram.py) on the datasheet model
of the chip (sim/sdram_model.py), which raises on any illegal command or timing violation.

Random AXI traffic from cocotbext-axi's ``AxiMaster`` (a driver we did not write): rounds
of write bursts, each awaited, then reads issued all at once (the controller pipelines
them), R and B under random backpressure; addresses in a few rows of every bank so that
row hits, row misses and bank switches all occur, every burst a whole number of SDRAM
bursts. Every read is compared byte for byte with a Python dict of what was written;
words never written read as the model's zeros.

Environment: BUMPRTL_SDRAM (the SdramConfig's fields as JSON), BUMPRTL_SAMPLES (rounds),
BUMPRTL_SEED.
"""

import itertools
import json
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge, SimTimeoutError, Timer, with_timeout
from cocotb.utils import get_sim_time
from cocotbext.axi import AxiBus, AxiMaster, AxiReadBus, AxiWriteBus

from bumprtl.sim.sdram_model import SdramModel
from bumprtl.sim.tb.stream import samples

AXI_INPUTS = ("rd__arid", "rd__araddr", "rd__arlen", "rd__arsize", "rd__arburst", "wr__awid",
              "wr__awaddr", "wr__awlen", "wr__awsize", "wr__awburst", "wr__wdata", "wr__wstrb",
              "wr__wlast", "rd__arvalid", "rd__rready", "wr__awvalid", "wr__wvalid", "wr__bready")
PINS = ("cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o", "dq_oe", "cke")


class SdramPins:
    """The model on the DUT's ``sdram__*`` pins: each cycle it reads the pins the chip
    samples at the next edge and drives ``dq_i`` for the cycle after. ``model`` raises on
    a violation; the coroutine stores it in ``error`` and stops, and the test fails."""

    def __init__(self, dut, model, prefix="sdram__"):
        self.dut, self.model, self.prefix = dut, model, prefix
        self.error = None
        self.cycles = 0

    def _pin(self, name):
        return getattr(self.dut, self.prefix + name)

    async def run(self):
        drive, value = False, 0
        dq_i = self._pin("dq_i")
        while True:
            await RisingEdge(self.dut.clk)
            dq_i.value = value if drive else 0
            await ReadOnly()
            rst = str(self.dut.rst.value)
            if rst != "0":                      # reset, or not yet driven
                self.model.reset()
                drive = False
                continue
            raw = {name: self._pin(name).value for name in PINS}
            unknown = [name for name, v in raw.items() if not set(str(v)) <= {"0", "1"}]
            if unknown:
                self.error = (f"cycle {self.model.n} ({get_sim_time('ns')} ns): X or Z on "
                              f"{', '.join(unknown)}")
                return
            try:
                drive, value = self.model.cycle(**{k: int(v) for k, v in raw.items()})
            except AssertionError as e:           # the model's SdramViolation
                self.error = e
                return
            self.cycles += 1


def model_for(cfg):
    """The datasheet model told the bench's shortcuts: the power-up wait in ns."""
    f = cfg["freq_mhz"]
    power = cfg.get("powerup_cycles")
    return SdramModel(cfg.get("variant", "32mb"), f,
                      powerup_ns=None if power is None else power * 1000 / f)


async def start(dut, cfg):
    """Clock, the AXI master (its outputs driven before the reset ends), the model on the
    pins, reset; returns the :class:`SdramPins` and the ``AxiMaster``."""
    period_ns = 1000 / cfg["freq_mhz"]
    dut.rst.value = 1
    for name in AXI_INPUTS:           # the master leaves a channel's payload undriven until used
        getattr(dut, name).value = 0
    cocotb.start_soon(Clock(dut.clk, 2 * round(period_ns * 500), unit="ps").start())   # even ps
    bus = AxiBus(write=AxiWriteBus.from_prefix(dut, "wr_"), read=AxiReadBus.from_prefix(dut, "rd_"))
    axi = AxiMaster(bus, dut.clk, dut.rst)
    pins = SdramPins(dut, model_for(cfg))
    cocotb.start_soon(pins.run())
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    return pins, axi


def _pauses(rng, p):
    return itertools.cycle([rng.random() < p for _ in range(997)])


def random_bursts(rng, cfg, n):
    """``n`` (address, bytes) in 4 rows of each bank, whole SDRAM bursts, aligned."""
    unit = 2 * cfg.get("burst", 8)
    cols = {"32mb": 512, "64mb": 1024}[cfg.get("variant", "32mb")]
    row_bytes = 2 * cols
    out = []
    for _ in range(n):
        row, bank = rng.randrange(4), rng.randrange(4)
        length = unit * rng.randint(1, max(1, 128 // unit))
        col = rng.randrange(0, row_bytes - length + 1, unit)
        out.append((((row * 4 + bank) * row_bytes) + col, length))
    return out


@cocotb.test(timeout_time=20, timeout_unit="ms")
async def random_traffic_matches_memory(dut):
    cfg = json.loads(os.environ["BUMPRTL_SDRAM"])
    seed = int(os.environ.get("BUMPRTL_SEED", 1))
    rng = random.Random(seed)
    pins, axi = await start(dut, cfg)
    axi.read_if.r_channel.set_pause_generator(_pauses(rng, 0.2))
    axi.write_if.b_channel.set_pause_generator(_pauses(rng, 0.3))
    axi.write_if.w_channel.set_pause_generator(_pauses(rng, 0.1))

    memory = {}
    rounds, reads, written = samples(6), 0, 0
    for _ in range(rounds):
        for addr, length in random_bursts(rng, cfg, rng.randint(1, 4)):
            data = rng.randbytes(length)
            await axi.write(addr, data, awid=0)
            memory.update({addr + k: b for k, b in enumerate(data)})
            written += length
        batch = random_bursts(rng, cfg, rng.randint(1, 4))
        ops = [cocotb.start_soon(axi.read(addr, length, arid=0)) for addr, length in batch]
        for (addr, length), op in zip(batch, ops, strict=True):
            try:
                got = (await with_timeout(op, 100, "us")).data
            except SimTimeoutError:
                raise AssertionError(f"read {addr:#x}+{length} not answered in 100 us; "
                                     f"model: {pins.error}") from None
            want = bytes(memory.get(addr + k, 0) for k in range(length))
            assert pins.error is None, pins.error
            assert got == want, (f"read {addr:#x}+{length}: first differing byte "
                                 f"{next(k for k in range(length) if got[k] != want[k])}")
            reads += 1
        assert pins.error is None, pins.error
    await Timer(1, unit="ns")
    assert pins.error is None, pins.error
    dut._log.info("%d rounds: %d bytes written, %d read bursts matched; %d cycles, commands %s",
                  rounds, written, reads, pins.cycles, pins.model.commands)


@cocotb.test(timeout_time=2, timeout_unit="ms")
async def refresh_keeps_data_while_idle(dut):
    """Written, then idle for 3 refresh intervals (refreshes only), then read back."""
    cfg = json.loads(os.environ["BUMPRTL_SDRAM"])
    pins, axi = await start(dut, cfg)
    data = bytes(range(64))
    await axi.write(0x2040, data, awid=0)
    refs = pins.model.commands.get("REF", 0)
    for _ in range(3 * int(7.8125 * cfg["freq_mhz"])):
        await RisingEdge(dut.clk)
    assert pins.error is None, pins.error
    assert pins.model.commands["REF"] >= refs + 3, pins.model.commands
    got = (await axi.read(0x2040, 64, arid=0)).data
    assert got == data
    assert pins.error is None, pins.error
