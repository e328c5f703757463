"""cocotb driver for the emitted pipeline.v: stream a stimulus file through it, record what
comes out.

Environment: BUMPRTL_SIDECAR (pipeline.json), BUMPRTL_STIMULUS (npz written by
``gen/render/rtl.write_stimulus``: input payload arrays ``in.<field>``, optional ``polygon.*``
and ``lut``), BUMPRTL_RESULT (npz to write: ``<pattern>.<field>`` output arrays and
``<pattern>.cycles``), BUMPRTL_PATTERNS (comma-separated traffic patterns of
sim/tb/stream.py; default no_stall). Checking is done by the caller against
sim/golden/fixed/pipeline.py, so the same run serves the render and the tests.
"""

import os
import random

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge
from tqdm import tqdm

from bumprtl.sim.tb.stream import PATTERNS, load_sidecar, pack, unpack


async def host_setup(dut, meta, stim):
    """Host cycles of the stimulus (``setup.<port>`` arrays: e.g. the map written through
    its port), the polygon registers (flat map) and the palette colour table, before the
    first pixel."""
    ports = meta.ports
    setup = {k[len("setup."):]: v.tolist() for k, v in stim.items() if k.startswith("setup.")}
    for i in range(len(next(iter(setup.values()), []))):
        for port, values in setup.items():
            getattr(dut, port).value = int(values[i])
        await RisingEdge(dut.clk)
    for port in setup:
        getattr(dut, port).value = 0
    if "poly" in ports:
        dut.poly.value = pack(meta.fields_of("poly"),
                              {k[len("polygon."):]: int(v) for k, v in stim.items()
                               if k.startswith("polygon.")})
        dut.poly_en.value = 1
        await RisingEdge(dut.clk)
        dut.poly_en.value = 0
    if "lut_w_en" in ports:
        for addr, word in enumerate(stim["lut"].tolist()):
            taken = False
            while not taken:                # held until lut_w_ready (rtl/pipeline.py)
                dut.lut_w_en.value, dut.lut_w_addr.value, dut.lut_w_data.value = 1, addr, int(word)
                await ReadOnly()
                taken = bool(int(dut.lut_w_ready.value))
                await RisingEdge(dut.clk)
        dut.lut_w_en.value, dut.lut_swap.value = 0, 1
        await RisingEdge(dut.clk)
        dut.lut_swap.value = 0


async def _reset(dut, meta):
    dut.rst.value = 1
    dut.i__valid.value = 0
    dut.o__ready.value = 0
    for port in ("poly_en", "lut_w_en", "lut_swap", "map_w_en", "tex_w_en"):
        if port in meta.ports:
            getattr(dut, port).value = 0
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


def _progress(total):
    return tqdm(total=total, unit="pix", unit_scale=True, desc="rtl", mininterval=0.5,
                disable=os.environ.get("BUMPRTL_PROGRESS", "1") == "0")


async def _stream(dut, meta, words, pattern, seed=1):
    """Offer ``words`` (packed payloads) under ``pattern``; returns (output words, cycles
    from the first offer to the last output)."""
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(seed)
    out, n, nxt, offered, cycles = [], len(words), 0, None, 0
    limit = 40 * (n + 100)
    with _progress(n) as bar:
        while len(out) < n:
            if offered is None and nxt < n and rng.random() >= gap_p:
                offered, nxt = words[nxt], nxt + 1
            dut.i__valid.value = int(offered is not None)
            if offered is not None:
                dut.i__payload.value = offered
            dut.o__ready.value = int(rng.random() >= bp_p)
            await ReadOnly()
            if offered is not None and int(dut.i__ready.value):
                offered = None
            if int(dut.o__valid.value) and int(dut.o__ready.value):
                out.append(int(dut.o__payload.value))
                bar.update(1)
            await RisingEdge(dut.clk)
            cycles += 1
            assert cycles < limit, f"timeout: {len(out)} of {n} outputs after {cycles} cycles"
    dut.i__valid.value = 0
    return out, cycles


@cocotb.test()
async def pipeline_stream(dut):
    meta = load_sidecar()
    stim = dict(np.load(os.environ["BUMPRTL_STIMULUS"]))
    fin, fout = meta.input_fields, meta.output_fields
    inputs = {k[3:]: v.tolist() for k, v in stim.items() if k.startswith("in.")}
    n = len(next(iter(inputs.values())))
    words = [pack(fin, {k: col[i] for k, col in inputs.items()}) for i in range(n)]
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    result = {}
    for pattern in os.environ.get("BUMPRTL_PATTERNS", "no_stall").split(","):
        await _reset(dut, meta)
        await host_setup(dut, meta, stim)
        out, cycles = await _stream(dut, meta, words, pattern)
        fields = [unpack(fout, w) for w in out]
        for name in fout:
            result[f"{pattern}.{name}"] = np.array([f[name] for f in fields], dtype=np.int64)
        result[f"{pattern}.cycles"] = np.array(cycles)
        dut._log.info("%s: %d pixels in %d cycles", pattern, n, cycles)
    np.savez(os.environ["BUMPRTL_RESULT"], **result)
