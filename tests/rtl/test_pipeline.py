"""BumpPipeline in the Amaranth simulator, bit for bit against sim/golden/fixed/pipeline.py,
for every pair of SceneConfig switch values (every combination under make regress); lint of
the emitted Verilog; throughput and backpressure (tags in order, each once)."""

import itertools
import random
import re

import numpy as np
import pytest
from amaranth.hdl import Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.sim import Simulator

from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.units import emit_unit
from bumprtl.rtl.layouts import layout_fields, light_keys, light_layout
from bumprtl.rtl.methods import PER_PIXEL
from bumprtl.rtl.palette import index_bits
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden.fixed.palette_lut import PaletteLUTModel
from bumprtl.sim.golden.fixed.pipeline import (
    as_payload_list,
    pipeline_fixed,
    polygon_fixed,
    random_inputs,
    random_map,
    random_texture,
    unpack_rgb,
)
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.traffic import PATTERNS

SWITCHES = {"lights": (1, 2), "specular": (True, False), "bump_map": ("varying", "flat"),
            "shading": ("per-pixel", "palette"), "addressing": ("wrap", "clamp"),
            "mip_levels": (1, 3), "texture": (False, True)}


def combinations():
    """Every combination of the switches the generator honours (palette ignores lights and
    specular; a flat map without a texture ignores addressing and mip levels: those
    collapse; with a texture they address the colour texture)."""
    seen = {}
    for values in itertools.product(*SWITCHES.values()):
        keys = dict(zip(SWITCHES, values, strict=False))
        scene = load_scene_config({"name": "t", "texture_size": 16, **keys})
        if scene.shading == "palette":
            keys.update(lights=1, specular=True, bump_map="varying")
        if scene.bump_map == "flat" and not scene.texture:
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
    texels = random_texture(scene, rng)
    inputs = random_inputs(scene, n, rng)
    polygon = table = None
    if scene.bump_map == "flat":
        polygon = polygon_fixed(*rng.integers(0, 1 << scene.angle_bits, 2),
                                rng.integers(0, 1 << scene.angle_bits),
                                rng.integers(0, 1 << (scene.angle_bits - 2)), scene)
    golden = pipeline_fixed(inputs, scene, words, polygon, texels)
    if scene.shading == "palette":
        table = [int(x) for x in rng.integers(0, 1 << 32, 1 << index_bits(scene.config))]
        model = PaletteLUTModel(scene.config)
        model.banks[0, :scene.palette_size] = table[:scene.palette_size]
        if scene.texture:                 # Tarini eq. 2 with the texel as the base colour
            bases = [{**{c: int(v) for c, v in unpack_rgb(t).items()}, "a": 255}
                     for t in golden["texel"]]
            looked = [model.lookup(i, b, blend=True) for i, b in zip(golden["index"], bases, strict=False)]
        else:
            looked = [model.lookup(i) for i in golden["index"]]
        golden = {k: [d[k] for d in looked] for k in looked[0]}
    dut = BumpPipeline(scene.hardware, init=words, texture=texels)
    payloads = as_payload_list(inputs)
    out, cycles = simulate_stream(_Host(dut, polygon, table), payloads, pattern, seed=seed)
    assert_bit_exact(out, golden, payloads)
    return cycles, dut.port_latency


def pairwise(combos):
    """A subset of ``combos`` in which every pair of switch values that occurs together in
    some combination occurs together at least once (greedy covering array, deterministic)."""
    def pairs(k):
        items = sorted((f, str(v)) for f, v in k.items())
        return set(itertools.combinations(items, 2))
    uncovered = set().union(*(pairs(k) for k in combos))
    chosen = []
    while uncovered:
        best = max(combos, key=lambda k: len(pairs(k) & uncovered))
        chosen.append(best)
        uncovered -= pairs(best)
    return chosen


def test_pairwise_covers_every_pair_with_fewer_cases():
    full, cover = combinations(), pairwise(combinations())
    want = set().union(*({(a, b) for a in k.items() for b in k.items() if a[0] < b[0]} for k in full))
    got = set().union(*({(a, b) for a in k.items() for b in k.items() if a[0] < b[0]} for k in cover))
    assert got == want and len(cover) < len(full) // 3 and all(k in full for k in cover)


def _switch_case(keys, build_dir):
    """At 10-bit angles, B = 11: the switches' interplay does not depend on the widths, and the
    default widths' tables (12 of 2049 words) would be most of the emission and lint time."""
    scene = load_scene_config({"name": "t", "texture_size": 16, "angle_bits": 10, "frac_bits": 11,
                               **keys})
    v, _ = emit_unit("pipeline", scene, build_dir)
    assert lint(v) == []
    run(scene, 60, "no_stall")


def _ids(k):
    return "-".join(str(v) for v in k.values())


# make test: every pair of switch values (two-way interactions) once; make regress: all of them.
@pytest.mark.parametrize("keys", pairwise(combinations()), ids=_ids)
def test_every_switch_pair_lint_clean_and_bit_exact(keys, build_dir):
    _switch_case(keys, build_dir)


@pytest.mark.regress
@pytest.mark.parametrize("keys", combinations(), ids=_ids)
def test_every_switch_combination_lint_clean_and_bit_exact(keys, build_dir):
    _switch_case(keys, build_dir)


@pytest.mark.parametrize("keys", [{}, {"bump_map": "flat"}, {"specular": False}])
def test_extra_lights_are_an_array_after_light_0(keys):
    """Light 0's vectors are the one-light fields l, h; lights 1..m-1 an ArrayLayout of
    {l, [h]} (extra_lights); the lights' angles lie one after the other in the payload, the
    bits the golden model and the stimulus address through light_keys."""
    scene = load_scene_config({"name": "t", "texture_size": 16, "lights": 3, **keys})
    layout = BumpPipeline(scene.hardware).i.payload.shape()
    extra = layout["extra_lights"].shape
    assert isinstance(extra, data.ArrayLayout) and extra.length == 2
    assert extra.elem_shape == light_layout(scene.config)
    fields, keys = layout_fields(layout), light_keys(scene.config)
    assert [k["l.phi"] for k in keys] == ["l.phi", "extra_lights.0.l.phi", "extra_lights.1.l.phi"]
    offsets = [fields[name][0] for k in keys for name in k.values()]
    first = fields["l.phi"][0]
    assert offsets == [first + n * scene.angle_bits for n in range(len(offsets))]


@pytest.mark.parametrize("pattern", [p for p in PATTERNS if p != "no_stall"])
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


def _ports(dut, cycles, valid, ready):
    """Drive ``dut`` (no host writes) for ``cycles`` cycles: ``i.valid`` = ``valid(cycle)``
    (held until taken), ``o.ready`` = ``ready(cycle)``, consecutive tags. Every cycle, before
    choosing ``o.ready``, the pipeline's stream rule is checked: ``i.ready``, ``o.valid`` and
    ``o.payload`` are the same whether ``o.ready`` is 0 or 1 in that cycle, and ``i.ready``
    is high exactly while fewer than ``fifo_depth`` pixels are inside (a free credit).
    Returns (i.ready per cycle, tags out)."""
    top = 1 << len(dut.i.payload.tag)
    readies, tags = [], []

    async def testbench(ctx):
        sent, offered, inside = 0, False, 0
        for cycle in range(cycles):
            offered = offered or valid(cycle)
            ctx.set(dut.i.valid, offered)
            ctx.set(dut.i.payload.tag, sent % top)
            seen = []
            for r in (0, 1):
                ctx.set(dut.o.ready, r)
                seen.append((ctx.get(dut.i.ready), ctx.get(dut.o.valid),
                             ctx.get(dut.o.payload.as_value())))
            assert seen[0] == seen[1], f"cycle {cycle}: i.ready/o.valid/o.payload follow o.ready"
            i_ready, o_valid, _ = seen[0]
            assert i_ready == (inside < dut.fifo_depth), \
                f"cycle {cycle}: i.ready {i_ready} with {inside} of {dut.fifo_depth} inside"
            ctx.set(dut.o.ready, ready(cycle))
            if o_valid and ready(cycle):
                tags.append(ctx.get(dut.o.payload.tag))
                inside -= 1
            if offered and i_ready:
                offered, sent, inside = False, sent + 1, inside + 1
            readies.append(i_ready)
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(testbench)
    sim.run()
    return readies, tags


@pytest.mark.parametrize("keys", [{"lights": 2, "texture": True}, {"shading": "palette"},
                                  {"bump_map": "flat"}], ids=["lights2-texture", "palette", "flat"])
def test_ready_is_a_free_credit_and_never_waits_on_o_ready(keys):
    """The pipeline's handshake (free-running units, one credit edge): per cycle i.ready does
    not depend on o.ready and is high exactly while a credit is free; o.valid and o.payload do not
    depend on o.ready; under random gaps and backpressure every pixel comes out once, in
    order (the payloads are checked bit for bit by test_stalls_lose_nothing)."""
    scene = load_scene_config({"name": "t", "texture_size": 16, **keys})
    rng = random.Random(7)
    valid = [rng.random() < 0.7 for _ in range(400)]
    ready = [rng.random() < 0.5 for _ in range(400)]
    _, tags = _ports(BumpPipeline(scene.hardware), 400, valid.__getitem__, ready.__getitem__)
    top = 1 << scene.config.tag_bits
    assert len(tags) > 100 and tags == [n % top for n in range(len(tags))]


def test_one_consumer_stall_costs_one_input_cycle_at_the_least_depth():
    """At the least FIFO depth every credit is in the loop at full rate, so o.ready low for
    one cycle holds one credit back and i.ready falls for exactly one cycle; one entry more
    and the same stall does not reach the input. Held low, the pipe takes exactly
    fifo_depth pixels (its credits) and i.ready falls."""
    scene = load_scene_config({"name": "t", "texture_size": 16})
    dut = BumpPipeline(scene.hardware)
    n = dut.port_latency
    stall = 2 * n
    readies, tags = _ports(dut, 4 * n, lambda c: True, lambda c: c != stall)
    assert [c for c, r in enumerate(readies) if not r] == [stall + 1], readies
    deeper = BumpPipeline(scene.hardware, fifo_depth=dut.fifo_depth + 1)
    readies, tags = _ports(deeper, 4 * n, lambda c: True, lambda c: c != stall)
    assert all(readies) and len(tags) == 4 * n - n - 1
    dut = BumpPipeline(scene.hardware)
    readies, tags = _ports(dut, 3 * n, lambda c: True, lambda c: False)
    d = dut.fifo_depth
    assert tags == [] and sum(readies) == d and not any(readies[d:])


def _plan(keys):
    """Built and skipped lists of a pipeline that is never elaborated."""
    dut = BumpPipeline(load_scene_config({"name": "t", "texture_size": 16, **keys}).hardware)
    for unit in (dut, *dut.units.values()):
        unit._MustUse__silence = True
    return [b["unit"] for b in dut.built], [k["unit"] for k in dut.skipped], dut


def test_texture_builds_the_blend_only_when_asked():
    built, skipped, dut = _plan({})
    assert "blend" not in built and "colour-texture blend" in skipped
    assert not any(p.startswith("tex_") for p in dut.signature.members)
    built, skipped, dut = _plan({"texture": True, "lights": 2})
    assert built[-1] == "blend" and "lightsum" not in built and "colour-texture blend" not in skipped
    assert {"texel_r", "texel_i", "tex_w_en"} <= set(built) | set(dut.signature.members)
    assert set(dut.o.payload.shape().members["color"].members) == {"r", "g", "b"}
    built, _, dut = _plan({"texture": True, "bump_map": "flat"})     # the texture RAM only
    assert built[0] == "fetch" and "map_w_en" not in dut.signature.members
    assert dut.units["fetch"].memory_bits == 16 * 16 * 24


def test_textured_scene_the_texture_reaches_the_output():
    """A white texture and a black one give different colours through the RTL (the blend
    is not a pass-through of the grey shade), each equal to the golden model."""
    from bumprtl.rtl.bumpfetch import memory_depth
    scene = load_scene_config({"name": "t", "texture_size": 16, "texture": True})
    rng = np.random.default_rng(4)
    words, inputs = random_map(scene, rng), random_inputs(scene, 40, rng)
    payloads = as_payload_list(inputs)
    colors = {}
    for name, value in (("white", 0xFFFFFF), ("black", 0)):
        texels = np.full(memory_depth(scene), value)
        out, _ = simulate_stream(BumpPipeline(scene.hardware, init=words, texture=texels), payloads)
        golden = pipeline_fixed(inputs, scene, words, None, texels)
        assert_bit_exact(out, golden, payloads)
        colors[name] = np.array([o["color.g"] for o in out])
    assert (colors["black"] <= golden["specular"]).all() and colors["white"].mean() > 80


@pytest.mark.parametrize("method", PER_PIXEL)
def test_no_specular_builds_no_h_path_and_no_table(method, build_dir):
    """specular = false checked on the elaborated design (not on the built/skipped lists,
    which are computed from the SceneConfig): the emitted pipeline's memories and Verilog have
    no specular table and no H path (no signal of the rotation or illumination named h_...),
    and the ROMs are those of the L path alone. Counts from the datapaths' structure, per
    vector V built: exact rotation, n'' takes 6 sines and 8 cosines and each vector 2 sines
    and 3 cosines, two reads per dual-port ROM: ceil((14 + 5 V) / 2) ROMs (10 with L, 12 with
    L and H), no ROM in its illumination but the specular table; lee (Fig. 7 and 8): 6 ROMs
    per vector in the rotation, 3 cosine ROMs per vector in the illumination."""
    for specular in (False, True):
        scene = load_scene_config({"name": "t", "texture_size": 16, "specular": specular,
                                   "method": method, "angle_bits": 8, "frac_bits": 9})
        v, sidecar = emit_unit("pipeline", scene, build_dir / f"specular_{specular}")
        text, roms = v.read_text(), load_sidecar(sidecar).memories
        assert any(name.endswith("specular_table") for name in roms) == specular, roms
        assert ("specular_table" in text) == specular
        assert bool(re.search(r"\\(rotation|illumination)\.h_", text)) == specular
        vectors = 2 if specular else 1
        rotation = [r for r in roms if r.startswith("rotation.")]
        illumination = [r for r in roms if r.startswith("illumination.")
                        and not r.endswith("specular_table")]
        if method == "exact":
            assert len(rotation) == -(-(14 + 5 * vectors) // 2) and illumination == []
        else:
            assert len(rotation) == 6 * vectors and len(illumination) == 3 * vectors
