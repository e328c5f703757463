"""BumpPipeline in the Amaranth simulator, bit for bit against sim/golden/fixed_pipeline.py,
for every combination of the SceneConfig switches; lint of the emitted Verilog; throughput
and backpressure (tags in order, each once)."""

import itertools

import numpy as np
import pytest
from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.memory import Memory

from bumprtl.gen.emit import lint
from bumprtl.gen.units import emit_unit
from bumprtl.rtl.palette import index_bits
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.scene import SceneConfig, load_scene_config
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden.fixed_pipeline import (as_payload_list, pipeline_fixed, polygon_fixed,
                                               random_inputs, random_map)
from bumprtl.sim.golden.palette_lut import PaletteLUTModel

SWITCHES = {"lights": (1, 2), "specular": (True, False), "bump_map": ("varying", "flat"),
            "shading": ("per-pixel", "palette"), "addressing": ("wrap", "clamp"),
            "mip_levels": (1, 3)}


def combinations():
    """Every combination of the switches the generator honours (palette ignores lights and
    specular; a flat map ignores addressing and mip levels: those collapse)."""
    seen = {}
    for values in itertools.product(*SWITCHES.values()):
        keys = dict(zip(SWITCHES, values))
        scene = load_scene_config({"name": "t", "texture_size": 16, **keys})
        if scene.shading == "palette":
            keys.update(lights=1, specular=True, bump_map="varying")
        if scene.bump_map == "flat":
            keys.update(addressing="wrap", mip_levels=1)
        seen[tuple(sorted(keys.items()))] = keys
    return list(seen.values())


class _Host(wiring.Component):
    """The pipeline with its host ports driven: polygon registers held (flat map), or the
    palette table written then published before the first pixel is let in."""

    def __init__(self, dut, polygon=None, table=None):
        self.dut, self.polygon, self.table = dut, polygon, table
        super().__init__({"i": wiring.In(dut.signature.members["i"].signature),
                          "o": wiring.Out(dut.signature.members["o"].signature)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.dut = dut = self.dut
        ready = 1
        if self.polygon is not None:
            m.d.comb += [dut.poly_en.eq(1), dut.poly.n_phi.eq(self.polygon["n_phi"])]
            m.d.comb += [dut.poly.n[k].eq(self.polygon[f"n.{k}"]) for k in ("x4", "y2", "z4")]
            loaded = Signal()                    # the polygon registers load in cycle 0
            m.d.sync += loaded.eq(1)
            ready = loaded
        if self.table is not None:
            m.submodules.rom = rom = Memory(shape=32, depth=len(self.table), init=self.table)
            count = Signal(range(len(self.table) + 2))
            rp = rom.read_port(domain="comb")
            busy = count <= len(self.table)
            with m.If(busy):
                m.d.sync += count.eq(count + 1)
            m.d.comb += [rp.addr.eq(count), dut.lut_w_en.eq(count < len(self.table)),
                         dut.lut_w_addr.eq(count), dut.lut_w_data.eq(rp.data),
                         dut.lut_swap.eq(count == len(self.table))]
            ready = ~busy
        m.d.comb += [dut.i.payload.eq(self.i.payload), dut.i.valid.eq(self.i.valid & ready),
                     self.i.ready.eq(dut.i.ready & ready)]
        wiring.connect(m, dut.o, wiring.flipped(self.o))
        return m


def run(scene, n, pattern, seed=0):
    """Simulate BumpPipeline(scene) on ``n`` random pixels; check against the golden model.
    Returns (cycles, latency)."""
    rng = np.random.default_rng(seed)
    words = random_map(scene, rng) if scene.bump_map == "varying" else None
    inputs = random_inputs(scene, n, rng)
    polygon = table = None
    if scene.bump_map == "flat":
        polygon = polygon_fixed(*rng.integers(0, 1 << scene.angle_bits, 2),
                                rng.integers(0, 1 << scene.angle_bits),
                                rng.integers(0, 1 << (scene.angle_bits - 2)), scene)
    golden = pipeline_fixed(inputs, scene, words, polygon)
    if scene.shading == "palette":
        table = [int(x) for x in rng.integers(0, 1 << 32, 1 << index_bits(scene.config))]
        model = PaletteLUTModel(scene.config)
        model.banks[0, :scene.palette_size] = table[:scene.palette_size]
        looked = [model.lookup(i) for i in golden["index"]]
        golden = {k: [d[k] for d in looked] for k in looked[0]}
    dut = BumpPipeline(scene, init=words)
    payloads = as_payload_list(inputs)
    out, cycles = simulate_stream(_Host(dut, polygon, table), payloads, pattern, seed=seed)
    assert_bit_exact(out, golden, payloads)
    return cycles, dut.latency


@pytest.mark.parametrize("keys", combinations(), ids=lambda k: "-".join(str(v) for v in k.values()))
def test_every_switch_combination_lint_clean_and_bit_exact(keys, build_dir):
    scene = load_scene_config({"name": "t", "texture_size": 16, **keys})
    v, _ = emit_unit("pipeline", scene, build_dir)
    assert lint(v) == []
    run(scene, 60, "no_stall")


@pytest.mark.parametrize("pattern", ["backpressure", "input_gaps"])
@pytest.mark.parametrize("name", ["full-2", "flat", "palette"])
def test_stalls_lose_nothing(name, pattern):
    """Random backpressure / input gaps: bit-exact and the tags in order, each once
    (assert_bit_exact checks the tag sequence)."""
    keys = {"full-2": {"lights": 2, "mip_levels": 2}, "flat": {"bump_map": "flat"},
            "palette": {"shading": "palette"}}[name]
    cycles, _ = run(load_scene_config({"name": name, "texture_size": 16, **keys}), 300, pattern, seed=3)
    assert cycles > 300


@pytest.mark.parametrize("keys", [{}, {"lights": 3, "specular": False}, {"bump_map": "flat"}])
def test_one_pixel_per_clock(keys):
    """No stalls: n pixels take at most n + latency (+ 1 for the handshake) cycles, i.e. at
    most 1 + latency / n cycles per pixel."""
    scene = load_scene_config({"name": "t", "texture_size": 16, **keys})
    n = 400
    cycles, latency = run(scene, n, "no_stall", seed=5)
    assert cycles / n <= 1 + (latency + 1) / n


def test_texture_blend_not_built_is_an_error():
    with pytest.raises(Exception, match="texture"):
        BumpPipeline(load_scene_config({"name": "t", "texture": True}))
