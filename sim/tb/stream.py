"""cocotb stream verification components: driver, monitors, in-order scoreboard.

Payloads are packed and unpacked from the bit-field table of the sidecar
(``Sidecar.input_fields``/``output_fields``), so no testbench hard-codes a bit position. Traffic patterns
are sim/traffic.py's (after verilog-axis: no stall, random input gaps, random output
backpressure, both).
"""

import logging
import os
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from bumprtl.rtl.layouts import pack, unpack
from bumprtl.rtl.sidecar import load
from bumprtl.sim.traffic import PATTERNS

__all__ = ["PATTERNS", "load_sidecar", "pack", "unpack", "run_stream", "samples"]

log = logging.getLogger("bumprtl.tb")


def load_sidecar():
    """The :class:`~bumprtl.rtl.sidecar.Sidecar` named by ``BUMPRTL_SIDECAR``."""
    return load(os.environ["BUMPRTL_SIDECAR"])


def samples(default):
    return int(os.environ.get("BUMPRTL_SAMPLES", default))


async def _reset(dut):
    dut.rst.value = 1
    dut.i__valid.value = 0
    dut.o__ready.value = 0
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


async def run_stream(dut, meta, inputs, model, pattern, seed=1, timeout_factor=20, setup=None):
    """Drive ``inputs`` (list of field dicts) through the DUT under ``pattern``.

    Input monitor -> ``model`` (list of accepted input dicts -> list of expected output
    dicts) -> in-order check against the output monitor, field by field, bit for bit.
    ``setup``: an async function awaited after the reset, before the first pixel (the
    host's writes). Returns the number of cycles spent.
    """
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(seed)
    fin, fout = meta.input_fields, meta.output_fields
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    await _reset(dut)
    if setup is not None:
        await setup()

    accepted, received = [], []
    pending = list(inputs)
    limit = timeout_factor * (len(inputs) + 50)
    cycles = 0
    offered = None
    while len(received) < len(inputs):
        # Set inputs for this cycle (valid never waits on ready; payload held until taken).
        if offered is None and pending and rng.random() >= gap_p:
            offered = pending.pop(0)
        dut.i__valid.value = int(offered is not None)
        if offered is not None:
            dut.i__payload.value = pack(fin, offered)
        dut.o__ready.value = int(rng.random() >= bp_p)
        await ReadOnly()
        if offered is not None and int(dut.i__ready.value):
            accepted.append(offered)
            offered = None
        if int(dut.o__valid.value) and int(dut.o__ready.value):
            received.append(unpack(fout, int(dut.o__payload.value)))
        await RisingEdge(dut.clk)
        cycles += 1
        assert cycles < limit, f"timeout: {len(received)} of {len(inputs)} outputs after {cycles} cycles"

    expected = model(accepted)
    assert len(expected) == len(received)
    for n, (exp, got) in enumerate(zip(expected, received, strict=False)):
        for name, value in exp.items():
            assert got[name] == value, (
                f"output {n} field {name}: RTL {got[name]} != golden {value} "
                f"(input {accepted[n]}, pattern {pattern})")
    log.info("%s: %d outputs matched the golden model bit for bit in %d cycles",
             pattern, len(received), cycles)
    return cycles
