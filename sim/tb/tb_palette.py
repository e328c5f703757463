"""cocotb testbench for the emitted ``palette.v``: pixels and random host traffic (writes
to the back bank, swap strobes at any time, also under backpressure) against the
cycle-level :class:`PaletteLUTModel`, bit for bit, under every traffic pattern."""

import logging
import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ReadOnly, RisingEdge

from bumprtl.rtl.config import Config
from bumprtl.rtl.palette import CHANNELS, index_bits
from bumprtl.sim.golden.fixed.palette_lut import PaletteLUTModel, host_op
from bumprtl.sim.golden.vectors import range_corners
from bumprtl.sim.tb.stream import PATTERNS, load_sidecar, pack, samples, unpack

log = logging.getLogger("bumprtl.tb")


def _pixels(cfg, n, rng):
    """The corners (sim/golden/vectors.range_corners: the index and every base channel at
    both ends, together and alone; the table's last entry), then ``n`` random pixels."""
    top = 1 << index_bits(cfg)
    ranges = {"index": (0, top - 1),
              **({f"base.{c}": (0, 255) for c in CHANNELS} if cfg.palette_blend else {})}
    corners = range_corners(ranges)
    out = [{k: int(v[i]) for k, v in corners.items()} for i in range(len(corners["index"]))]
    out.append({**out[0], "index": cfg.palette_size - 1})
    for _ in range(n):
        px = {"index": rng.randrange(top)}
        if cfg.palette_blend:
            px.update({f"base.{c}": rng.choice([0, 255, rng.randrange(256)]) for c in CHANNELS})
        out.append(px)
    return [{**px, "tag": k & ((1 << cfg.tag_bits) - 1)} for k, px in enumerate(out)]


async def _reset(dut):
    for sig in (dut.i__valid, dut.o__ready, dut.w_en, dut.swap):
        sig.value = 0
    dut.rst.value = 1
    for _ in range(3):
        await RisingEdge(dut.clk)
    dut.rst.value = 0
    await RisingEdge(dut.clk)


async def _load_both_banks(dut, model, cfg, rng):
    """Fill both banks (the RAM keeps its contents across resets and earlier tests):
    write a whole table, swap, write another; the model sees the same cycles."""
    for bank in range(2):
        for addr in range(cfg.palette_size):
            write = (addr, rng.getrandbits(4 * cfg.color_bits))
            swap = bank == 0 and addr == cfg.palette_size - 1
            _set_host(dut, write, swap)
            model.clock(write, swap)
            await RisingEdge(dut.clk)
    _set_host(dut, None, False)


def _set_host(dut, write, swap):
    dut.w_en.value = int(write is not None)
    if write is not None:
        dut.w_addr.value = write[0]
        dut.w_data.value = write[1]          # packed rgba word, r in the low bits
    dut.swap.value = int(swap)


@cocotb.test()
@cocotb.parametrize(pattern=list(PATTERNS))
async def palette_matches_model(dut, pattern):
    meta = load_sidecar()
    cfg = Config(**meta.config)
    fin, fout = meta.input_fields, meta.output_fields
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(11)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    await _reset(dut)
    model = PaletteLUTModel(cfg)
    await _load_both_banks(dut, model, cfg, rng)
    pending, offered = _pixels(cfg, samples(500), rng), None
    total = len(pending)
    expected, received = [], []
    for _cycle in range(30 * total):
        if len(received) == total:
            break
        if offered is None and pending and rng.random() >= gap_p:
            offered = pending.pop(0)
        dut.i__valid.value = int(offered is not None)
        if offered is not None:
            dut.i__payload.value = pack(fin, offered)
        write, swap = host_op(rng, cfg)
        _set_host(dut, write, swap)
        dut.o__ready.value = int(rng.random() >= bp_p)
        await ReadOnly()
        if offered is not None and int(dut.i__ready.value):
            base = {c: offered[f"base.{c}"] for c in CHANNELS} if cfg.palette_blend else None
            expected.append({**model.lookup(offered["index"], base, cfg.palette_blend),
                             "tag": offered["tag"]})
            offered = None
        if int(dut.o__valid.value) and int(dut.o__ready.value):
            received.append(unpack(fout, int(dut.o__payload.value)))
        model.clock(write, swap)
        await RisingEdge(dut.clk)
    assert len(received) == total, f"timeout: {len(received)} of {total} outputs"
    for n, (exp, got) in enumerate(zip(expected, received, strict=False)):
        assert got == exp, f"pixel {n} ({pattern}): RTL {got} != model {exp}"
    log.info("%s: %d pixels bit-exact, %d out of range, host writes and swaps racing",
             pattern, total, sum(e["oor"] for e in expected))
