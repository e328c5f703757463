"""PaletteLUT in the Amaranth simulator: bit-exact against the cycle model, with host writes
racing lookups and swaps at random times (also under backpressure), every traffic pattern;
and the palette scene pipeline, whose pixels read the bank in front when the pipeline
accepted them although the fetch stages sit between its input and the LUT."""

import random

import numpy as np
import pytest
from amaranth.sim import Simulator

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.units import build_unit, emit_unit
from bumprtl.rtl.cache import scene_levels, tiled_image
from bumprtl.rtl.config import Config
from bumprtl.rtl.palette import (
    CHANNELS,
    READ_LATENCY,
    PaletteLUT,
    blend_eq1,
    blend_eq2,
    index_bits,
    mul8,
)
from bumprtl.rtl.pipe import EDGE_LATENCY
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.amaranth_stream import Drive, driven
from bumprtl.sim.axi_memory import AxiReadMemory
from bumprtl.sim.formal.mutants import SwapAheadPalette
from bumprtl.sim.golden.cache import run_scene_cache
from bumprtl.sim.golden.fixed.palette_lut import PaletteLUTModel, host_op, pack_rgba, unpack_rgba
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed, random_inputs, random_map
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.traffic import PATTERNS

CONFIGS = [Config(palette_size=200, tag_bits=8),                       # indices 200..255 out of range
           Config(palette_size=100, palette_blend=True, tag_bits=8)]


def _inputs(cfg, n, seed):
    rng = random.Random(seed)
    top = 1 << index_bits(cfg)
    edges = [0, cfg.palette_size - 1, cfg.palette_size % top, top - 1]
    out = []
    for k, index in enumerate(edges + [rng.randrange(top) for _ in range(n)]):
        px = {"index": index, "tag": k & 0xFF}
        if cfg.palette_blend:
            px["base"] = {c: rng.choice([0, 255, rng.randrange(256)]) for c in CHANNELS}
        out.append(px)
    return out


def run_lut(cfg, inputs, pattern, seed=1, unit=PaletteLUT):
    """Drive pixels and random host traffic into ``unit(cfg)``; return (received, expected)
    output dicts."""
    dut = unit(cfg)
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(seed)
    model = PaletteLUTModel(cfg)
    expected, received = [], []
    out_sigs = {**{f"color.{c}": getattr(dut.o.payload.color, c) for c in CHANNELS},
                "oor": dut.o.payload.oor, "tag": dut.o.payload.tag}

    drive = Drive({"valid": dut.i.valid, "index": dut.i.payload.index, "tag": dut.i.payload.tag,
                   **({f"base.{c}": getattr(dut.i.payload.base, c) for c in CHANNELS}
                      if cfg.palette_blend else {}),
                   "w_en": dut.w_en, "w_addr": dut.w_addr,
                   **{f"w_data.{c}": getattr(dut.w_data, c) for c in CHANNELS},
                   "swap": dut.swap, "ready": dut.o.ready})

    async def testbench(ctx):
        pending, offered = list(inputs), None
        for _ in range(30 * len(inputs)):
            if len(received) == len(inputs):
                return
            if offered is None and pending and rng.random() >= gap_p:
                offered = pending.pop(0)
            drive["valid"] = offered is not None
            if offered is not None:
                drive["index"] = offered["index"]
                drive["tag"] = offered["tag"]
                for c, v in offered.get("base", {}).items():
                    drive[f"base.{c}"] = v
            write, swap = host_op(rng, cfg)
            drive["w_en"] = write is not None
            if write is not None:
                drive["w_addr"] = write[0]
                for c, v in unpack_rgba(write[1], cfg).items():
                    drive[f"w_data.{c}"] = int(v)
            drive["swap"] = swap
            drive["ready"] = rng.random() >= bp_p
            drive.set(ctx)
            _, _, i_ready, o_valid, o_ready, *vals = await ctx.tick().sample(
                dut.i.ready, dut.o.valid, dut.o.ready, *out_sigs.values())
            if offered is not None and i_ready:
                exp = model.lookup(offered["index"], offered.get("base"), cfg.palette_blend)
                expected.append({**exp, "tag": offered["tag"]})
                offered = None
            if o_valid and o_ready:
                received.append(dict(zip(out_sigs, (int(v) for v in vals), strict=False)))
            model.clock(write, swap)
        raise AssertionError(f"timeout: {len(received)} of {len(inputs)} outputs")

    sim = Simulator(driven(dut, drive))
    sim.add_clock(1e-8)
    sim.add_testbench(testbench)
    sim.run()
    return received, expected


@pytest.mark.parametrize("pattern", list(PATTERNS))
@pytest.mark.parametrize("cfg", CONFIGS, ids=["lookup200", "blend100"])
def test_bit_exact_with_racing_host(cfg, pattern):
    received, expected = run_lut(cfg, _inputs(cfg, 1200, seed=3), pattern)
    assert len(received) == len(expected)
    for n, (got, exp) in enumerate(zip(received, expected, strict=False)):
        assert got == exp, f"pixel {n} ({pattern}): RTL {got} != model {exp}"
    oor = sum(e["oor"] for e in expected)
    assert 0 < oor < len(expected)                # out-of-range indices were exercised
    assert any(e["color.r"] for e in expected)    # and written entries were read back


def test_a_stage_ahead_that_does_not_carry_the_swap_reads_the_wrong_bank():
    """The broken unit make formal's bank proof must fail (sim/formal/mutants.py's
    SwapAheadPalette: a register stage in front of the LUT, the swap not carried with the
    pixel) differs from the cycle model under the same racing host: the model reads the
    bank of each pixel's acceptance, so the check above can tell."""
    cfg = CONFIGS[0]
    received, expected = run_lut(cfg, _inputs(cfg, 400, seed=3), "both", unit=SwapAheadPalette)
    assert [r["tag"] for r in received] == [e["tag"] for e in expected]   # nothing lost
    assert received != expected


def test_out_of_range_reads_zero_even_after_writes():
    """Host writes to addresses >= sN are ignored; an out-of-range lookup gives rgba = 0
    (or, blended, the base colour times zero) with oor = 1, never X or stale data."""
    cfg = CONFIGS[0]
    model = PaletteLUTModel(cfg)
    for addr in range(1 << index_bits(cfg)):
        model.clock((addr, 0xFFFFFFFF), swap=False)
    model.clock(None, swap=True)
    assert model.lookup(cfg.palette_size) == {"color.r": 0, "color.g": 0, "color.b": 0,
                                              "color.a": 0, "oor": 1}
    inputs = [{"index": cfg.palette_size + k, "tag": k} for k in range(40)]
    received, expected = run_lut(cfg, inputs, "no_stall")
    assert received == expected
    assert all(r["oor"] == 1 and r["color.r"] == r["color.a"] == 0 for r in received)


def test_mul8_is_rounded_product_over_255():
    x, a = np.meshgrid(np.arange(256), np.arange(256))
    assert np.array_equal(mul8(x, a), np.floor(x * a / 255 + 0.5).astype(np.int64))


def test_blend_integer_vs_float():
    """The 8-bit eq. 2 (two rounded products: <= 1 LSB) and eq. 1 (the rounding of
    p = ro * ai propagates: <= 1.5 LSB) against float64, exhaustive over ro, ai."""
    ro, ai = np.meshgrid(np.arange(256), np.arange(256))
    for ri in (0, 1, 77, 128, 254, 255):
        entry = {"r": np.full_like(ro, ri), "g": np.full_like(ro, ri), "b": np.full_like(ro, ri), "a": ai}
        base = {"r": ro, "g": ro, "b": ro, "a": ro}
        f_ro, f_ai, f_ri = ro / 255, ai / 255, ri / 255
        eq2 = (f_ro * f_ai + (1 - f_ro) * f_ri) * 255
        eq1 = (f_ro * f_ai + (1 - f_ro * f_ai) * f_ri) * 255
        assert np.max(np.abs(blend_eq2(entry, base)["r"] - eq2)) <= 1.0
        assert np.max(np.abs(blend_eq1(entry, base)["r"] - eq1)) <= 1.5
        assert np.array_equal(blend_eq2(entry, base)["a"], ro)



def test_blend_every_channel_its_own_closed_form():
    """Eq. 2 and eq. 1 with a different value in every channel of the entry and the base
    colour (the test above uses one value for all three), each output channel against its
    own float64 closed form written out here: a channel read from its neighbour (r's entry
    blended into g, g's base into b, ...) is off by far more than the rounding allows."""
    rng = np.random.default_rng(2)
    n = 20000
    entry = {c: rng.integers(0, 256, n) for c in CHANNELS}
    base = {c: rng.integers(0, 256, n) for c in CHANNELS}
    edges = np.array([0, 1, 127, 128, 254, 255])
    for k, c in enumerate(CHANNELS):               # every channel at the edges, apart
        entry[c][:216] = np.repeat(edges, 36)[(np.arange(216) + 7 * k) % 216]
        base[c][:216] = np.tile(edges, 36)[(np.arange(216) + 11 * k) % 216]
    got2, got1 = blend_eq2(entry, base), blend_eq1(entry, base)
    a_in = entry["a"] / 255
    for c in ("r", "g", "b"):
        ro, ri = base[c] / 255, entry[c] / 255
        assert np.max(np.abs(got2[c] - (ro * a_in + (1 - ro) * ri) * 255)) <= 1.0, c
        assert np.max(np.abs(got1[c] - (ro * a_in + (1 - ro * a_in) * ri) * 255)) <= 1.5, c
    assert np.array_equal(got2["a"], base["a"]) and np.array_equal(got1["a"], base["a"])
    assert all(np.mean(entry[c] != entry[d]) > 0.9 for c in CHANNELS for d in CHANNELS if c < d)


def test_lut_model_blend_every_channel_its_own_closed_form():
    """The table word's channel order (r low) and the blend, through the cycle model the
    RTL is held to, against the closed form with distinct values per channel."""
    cfg = CONFIGS[1]
    model = PaletteLUTModel(cfg)
    rng = np.random.default_rng(5)
    rgba = rng.integers(0, 256, (cfg.palette_size, 4))
    for i, word in enumerate(pack_rgba(rgba, cfg)):
        model.clock((i, int(word)))
    model.clock(None, swap=True)
    for i in range(cfg.palette_size):
        base = {c: int(v) for c, v in zip(CHANNELS, rng.integers(0, 256, 4), strict=False)}
        got = model.lookup(i, base, blend=True)
        for k, c in enumerate("rgb"):
            ro, ri, ai = base[c] / 255, rgba[i, k] / 255, rgba[i, 3] / 255
            assert abs(got[f"color.{c}"] - (ro * ai + (1 - ro) * ri) * 255) <= 1.0, (i, c)
        assert got["color.a"] == base["a"]


@pytest.mark.parametrize("cfg", CONFIGS, ids=["lookup200", "blend100"])
def test_emit_lint_and_sidecar(cfg, build_dir):
    v, _ = emit_unit("palette", cfg, build_dir)
    assert lint(v) == []
    dut, side, command = build_unit("palette", cfg)
    assert side.latency == dut.port_latency == dut.latency + EDGE_LATENCY
    assert dut.latency == READ_LATENCY + cfg.palette_blend
    assert side.memory_bits == 2 * cfg.palette_size * 32
    assert side.rams["table"].depth == 2 * cfg.palette_size and not side.roms
    assert f"--palette-size {cfg.palette_size}" in command


def run_palette_pipeline(scene, n, pattern, seed=1, write_p=0.6, swap_p=0.15, cache=None,
                         latency=20):
    """BumpPipeline(palette scene) with a racing host that obeys the ``lut_w_ready``
    handshake (a write is held until it is taken) and swaps at random; every pixel's colour
    must be the model's lookup in the cycle the *pipeline* accepted it. With ``map_memory =
    "axi"`` the index map is in an AXI memory (sim/axi_memory.py, ``latency``, AR and R
    stalls) behind the cache (``cache``: CacheGeometry parameters), whose AR stream must be
    the golden cache model's. Returns (received, expected, writes held back by
    lut_w_ready)."""
    cfg = scene.config
    nrng = np.random.default_rng(seed)
    words = random_map(scene, nrng)
    inputs = random_inputs(scene, n, nrng)
    index = pipeline_fixed(inputs, scene, words)["index"]
    mem = None
    if scene.map_memory == "axi":
        dut = BumpPipeline(scene.hardware, cache=cache)
        geom = dut.units["fetch"].geom
        mem = AxiReadMemory(dut.axi, tiled_image(geom, scene_levels(scene, words)),
                            geom.data_bits, latency=latency, ar_stall=0.3, r_stall=0.3,
                            seed=seed)
    else:
        dut = BumpPipeline(scene.hardware, init=words)
    gap_p, bp_p = PATTERNS[pattern]
    rng = random.Random(seed)
    model = PaletteLUTModel(cfg)
    expected, received, held = [], [], [0]
    out_sigs = {**{f"color.{c}": getattr(dut.o.payload.color, c) for c in CHANNELS},
                "oor": dut.o.payload.oor, "tag": dut.o.payload.tag}

    fields = [k for k in ("u", "v", "level", "tag") if k in inputs]
    drive = Drive({"valid": dut.i.valid, **{k: dut.i.payload[k] for k in fields},
                   "w_en": dut.lut_w_en, "w_addr": dut.lut_w_addr,
                   **{f"w_data.{c}": getattr(dut.lut_w_data, c) for c in CHANNELS},
                   "swap": dut.lut_swap, "ready": dut.o.ready})

    async def testbench(ctx):
        nxt, offered, write = 0, None, None
        for _ in range(40 * n):
            if len(received) == n:
                return
            if offered is None and nxt < n and rng.random() >= gap_p:
                offered, nxt = nxt, nxt + 1
            drive["valid"] = offered is not None
            if offered is not None:
                for k in fields:
                    drive[k] = int(inputs[k][offered])
            if write is None:                     # a new write only once the last was taken
                write, swap = host_op(rng, cfg, write_p, swap_p)
            else:
                swap = rng.random() < swap_p
            drive["w_en"] = write is not None
            if write is not None:
                drive["w_addr"] = write[0]
                for c, v in unpack_rgba(write[1], cfg).items():
                    drive[f"w_data.{c}"] = int(v)
            drive["swap"] = swap
            drive["ready"] = rng.random() >= bp_p
            drive.set(ctx)
            _, _, i_ready, w_ready, bank, o_valid, o_ready, *vals = await ctx.tick().sample(
                dut.i.ready, dut.lut_w_ready, dut.lut_bank, dut.o.valid, dut.o.ready,
                *out_sigs.values())
            assert bank == model.front
            if offered is not None and i_ready:
                exp = model.lookup(int(index[offered]))
                expected.append({**exp, "tag": int(inputs["tag"][offered])})
                offered = None
            if o_valid and o_ready:
                received.append(dict(zip(out_sigs, (int(v) for v in vals), strict=False)))
            done = write if w_ready else None
            held[0] += write is not None and not w_ready
            model.clock(done, swap)
            if w_ready:
                write = None
        raise AssertionError(f"timeout: {len(received)} of {n} outputs")

    sim = Simulator(driven(dut, drive, *([mem.drive] if mem is not None else [])))
    sim.add_clock(1e-8)
    sim.add_testbench(testbench)
    if mem is not None:
        sim.add_testbench(mem.process, background=True)
    sim.run()
    if mem is not None:
        assert mem.requests == run_scene_cache(scene.hardware, geom, inputs, words).requests
    return received, expected, held[0]


@pytest.mark.parametrize("pattern", list(PATTERNS))
def test_pipeline_pixel_reads_the_bank_of_its_acceptance(pattern):
    """Swaps and writes racing pixels in the fetch stages (3 cycles between the pipeline's
    input and the LUT, more under backpressure): each pixel still reads the table as it
    was when the pipeline accepted it. Fails if the LUT reads the bank in front when the
    pixel reaches it, or if a write to a bank a pixel in flight still reads is let through."""
    scene = load_scene_config({"name": "p", "shading": "palette", "texture_size": 16,
                               "palette_size": 16, "tag_bits": 8})
    received, expected, held = run_palette_pipeline(scene, 400, pattern)
    assert len(received) == len(expected) == 400
    for n, (got, exp) in enumerate(zip(received, expected, strict=False)):
        assert got == exp, f"pixel {n} ({pattern}): RTL {got} != model {exp}"
    assert held > 0                               # lut_w_ready did hold writes back
    assert len({e["color.r"] for e in expected}) > 4      # written entries were read back


@pytest.mark.parametrize("palette_size,mip_levels", [(16, 2), (1000, 1)])
def test_axi_pipeline_pixel_reads_the_bank_of_its_acceptance(palette_size, mip_levels):
    """map_memory = "axi": the palette indices (8 bits, or 10 in 2-byte slots) come from an
    AXI memory at latency 20 through the cache; a pixel waits there far longer than in the
    block-RAM fetch (its queue of 8 here filled by misses), and still reads the table as it
    was when the pipeline accepted it; writes are held back the longer. Fails if the
    per-bank counters cannot count the cache's pixels (they would wrap and let a write
    through to a bank a queued pixel still reads)."""
    scene = load_scene_config({"name": "p", "shading": "palette", "texture_size": 32,
                               "mip_levels": mip_levels, "palette_size": palette_size,
                               "tag_bits": 8, "map_memory": "axi"})
    # 600 pixels: with writes held back the longer, 400 saw one colour of the 1000-entry
    # table at this seed (the check below wants the table's writes to reach the pixels)
    received, expected, held = run_palette_pipeline(scene, 600, "both", seed=palette_size,
                                                    cache={"sets": 4, "queue": 8})
    assert len(received) == len(expected) == 600
    for n, (got, exp) in enumerate(zip(received, expected, strict=False)):
        assert got == exp, f"pixel {n}: RTL {got} != model {exp}"
    assert held > 0 and len({e["color.r"] for e in expected}) > 4
