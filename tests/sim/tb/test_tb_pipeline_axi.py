"""A ``map_memory = "axi"`` scene pipeline emitted with its ``_map.bin``, under cocotb on
Icarus and Verilator against cocotbext-axi's AxiRamRead holding that image
(sim/tb/tb_pipeline_axi.py): outputs bit-exact with the golden pipeline (per-pixel
shading) or the colour-table model (palette: the indices in the ``.bin``), AR requests
with the golden cache model, memory latencies 2, 20 and 60, random stalls everywhere."""

import logging

import numpy as np
import pytest

from bumprtl.gen.cli.main import main
from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.memories import emit_scene_unit, memory_images
from bumprtl.gen.render.rtl import emit_pipeline, scene_memories, scene_stimulus
from bumprtl.rtl.cache import scene_geometry
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.golden.cache import run_scene_cache
from bumprtl.sim.golden.fixed.palette_lut import palette_colors
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
from bumprtl.sim.tb.bulk import CHUNK, TRAFFIC, run_bulk, setup_writes
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb

log = logging.getLogger(__name__)

# The default scene at small widths, a 32 x 32 map of two levels, its map in AXI memory;
# the palette scene's 8-bit index map the same way, its colour table behind the cache.
SCENES = {
    "default": load_scene_config({**BUILTIN["default"], "angle_bits": 8, "frac_bits": 8,
                                  "tag_bits": 6, "texture_size": 32, "mip_levels": 2,
                                  "map_memory": "axi"}),
    "palette": load_scene_config({**BUILTIN["palette"], "tag_bits": 6, "texture_size": 32,
                                  "mip_levels": 2, "map_memory": "axi"})}


# A 32 x 16 map (texture_height 16) of two levels, the default scene's widths: u wraps by
# each level's width and v by its height in the emitted Verilog, the _map.bin tiled W x H.
NONSQUARE = load_scene_config({**BUILTIN["default"], "angle_bits": 8, "frac_bits": 8,
                               "tag_bits": 6, "texture_size": 32, "texture_height": 16,
                               "mip_levels": 2, "map_memory": "axi"})


# make test: the default scene on Icarus; make regress: the palette scene (make test reads
# its indices through the cache in tests/rtl/test_palette.py's AXI cases) and the default
# scene on Verilator too (make test runs the texel cache against AxiRamRead on Verilator on
# its own, tests/sim/tb/test_tb_cache.py)
CASES = [pytest.param(sim, scene, marks=pytest.mark.regress
                      if scene == "palette" or sim == "verilator" else ())
         for scene in SCENES for sim in SIMULATORS]


@pytest.mark.parametrize("sim,scene", CASES)
def test_pipeline_axi_cocotb_against_axi_ram(sim, scene, build_dir):
    scene = SCENES[scene]
    images = memory_images("pipeline", scene, *scene_memories(scene))
    v, j, files = emit_scene_unit("pipeline", scene, build_dir / "rtl", images)
    assert [f.name for f in files if f.suffix == ".bin"] == ["pipeline_map.bin"]
    meta = load_sidecar(j)
    record = meta.memory_images["map"]
    assert record["bytes"] == files[0].stat().st_size
    slot = 1 if scene.shading == "palette" else 2       # an 8-bit index, a 16-bit angle pair
    assert record["bytes"] == slot * sum((32 >> n) ** 2 for n in range(2))
    assert lint(v) == []
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_pipeline_axi", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 150})
    assert (run.tests, run.failures) == (3, 0)


# make regress: make test checks the non-square map's pipeline bit for bit, its AR stream
# the golden cache's, in the Amaranth simulator with the AXI memory model, wrap and clamp
# (tests/rtl/test_cache.py), and AxiRamRead under cocotb on the square scene (above).
@pytest.mark.regress
def test_nonsquare_pipeline_axi_on_icarus(build_dir):
    """The 32 x 16 map's pipeline emitted with its _map.bin (32 x 16 + 16 x 8 texels in 2-byte
    slots; the sidecar records the map's width and height) under cocotb on Icarus against
    AxiRamRead: bit-exact with the golden pipeline, the AR stream the golden cache's, at
    memory latency 20 (the other latencies: the square scene's)."""
    scene = NONSQUARE
    images = memory_images("pipeline", scene, *scene_memories(scene))
    v, j, files = emit_scene_unit("pipeline", scene, build_dir / "rtl", images)
    meta = load_sidecar(j)
    record = meta.memory_images["map"]
    assert (record["map_width"], record["map_height"]) == (32, 16)
    assert meta.scene["texture_height"] == 16
    assert record["bytes"] == files[0].stat().st_size == 2 * (32 * 16 + 16 * 8)
    run = run_cocotb("icarus", v, "bumprtl.sim.tb.tb_pipeline_axi", build_dir / "icarus",
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 150, "COCOTB_TEST_FILTER":
                      "pipeline_matches_golden_against_axi_ram/latency=20"})
    assert (run.tests, run.failures) == (1, 0)


@pytest.mark.regress
def test_megatexel_pipeline_axi_raster_on_verilator(build_dir):
    """A 2048² map at the default widths (16 MiB of _map.bin): two frame rows of a raster
    scan at one texel per pixel, whose block rows do not fit the default cache (a miss every
    fourth pixel), bit-exact and AR stream as the golden model's at latencies 2, 20, 60."""
    scene = load_scene_config({**BUILTIN["default"], "texture_size": 2048, "map_memory": "axi"})
    images = memory_images("pipeline", scene, *scene_memories(scene))
    v, j, files = emit_scene_unit("pipeline", scene, build_dir / "rtl", images)
    assert files[0].stat().st_size == 2048 * 2048 * 4
    run = run_cocotb("verilator", v, "bumprtl.sim.tb.tb_pipeline_axi", build_dir / "verilator",
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 4096, "BUMPRTL_STIMULUS": "raster"})
    assert (run.tests, run.failures) == (3, 0)


def _bulk_frame(scene, size, sim, build_dir, patterns=tuple(TRAFFIC)):
    """``scene``'s frame at ``size`` x ``size`` (gen/render/rtl.scene_stimulus, level 0)
    through its emitted axi pipeline on the bulk path (sim/tb/bulk.py, the wrapper's AXI
    memory model holding the ``_map.bin``; a palette scene's colour table written and
    swapped in first): chunk by chunk, each chunk under ``patterns`` one after the other,
    without a reset between them. Every output field bit-exact with the golden pipeline
    (palette: the table entry of the golden index), and per pattern the AR requests (count
    and sum of addresses) the golden cache model's for the pixels in that order. Returns
    (BulkResult, CacheRun)."""
    inputs, words, _, table, _ = scene_stimulus(scene, size)
    n = len(inputs["tag"])
    v, j = emit_pipeline(scene, words, None, build_dir, None, table)
    golden, setup = pipeline_fixed(inputs, scene, words), ()
    if scene.shading == "palette":
        golden = {**palette_colors(golden, table, scene), "oor": np.zeros(n, np.int64)}
        setup = setup_writes(load_sidecar(j), table=table)
    r = run_bulk(sim, v, j, build_dir / f"bulk_{sim}", patterns, inputs=inputs,
                 expected=golden, setup=setup, keep=False)
    assert r.checked and all(r.pixels[p] == n for p in patterns)
    order = [(p, slice(s, min(s + CHUNK, n))) for s in range(0, n, CHUNK) for p in patterns]
    pixels = {k: np.concatenate([inputs[k][sl] for _, sl in order])
              for k in ("u", "v", "level") if k in inputs}
    cache = run_scene_cache(scene.hardware, scene_geometry(scene.hardware), pixels, words)
    addrs = np.array([a for a, _ in cache.requests], np.int64)
    want, at, miss = {p: [0, 0] for p in patterns}, 0, 0
    for p, sl in order:
        count = int((~cache.hit[at:at + sl.stop - sl.start]).sum())
        want[p][0] += count
        want[p][1] += int(addrs[miss:miss + count].sum())
        at, miss = at + sl.stop - sl.start, miss + count
    got = {p: [r.summary["patterns"][p]["ar"], r.summary["patterns"][p]["ar_sum"]]
           for p in patterns}
    assert got == want
    return r, cache


def test_bulk_axi_frame_on_icarus(build_dir):
    """The bulk path with its AXI memory model, reduced: a 32 x 32 frame of the palette
    scene on a 32² index map in a 4-set cache, its colour table written through the host
    ports first, four traffic patterns back to back (the cache warm from the pattern
    before)."""
    scene = load_scene_config({**BUILTIN["palette"], "tag_bits": 6, "texture_size": 32,
                               "map_memory": "axi", "cache_sets": 4})
    _, cache = _bulk_frame(scene, 32, "icarus", build_dir)
    # one texel per pixel in raster order: a block row's 8 lines fit the 4 x 2 lines, so
    # each of the 64 lines is fetched once a pattern (the next frame's first rows evicted
    # by the last ones)
    assert len(cache.requests) == len(TRAFFIC) * (32 // 4) ** 2


# (scene, image, frame side, patterns): bumprtl render's 512² frame, every pixel 4 texels
# from the last (every pixel misses), and the plane at one texel per pixel over the whole
# map (16 chunks: every texel read, a miss every 4th pixel and each line refetched for each
# of its 4 texel rows); the palette's 8-bit indices (a 4 MiB _map.bin) on the sphere.
MEGATEXEL = [("default", "bricks", 512, tuple(TRAFFIC)),
             ("default", "globe", 512, tuple(TRAFFIC)),
             ("default", "bricks", 2048, ("no_stall", "both")),
             ("palette", "globe", 512, tuple(TRAFFIC))]


@pytest.mark.regress
@pytest.mark.parametrize("base,image,size,patterns", MEGATEXEL,
                         ids=[f"{b}-{i}-{n}-{len(p)}patterns" for b, i, n, p in MEGATEXEL])
def test_megatexel_frames_pipeline_axi_on_verilator(base, image, size, patterns, build_dir):
    """A 2048² map at the default widths (a 16 MiB _map.bin of angle pairs, or 4 MiB of
    palette indices), whole frames of the scene through the axi pipeline on Verilator's
    bulk path, under traffic patterns back to back: bit-exact and AR stream as the golden
    model's (the 16-bit stamps wrap every 65536 pixels)."""
    scene = load_scene_config({**BUILTIN[base], "image": image, "texture_size": 2048,
                               "map_memory": "axi"})
    r, cache = _bulk_frame(scene, size, "verilator", build_dir, patterns)
    log.info("%s %d²: %d pixels x %d patterns, %d AR requests, cycles %s, simulated in %s s "
             "(build %.0f s)", image, size, r.pixels[patterns[0]], len(patterns),
             len(cache.requests), r.cycles, {p: round(t, 1) for p, t in r.sim_s.items()},
             r.build_s)


@pytest.mark.parametrize("flags", [["--per-cycle"], ["--load", "port"]])
def test_render_rtl_refuses_the_per_cycle_path_and_load_with_axi(flags, tmp_path, capfd):
    """The per-cycle cocotb driver has no memory on the AXI port (the bulk wrapper has):
    one line, exit 2, before anything is built."""
    scene = tmp_path / "axi.toml"
    scene.write_text('name = "axi"\ntexture_size = 16\nmap_memory = "axi"\n')
    out = tmp_path / "r.png"
    assert main(["render", "--rtl", "--pipeline", str(scene), "--size", "16",
                 "--simulator", "icarus", "--out", str(out), *flags]) == 2
    err = capfd.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{flags[0]} applies to map_memory = 'bram'" in err[0], err
    assert not out.exists()
