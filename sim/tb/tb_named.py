"""cocotb driver for units behind their named-ports wrappers (``bumprtl emit --ports named``),
several side by side in one design: each unit's ports appear at the top level as
``<prefix><named port>`` (e.g. ``a_in_n_phi``, ``b_out_color``), ``clk`` and ``rst``
shared.

Environment: BUMPRTL_NAMED, a JSON object ``{prefix: {"sidecar", "stimulus", "result"}}``:
the unit's sidecar (with its ``named_ports`` table), an npz of input arrays by named port
(``in_n_phi``...) and optional ``setup.<port>`` host cycles (one entry a clock, e.g. the map
written through its write port), and the npz to write (output arrays by named port,
``cycles``). Every unit is reset together, its host set-up played, then all units stream at
once with random input gaps and output stalls (seeded per prefix). Checking is the caller's.
"""

import json
import os
import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from bumprtl.rtl.sidecar import load


def _port(dut, prefix, name):
    return getattr(dut, f"{prefix}{name}")


def _mask(value, width):
    return int(value) & ((1 << width) - 1)


def _signed(value, width):
    return value - (1 << width) if value >> (width - 1) else value


async def _setup(dut, prefix, stim):
    setup = {k[len("setup."):]: v.tolist() for k, v in stim.items() if k.startswith("setup.")}
    for i in range(len(next(iter(setup.values()), []))):
        for port, values in setup.items():
            _port(dut, prefix, port).value = int(values[i])
        await RisingEdge(dut.clk)
    for port in setup:
        _port(dut, prefix, port).value = 0


async def _stream(dut, prefix, ports, stim, seed):
    """Offer every input (gaps of 1 in 4), take outputs (stalls of 1 in 4); returns the
    output arrays and the cycles from the first offer to the last output."""
    rng = random.Random(seed)
    ins = {n: p for n, p in ports.items() if p.dir == "in" and p.bits is not None}
    outs = {n: p for n, p in ports.items() if p.dir == "out" and p.bits is not None}
    cols = {n: stim[n].tolist() for n in ins}
    n = len(next(iter(cols.values())))
    got, nxt, offered, cycles = {k: [] for k in outs}, 0, False, 0
    valid, ready = _port(dut, prefix, "in_valid"), _port(dut, prefix, "out_ready")
    while len(got[next(iter(outs))]) < n:
        if not offered and nxt < n and rng.random() >= 0.25:
            for k, p in ins.items():
                _port(dut, prefix, k).value = _mask(cols[k][nxt], p.width)
            offered, nxt = True, nxt + 1
        valid.value = int(offered)
        ready.value = int(rng.random() >= 0.25)
        await ReadOnly()
        if offered and int(_port(dut, prefix, "in_ready").value):
            offered = False
        if int(_port(dut, prefix, "out_valid").value) and int(ready.value):
            for k, p in outs.items():
                v = int(_port(dut, prefix, k).value)
                got[k].append(_signed(v, p.width) if p.signed else v)
        await RisingEdge(dut.clk)
        cycles += 1
        assert cycles < 40 * (n + 100), f"{prefix}: timeout after {cycles} cycles"
    valid.value = 0
    return {k: np.array(v, np.int64) for k, v in got.items()}, cycles


@cocotb.test()
async def named_side_by_side(dut):
    units = json.loads(os.environ["BUMPRTL_NAMED"])
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    metas = {p: load(u["sidecar"]) for p, u in units.items()}
    stims = {p: dict(np.load(u["stimulus"])) for p, u in units.items()}
    dut.rst.value = 1
    for prefix, meta in metas.items():
        for name, p in meta.named_ports.ports.items():
            if p.dir == "in" and name not in ("clk", "rst"):
                _port(dut, prefix, name).value = 0
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    for prefix in units:
        await _setup(dut, prefix, stims[prefix])
    tasks = {p: cocotb.start_soon(_stream(dut, p, metas[p].named_ports.ports, stims[p],
                                          seed=i + 1))
             for i, p in enumerate(units)}
    for prefix, task in tasks.items():
        out, cycles = await task
        np.savez(units[prefix]["result"], cycles=np.array(cycles), **out)
        dut._log.info("%s: %d outputs in %d cycles", prefix, len(next(iter(out.values()))), cycles)
