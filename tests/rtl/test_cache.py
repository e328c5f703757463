"""TextureCache (rtl/cache.py), and BumpPipeline with map_memory = "axi", in the Amaranth simulator against a Python AXI memory
(sim/axi_memory.py): every texel bit-exact and the AR request stream equal to the golden
cache model's (sim/golden/cache.py), under random input gaps, output backpressure, AR and R
stalls and memory latencies, without deadlock; the AXI4 manager rules are checked every
cycle by the memory."""

import numpy as np
import pytest

from bumprtl.gen.cli.main import main
from bumprtl.rtl.cache import (
    CACHE_LATENCY,
    CacheGeometry,
    TextureCache,
    scene_geometry,
    scene_levels,
    tiled_image,
)
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.axi_memory import AxiReadMemory
from bumprtl.sim.golden.cache import (
    blocking_cycles,
    cache_stimulus,
    random_levels,
    run_cache,
    run_scene_cache,
    stream_cycles,
)
from bumprtl.sim.golden.fixed.pipeline import (
    as_payload_list,
    pipeline_fixed,
    random_inputs,
    random_map,
)
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
from bumprtl.sim.traffic import PATTERNS


def check_cache(geom, n=150, pattern="both", latency=2, ar_stall=0.3, r_stall=0.3, seed=0):
    """Run ``n`` pixels; assert bit-exact texels, tags in order and the golden AR stream.
    Returns (golden run, cycles)."""
    levels = random_levels(geom, seed)
    u, v, level = cache_stimulus(geom, n, seed)
    golden = run_cache(geom, u, v, level, levels)
    dut = TextureCache(geom, extra={"tag": 8})
    mem = AxiReadMemory(dut.axi, tiled_image(geom, levels), geom.data_bits, geom.base,
                        latency, ar_stall, r_stall, seed)
    inputs = [{"u": int(u[k]), "v": int(v[k]), "tag": k & 255,
               **({"level": int(level[k])} if geom.mip_levels > 1 else {})} for k in range(n)]
    out, cycles = simulate_stream(dut, inputs, pattern, seed=seed,
                                  max_cycles=(n + 1) * (latency + 4 * geom.beats + 20),
                                  models=[mem])
    assert [o["tag"] for o in out] == [k & 255 for k in range(n)]
    bad = [k for k in range(n) if out[k]["texel"] != golden.texel[k]]
    assert not bad, (f"{len(bad)} texels differ, first pixel {bad[0]}: RTL "
                     f"{out[bad[0]]['texel']:#x}, golden {int(golden.texel[bad[0]]):#x}")
    assert mem.requests == golden.requests
    return golden, cycles


@pytest.mark.parametrize("pattern", sorted(PATTERNS))
def test_cache_bit_exact_default_geometry(pattern):
    geom = CacheGeometry(64, 3, 28, sets=8, ways=2)
    golden, _ = check_cache(geom, pattern=pattern, seed=len(pattern))
    assert 0.3 < golden.hit_rate < 0.95 and golden.evictions      # both paths exercised


@pytest.mark.parametrize("latency", [1, 7, 30])
def test_cache_bit_exact_under_latency(latency):
    geom = CacheGeometry(32, 2, 28, sets=4, ways=2, base=1 << 16)
    check_cache(geom, n=100, latency=latency, seed=latency)


@pytest.mark.parametrize("texel_bits,data_bits,ways,block", [(8, 32, 4, 4), (16, 64, 4, 4),
                                                             (28, 64, 1, 4), (8, 64, 2, 8)])
def test_cache_bit_exact_geometries(texel_bits, data_bits, ways, block):
    """Several texels a beat (slot select), 4-way pseudo-LRU, direct-mapped (one level),
    8 x 8 lines."""
    geom = CacheGeometry(64, 1 if ways == 1 else 4, texel_bits, sets=4, ways=ways, block=block, data_bits=data_bits)
    golden, _ = check_cache(geom, n=120, seed=texel_bits + ways)
    assert golden.evictions


def test_cache_bit_exact_nonsquare_map():
    """A 64 x 32 map (texture_height 32) of three levels (64 x 32, 32 x 16, 16 x 8): lines
    of 4 x 4 blocks, 16 a row and 8 a column at level 0; the u and v ports of their own
    widths (6 and 5 bits)."""
    geom = CacheGeometry(64, 3, 28, sets=8, texture_height=32)
    assert geom.lines == 128 + 32 + 8
    dut = TextureCache(geom)
    dut._MustUse__silence = True                  # its ports only: check_cache builds its own
    assert (dut.i.payload.u.shape().width, dut.i.payload.v.shape().width) == (6, 5)
    golden, _ = check_cache(geom, n=120, seed=11)
    assert golden.evictions


@pytest.mark.parametrize("ways", [1, 2])
def test_cache_bit_exact_with_one_set(ways):
    """sets = 1: no set bits in the address, every line competes for the one set's ways."""
    geom = CacheGeometry(32, 2, 28, sets=1, ways=ways)
    assert geom.set_bits == 0
    golden, _ = check_cache(geom, n=100, seed=3)
    assert golden.evictions


def test_cache_hits_at_one_pixel_a_clock():
    """A scan the cache holds after its first pass: the second pass hits every pixel and
    takes one cycle a pixel (no input gaps, no backpressure)."""
    geom = CacheGeometry(16, 1, 28, sets=16, ways=1)
    v, u = np.mgrid[0:16, 0:16]
    levels = random_levels(geom)
    one = [{"u": int(a), "v": int(b)} for a, b in zip(u.ravel(), v.ravel(), strict=True)]
    cycles = []
    for inputs in (one, one + one):
        dut = TextureCache(geom)
        mem = AxiReadMemory(dut.axi, tiled_image(geom, levels), 32)
        out, n = simulate_stream(dut, inputs, models=[mem])
        assert [o["texel"] for o in out] == [int(w) for w in levels[0].ravel()] * (len(inputs) // 256)
        assert len(mem.requests) == geom.lines
        cycles.append(n)
    assert cycles[1] - cycles[0] == len(one)


def _cycles(geom, latency, n, seed, levels_seed=None):
    """``n`` pixels of cache_stimulus through the RTL, memory and sink never stalling: its
    texels and AR stream checked against the golden model; returns (the RTL's cycles, the
    cycle model's: the reset's flush, stream_cycles, the hit latency, golden run)."""
    levels = random_levels(geom, seed if levels_seed is None else levels_seed)
    u, v, level = cache_stimulus(geom, n, seed)
    golden = run_cache(geom, u, v, level, levels)
    dut = TextureCache(geom)
    mem = AxiReadMemory(dut.axi, tiled_image(geom, levels), geom.data_bits, latency=latency)
    pixels = [{"u": int(a), "v": int(b), "level": int(c)} for a, b, c in zip(u, v, level, strict=True)]
    out, cycles = simulate_stream(dut, pixels, max_cycles=50_000, models=[mem])
    assert [o["texel"] for o in out] == golden.texel.tolist()
    assert mem.requests == golden.requests
    return cycles, geom.sets + stream_cycles(golden, geom, latency) + CACHE_LATENCY, golden


@pytest.mark.parametrize("latency", [1, 9])
@pytest.mark.parametrize("geom", [CacheGeometry(64, 3, 28, sets=8),
                                  CacheGeometry(64, 3, 8, sets=4, data_bits=64),
                                  CacheGeometry(64, 3, 28, sets=2, queue=4, misses=2),
                                  CacheGeometry(64, 3, 8, sets=2, ways=1, queue=8, misses=1)])
def test_cycle_model_counts_the_rtl_cycles(geom, latency):
    """sim/golden/cache.stream_cycles (what bumprtl bench memory reports) is the RTL's count
    for a stall-free memory and sink, the reset's flush (sets cycles) and the hit latency
    aside."""
    cycles, predicted, _ = _cycles(geom, latency, 80, latency, levels_seed=0)
    assert cycles == predicted


def test_misses_overlap():
    """A miss-heavy stream (a random jump every few pixels) at latency 60: the non-blocking
    cache takes far fewer cycles than a blocking one with the same hits and misses (one
    miss at a time: sim/golden/cache.blocking_cycles), and exactly the cycle model's."""
    geom = CacheGeometry(64, 3, 28, sets=8)
    cycles, predicted, golden = _cycles(geom, 60, 120, 5)
    blocking = blocking_cycles(golden, geom, 60)
    assert len(golden.requests) > 20 and cycles - geom.sets - CACHE_LATENCY < blocking / 2
    assert cycles == predicted


# The default scene at small widths, two levels, wrap; the same with clamp addressing.
AXI_SCENE = {"texture_size": 16, "angle_bits": 8, "frac_bits": 8, "tag_bits": 6, "mip_levels": 2,
             "map_memory": "axi"}


@pytest.mark.parametrize("base,addressing,latency,pattern,data_bits", [
    ("default", "wrap", 2, "both", 32), ("default", "clamp", 20, "both", 32),
    ("default", "wrap", 60, "backpressure", 32), ("two-lights", "clamp", 7, "both", 64)])
def test_pipeline_axi_bit_exact_under_memory_latency(base, addressing, latency, pattern,
                                                     data_bits):
    """BumpPipeline with map_memory = "axi": its outputs bit-exact with the golden pipeline
    (the same model as the block-RAM map's), the AR stream the golden cache model's, under
    AR/R stalls, input gaps and backpressure; a miss stalls only the front. Two lights take
    the pipeline's layered wiring (the default scene its direct chain)."""
    scene = load_scene_config({**BUILTIN[base], **AXI_SCENE, "addressing": addressing})
    rng = np.random.default_rng(latency)
    words = random_map(scene, rng)
    inputs = random_inputs(scene, 80, rng)
    dut = BumpPipeline(scene.hardware, cache={"sets": 4, "data_bits": data_bits})
    geom = dut.units["fetch"].geom
    mem = AxiReadMemory(dut.axi, tiled_image(geom, scene_levels(scene, words)), geom.data_bits,
                        latency=latency, ar_stall=0.3, r_stall=0.3, seed=latency)
    payloads = as_payload_list(inputs)
    out, _ = simulate_stream(dut, payloads, pattern, seed=latency, max_cycles=40_000,
                             models=[mem])
    assert_bit_exact(out, pipeline_fixed(inputs, scene, words), payloads)
    golden = run_scene_cache(scene.hardware, geom, inputs, words)
    assert mem.requests == golden.requests and golden.evictions


@pytest.mark.parametrize("addressing", ["wrap", "clamp"])
def test_pipeline_axi_nonsquare_map_bit_exact(addressing):
    """A 32 x 16 map of two levels (texture_height 16) in AXI memory: u wraps or clamps by
    each level's width, v by its height (random coordinates over the whole signed port
    range); the outputs bit-exact with the golden pipeline, the AR stream the golden cache
    model's."""
    scene = load_scene_config({**BUILTIN["default"], **AXI_SCENE, "texture_size": 32,
                               "texture_height": 16, "addressing": addressing})
    rng = np.random.default_rng(5)
    words = random_map(scene, rng)
    assert len(words) == 32 * 16 + 16 * 8
    inputs = random_inputs(scene, 80, rng)
    dut = BumpPipeline(scene.hardware, cache={"sets": 4})
    geom = dut.units["fetch"].geom
    assert (geom.texture_size, geom.map_height) == (32, 16)
    mem = AxiReadMemory(dut.axi, tiled_image(geom, scene_levels(scene, words)), geom.data_bits,
                        latency=7, ar_stall=0.3, r_stall=0.3, seed=5)
    payloads = as_payload_list(inputs)
    out, _ = simulate_stream(dut, payloads, "both", seed=5, max_cycles=40_000,
                             models=[mem])
    assert_bit_exact(out, pipeline_fixed(inputs, scene, words), payloads)
    golden = run_scene_cache(scene.hardware, geom, inputs, words)
    assert mem.requests == golden.requests


def test_map_memory_refusals():
    with pytest.raises(BumpError, match="map_memory must be one of bram, axi"):
        load_scene_config({"map_memory": "dram"})
    with pytest.raises(BumpError, match="map_memory = 'axi' needs texture = false"):
        load_scene_config({"map_memory": "axi", "texture": True})
    with pytest.raises(BumpError, match="map_memory = 'axi' needs texture = false"):
        load_scene_config({"map_memory": "axi", "texture": True, "shading": "palette"})
    with pytest.raises(BumpError, match="needs a map: bump_map = 'varying'"):
        load_scene_config({"map_memory": "axi", "bump_map": "flat"})
    with pytest.raises(BumpError, match="cache_ways: ways must be a power of two"):
        load_scene_config({"map_memory": "axi", "cache_ways": 3})
    with pytest.raises(BumpError, match="cache_sets = 16 applies to map_memory = 'axi'"):
        load_scene_config({"cache_sets": 16})
    scene = load_scene_config({"map_memory": "axi", "cache_sets": 16, "axi_data_bits": 64})
    assert (scene_geometry(scene.hardware).sets, scene_geometry(scene.hardware).beats) == (16, 8)
    bram = BumpPipeline(load_scene_config({}).hardware)
    bram._MustUse__silence = True                 # built for its ports only
    assert "axi" not in bram.signature.members


def test_cli_refuses_axi_with_a_colour_texture_in_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["emit", "pipeline", "--scene", "textured", "--map-memory", "axi",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "texture = false" in err and len(err.strip().splitlines()) == 1 and not out.exists()


def test_cli_refuses_a_cache_larger_than_the_block_ram(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["emit", "pipeline", "--map-memory", "axi", "--cache-sets", "4096",
                 "--cache-ways", "16", "--out", str(out)]) == 2
    assert "fewer sets or ways" in capsys.readouterr().err and not out.exists()


def _pipeline_cycles(scene, latency, n=120, seed=3):
    """(cycles, golden cycle model's prediction) of the palette pipeline of ``scene`` on
    ``n`` random pixels, its memory never stalling, its output always taken: the reset's
    flush, stream_cycles of the scene's own geometry, the pipeline's port latency."""
    rng = np.random.default_rng(seed)
    words, inputs = random_map(scene, rng), random_inputs(scene, n, rng)
    dut = BumpPipeline(scene.hardware)
    geom = scene_geometry(scene.hardware)
    assert dut.units["fetch"].geom == geom
    mem = AxiReadMemory(dut.axi, tiled_image(geom, scene_levels(scene, words)), geom.data_bits,
                        latency=latency)
    _, cycles = simulate_stream(dut, as_payload_list(inputs), max_cycles=50_000,
                                models=[mem])
    run = run_scene_cache(scene.hardware, geom, inputs, words)
    return cycles, geom.sets + stream_cycles(run, geom, latency) + dut.port_latency


def test_queue_and_outstanding_keys_set_the_cycle_schedule():
    """cache_queue and cache_outstanding reach the RTL and the golden model from the one
    scene: a 4-entry queue with 2 bursts outstanding takes more cycles than the defaults on
    a miss-heavy stream at latency 30, and each count is the cycle model's exactly."""
    keys = {**BUILTIN["palette"], "texture_size": 64, "mip_levels": 3, "tag_bits": 8,
            "map_memory": "axi", "cache_sets": 8}
    small = load_scene_config({**keys, "cache_queue": 4, "cache_outstanding": 2})
    assert scene_geometry(small.hardware).queue == 4
    assert scene_geometry(small.hardware).misses == 2
    got_small, want_small = _pipeline_cycles(small, 30)
    got, want = _pipeline_cycles(load_scene_config(keys), 30)
    assert (got_small, got) == (want_small, want)
    assert got_small > 1.5 * got


def test_queue_and_outstanding_refusals(tmp_path, capsys):
    with pytest.raises(BumpError, match=r"cache_queue: queue must be a power of two in \[2, 1024\]"):
        load_scene_config({"map_memory": "axi", "cache_queue": 3})
    with pytest.raises(BumpError, match=r"cache_outstanding: misses must be a power of two in \[1, 64\]"):
        load_scene_config({"map_memory": "axi", "cache_outstanding": 128})
    with pytest.raises(BumpError, match="cache_queue = 16 applies to map_memory = 'axi'"):
        load_scene_config({"cache_queue": 16})
    out = tmp_path / "out"
    assert main(["emit", "pipeline", "--map-memory", "axi", "--cache-outstanding", "0",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "cache_outstanding" in err and len(err.strip().splitlines()) == 1 and not out.exists()


def test_stamp_wrap_in_rtl_is_the_cycle_models():
    """3-bit stamps (the least for a 4-entry queue) wrap every 8 pixels: a stale stamp then
    reads as a queued pixel's and holds a miss until the queue has drained. The RTL's
    texels and AR stream stay the golden model's, and its cycles are stream_cycles' with
    the wrap modelled, which differ from the same stream's with 16-bit stamps (so the
    wrap was reached and changed the schedule)."""
    keys = {"texture_size": 64, "mip_levels": 3, "texel_bits": 28, "sets": 2, "queue": 4}
    narrow = CacheGeometry(**keys, stamp_bits=3)
    wide = CacheGeometry(**keys)
    assert wide.stamp_bits == 16
    got_narrow, want_narrow, _ = _cycles(narrow, 9, 300, 11)
    got_wide, want_wide, _ = _cycles(wide, 9, 300, 11)
    assert (got_narrow, got_wide) == (want_narrow, want_wide)
    assert got_narrow > got_wide
    with pytest.raises(BumpError, match=r"stamp_bits must be an integer in \[3, 32\]"):
        CacheGeometry(**keys, stamp_bits=2)


def test_stamp_wrap_bit_exact_under_stalls():
    """Wrapping stamps under AR/R stalls, input gaps and backpressure: no line a queued pixel
    needs is evicted (every texel the golden model's), the AR stream the golden model's."""
    check_cache(CacheGeometry(64, 3, 28, sets=2, queue=8, stamp_bits=4), n=300, latency=20,
                seed=4)
