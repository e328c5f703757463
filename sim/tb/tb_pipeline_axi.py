"""cocotb testbench for an emitted ``map_memory = "axi"`` pipeline (rtl/cache.AxiMapFetch in
front of the credit edge): cocotbext-axi's ``AxiRamRead`` holds the ``_map.bin`` the
emission wrote, its AR and R channels paused at random and its bursts delayed by 2, 20 and
60 cycles (one cocotb test each); pixels stream in with random gaps and out under random
backpressure. Every output field is compared bit for bit with the golden pipeline
(sim/golden/fixed/pipeline.py, the same model as the block-RAM map's) and the AR requests
with the golden cache model's (sim/golden/cache.run_scene_cache). A palette scene's
``_map.bin`` holds the indices: the host writes a random colour table through ``lut_w_*``
(held until ``lut_w_ready``) and swaps it in before the first pixel, and each pixel's
colour is the table model's lookup of its index (sim/golden/fixed/palette_lut.py).

Environment: BUMPRTL_SIDECAR (the pipeline's sidecar), BUMPRTL_SAMPLES, BUMPRTL_PATTERN,
BUMPRTL_STIMULUS (``raster``: the pixels' texel coordinates a raster scan of a plane at one
texel per pixel, :func:`raster`; default: random coordinates over the whole port range).
"""

import itertools
import os
import random
from pathlib import Path

import cocotb
import numpy as np
from cocotbext.axi import AxiReadBus

from bumprtl.rtl.cache import scene_geometry
from bumprtl.sim.golden.cache import image_words, run_scene_cache
from bumprtl.sim.golden.fixed.palette_lut import PaletteLUTModel
from bumprtl.sim.golden.fixed.pipeline import as_payload_list, pipeline_fixed, random_inputs
from bumprtl.sim.scenes import texel_coordinates
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.stream import load_sidecar, run_stream, samples
from bumprtl.sim.tb.tb_cache import LATENCIES, LatentAxiRamRead
from bumprtl.sim.tb.tb_pipeline import host_setup


def raster(size, n, height=None):
    """``{u, v, level}`` of ``n`` pixels of a plane at one texel per pixel (a ``size`` x
    ``size`` frame on a ``size`` x ``height`` map: u over the width, v over the height; None:
    square) in raster order from the frame's centre row on."""
    u, v, _ = texel_coordinates("plane", size, size, height)
    top = max(0, size // 2 - n // (2 * size))
    u, v = u[top:].ravel()[:n], v[top:].ravel()[:n]
    return {"u": u, "v": v, "level": np.zeros_like(u)}


def _palette_colors(scene, index, rng):
    """``(golden outputs, table)``: a random colour table of ``palette_size`` entries, written
    then swapped to the front, and each pixel's lookup of its ``index`` in it."""
    table = rng.integers(0, 1 << 32, scene.palette_size)
    lut = PaletteLUTModel(scene.config)
    for addr, word in enumerate(table.tolist()):
        lut.clock((addr, word))
    lut.clock(swap=True)
    looked = [lut.lookup(int(i)) for i in index]
    return {k: [d[k] for d in looked] for k in looked[0]}, table


def _pauses(rng, p):
    return itertools.cycle([rng.random() < p for _ in range(997)])


@cocotb.test()
@cocotb.parametrize(latency=LATENCIES)
async def pipeline_matches_golden_against_axi_ram(dut, latency):
    meta = load_sidecar()
    scene = load_scene_config(meta.scene)
    record = meta.memory_images["map"]
    image = (Path(os.environ["BUMPRTL_SIDECAR"]).parent / record["file"]).read_bytes()
    assert len(image) == record["bytes"], f"{record['file']}: {len(image)} bytes, sidecar {record['bytes']}"
    geom = scene_geometry(scene.hardware)
    words = image_words(scene, geom, image)
    rng = np.random.default_rng(latency)
    inputs = random_inputs(scene, samples(150), rng)
    if os.environ.get("BUMPRTL_STIMULUS") == "raster":
        inputs.update({k: c for k, c in raster(scene.texture_size, len(inputs["u"]),
                                                         scene.map_height).items()
                       if k in inputs})
    golden = pipeline_fixed(inputs, scene, words)
    cache = run_scene_cache(scene.hardware, geom, inputs, words)
    setup = None
    if scene.shading == "palette":
        golden, table = _palette_colors(scene, golden["index"], rng)
        dut.lut_w_en.value, dut.lut_swap.value = 0, 0
        setup = lambda: host_setup(dut, meta, {"lut": table})

    ram = LatentAxiRamRead(AxiReadBus.from_prefix(dut, "axi_"), dut.clk, dut.rst, latency,
                           size=1 << (record["base"] + record["bytes"] - 1).bit_length())
    ram.write(record["base"], image)
    pauses = random.Random(latency)
    ram.ar_channel.set_pause_generator(_pauses(pauses, 0.3))
    ram.r_channel.set_pause_generator(_pauses(pauses, 0.3))
    payloads = as_payload_list(inputs)

    def model(accepted):
        return [{name: px["tag"] if name == "tag" else int(golden[name][k])
                 for name in meta.output_fields} for k, px in enumerate(accepted)]

    await run_stream(dut, meta, payloads, model, os.environ.get("BUMPRTL_PATTERN", "both"),
                     seed=latency, timeout_factor=2 * (latency + 2 * geom.beats + 20),
                     setup=setup)
    assert ram.requests == cache.requests, (
        f"{len(ram.requests)} AR requests, golden {len(cache.requests)}")
    dut._log.info("%d pixels bit-exact, %d AR requests as the golden cache model (hit rate "
                  "%.3f, latency %d)", len(payloads), len(cache.requests), cache.hit_rate, latency)
