"""A ``map_memory = "axi"`` scene pipeline emitted with its ``_map.bin``, under cocotb on
Icarus and Verilator against cocotbext-axi's AxiRamRead holding that image
(sim/tb/tb_pipeline_axi.py): outputs bit-exact with the golden pipeline (per-pixel
shading) or the colour-table model (palette: the indices in the ``.bin``), AR requests
with the golden cache model, memory latencies 2, 20 and 60, random stalls everywhere."""

import pytest

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.memories import emit_scene_unit, memory_images
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes.config import BUILTIN, load_scene_config
from bumprtl.sim.tb.runner import SIMULATORS, run_cocotb

# The default scene at small widths, a 32 x 32 map of two levels, its map in AXI memory;
# the palette scene's 8-bit index map the same way, its colour table behind the cache.
SCENES = {
    "default": load_scene_config({**BUILTIN["default"], "angle_bits": 8, "frac_bits": 8,
                                  "tag_bits": 6, "texture_size": 32, "mip_levels": 2,
                                  "map_memory": "axi"}),
    "palette": load_scene_config({**BUILTIN["palette"], "tag_bits": 6, "texture_size": 32,
                                  "mip_levels": 2, "map_memory": "axi"})}


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("sim", SIMULATORS)
def test_pipeline_axi_cocotb_against_axi_ram(sim, scene, build_dir):
    scene = SCENES[scene]
    images = memory_images("pipeline", scene, *scene_memories(scene))
    v, j, files = emit_scene_unit("pipeline", scene, build_dir / "rtl", images)
    assert [f.name for f in files if f.suffix == ".bin"] == ["pipeline_map.bin"]
    meta = load_sidecar(j)
    record = meta.memory_images["map"]
    assert record["bytes"] == files[0].stat().st_size
    slot = 1 if scene.shading == "palette" else 4       # an 8-bit index, a 16-bit angle pair
    assert record["bytes"] == slot * sum((32 >> n) ** 2 for n in range(2))
    assert lint(v) == []
    run = run_cocotb(sim, v, "bumprtl.sim.tb.tb_pipeline_axi", build_dir / sim,
                     {"BUMPRTL_SIDECAR": j, "BUMPRTL_SAMPLES": 150})
    assert (run.tests, run.failures) == (3, 0)


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
