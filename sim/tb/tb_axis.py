"""cocotb testbench for an emitted ``<unit>_axis.v`` (rtl/axis.py): cocotbext-axi's
AxiStreamSource and AxiStreamSink with random pauses on both sides, bit-exact against the
golden model of sim/golden/fixed/ (through the method registry; a scene pipeline against
``pipeline.pipeline_fixed`` with the memory images the sidecar names), tlast and tuser
checked. Units: rotation, illumination, and scene pipelines whose memories are initial
contents (no host writes: a varying bump map with per-pixel shading, e.g. the default scene).

The pixels go in as lines of ``LINE`` transfers (tlast on the last one); each line must come
back as one frame of the same length (tlast on the same pixel) with the same tusers (tags).
Environment: BUMPRTL_SIDECAR (the ``_axis.json``), BUMPRTL_SAMPLES.
"""

import itertools
import os
import random
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, RisingEdge
from cocotbext.axi import AxiStreamBus, AxiStreamFrame, AxiStreamSink, AxiStreamSource

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.fixed.pipeline import pipeline_fixed, random_inputs
from bumprtl.sim.golden.methods import get, illumination_fixed, rotation_fixed
from bumprtl.sim.golden.vectors import edge_codes, random_codes
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.tb.stream import load_sidecar, pack, samples, unpack

LINE = 7                     # pixels per line (tlast every LINE transfers)


def _scene_inputs(meta, n, seed):
    """A scene pipeline's random pixels and its golden outputs, the memories read from the
    ``$readmemh`` files beside the sidecar."""
    scene = load_scene_config(meta.scene)
    images = meta.memory_images or {}
    if scene.shading != "per-pixel" or scene.bump_map != "varying" or \
            any(img["load"] != "initial" for img in images.values()):
        raise ValueError(f"scene {scene.name!r}: this bench drives no host port (needs a varying "
                         f"bump map, per-pixel shading and initial memory contents)")
    folder = Path(os.environ["BUMPRTL_SIDECAR"]).parent

    def words(name):
        if name not in images:
            return None
        return np.array([int(x, 16) for x in (folder / images[name]["file"]).read_text().split()])

    inputs = random_inputs(scene, n, np.random.default_rng(seed))
    return inputs, pipeline_fixed(inputs, scene, words("map"), None, words("texture"))


def _inputs(unit, cfg, n, seed):
    """``(input arrays by field, golden output arrays by field)``."""
    edges, rand = edge_codes(cfg), random_codes(n, cfg, seed=seed)
    codes = {k: np.concatenate([edges[k], rand[k]]) for k in edges}
    codes = get(cfg.method).from_angle_codes(codes, cfg)
    codes = {k: v for k, v in codes.items() if cfg.specular or not k.startswith("h.")}
    if unit == "rotation_axis":
        return codes, rotation_fixed(codes, cfg)
    rot = rotation_fixed(codes, cfg)
    return rot, illumination_fixed(rot, cfg)


def _pauses(rng, p):
    return itertools.cycle([rng.random() < p for _ in range(997)])


@cocotb.test()
async def axis_matches_golden_with_pauses(dut):
    meta = load_sidecar()
    cfg = Config(**meta.config)
    axis = meta.axis
    s_fields, m_fields = axis["s_axis_tdata_fields"], axis["m_axis_tdata_fields"]
    rng = random.Random(5)
    if meta.scene is not None:
        inputs, golden = _scene_inputs(meta, samples(300), seed=3)
    else:
        inputs, golden = _inputs(meta.unit, cfg, samples(300), seed=3)
    n = len(next(iter(inputs.values())))
    n -= n % LINE
    mask = (1 << axis["tuser_width"]) - 1

    cocotb.start_soon(Clock(dut.aclk, 10, unit="ns").start())
    source = AxiStreamSource(AxiStreamBus.from_prefix(dut, "s_axis"), dut.aclk, dut.aresetn,
                             reset_active_level=False, byte_lanes=1)
    sink = AxiStreamSink(AxiStreamBus.from_prefix(dut, "m_axis"), dut.aclk, dut.aresetn,
                         reset_active_level=False, byte_lanes=1)
    source.set_pause_generator(_pauses(rng, 0.3))
    sink.set_pause_generator(_pauses(rng, 0.3))
    dut.aresetn.value = 0
    await ClockCycles(dut.aclk, 4)
    dut.aresetn.value = 1
    await RisingEdge(dut.aclk)

    words = [pack(s_fields, {k: int(v[i]) for k, v in inputs.items() if k in s_fields})
             for i in range(n)]
    tags = [(3 * i + 1) & mask for i in range(n)]          # not the pixel index: tuser rides
    for start in range(0, n, LINE):
        await source.send(AxiStreamFrame(words[start:start + LINE], tuser=tags[start:start + LINE]))

    for line, start in enumerate(range(0, n, LINE)):
        frame = await sink.recv()
        got = list(frame.tdata)
        users = frame.tuser if isinstance(frame.tuser, list) else [frame.tuser] * len(got)
        assert len(got) == LINE, f"line {line}: tlast after {len(got)} transfers, expected {LINE}"
        assert users == tags[start:start + LINE], f"line {line}: tuser {users}"
        for k, word in enumerate(got):
            px = start + k
            fields = unpack(m_fields, word)
            for name, value in fields.items():
                assert value == int(golden[name][px]), (
                    f"pixel {px} field {name}: RTL {value} != golden {int(golden[name][px])}")
            assert word >> sum(w for _o, w, _s in m_fields.values()) == 0, "tdata padding not zero"
    dut._log.info("%d pixels in %d lines: bit-exact, tlast and tuser preserved", n, n // LINE)
