"""BumpMapFetch: addressing (wrap, clamp, mip levels, coordinates outside the map) against
an independent per-texel reference, bit-exact streaming under stalls, the host write port."""

import numpy as np
import pytest

from bumprtl.rtl.bumpfetch import BumpMapFetch, level_bases, level_bits, memory_depth
from bumprtl.sim.amaranth_stream import assert_bit_exact, simulate_stream
from bumprtl.sim.golden.fixed.pipeline import fetch_fixed, random_inputs, random_map, random_texture
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.traffic import PATTERNS


def reference_word(words, u, v, level, scene):
    """Plain Python: the texel (u >> l, v >> l) of level l, wrapped modulo or clamped."""
    level = min(level, scene.mip_levels - 1)
    size = scene.texture_size >> level
    base = sum((scene.texture_size >> n) ** 2 for n in range(level))
    fix = (lambda c: c % size) if scene.addressing == "wrap" else (lambda c: min(max(c, 0), size - 1))
    return int(words[base + fix(v // 2 ** level) * size + fix(u // 2 ** level)])


@pytest.mark.parametrize("addressing", ["wrap", "clamp"])
@pytest.mark.parametrize("mip_levels", [1, 3, 5])
def test_golden_address_matches_reference(addressing, mip_levels):
    scene = load_scene_config({"texture_size": 16, "addressing": addressing, "mip_levels": mip_levels})
    rng = np.random.default_rng(mip_levels)
    words = rng.integers(0, 1 << 24, memory_depth(scene))
    u, v = np.meshgrid(np.arange(-32, 32), np.arange(-32, 32))    # the whole signed port range
    for level in range(8):
        got = fetch_fixed(u.ravel(), v.ravel(), np.full(u.size, level), words, scene)
        want = [reference_word(words, a, b, level, scene) for a, b in zip(u.ravel(), v.ravel(), strict=False)]
        assert got.tolist() == want


def reference_word_wh(words, u, v, level, scene, width, height):
    """Plain Python for a ``width`` x ``height`` map (given here, not read from the scene):
    level l is (width >> l) x (height >> l) texels, row-major, after the earlier levels; u
    wraps modulo or clamps to the level's width, v to its height."""
    level = min(level, scene.mip_levels - 1)
    w, h = width >> level, height >> level
    base = sum((width >> n) * (height >> n) for n in range(level))
    if scene.addressing == "wrap":
        col, row = (u >> level) % w, (v >> level) % h
    else:
        col, row = min(max(u >> level, 0), w - 1), min(max(v >> level, 0), h - 1)
    return int(words[base + row * w + col])


@pytest.mark.parametrize("addressing", ["wrap", "clamp"])
@pytest.mark.parametrize("height, mip_levels", [(16, 5), (32, 3)])
def test_nonsquare_golden_address_matches_reference(addressing, height, mip_levels):
    """A 64 x 16 or 64 x 32 map (texture_height): every coordinate of the signed port range,
    every level code, against the reference written above."""
    scene = load_scene_config({"texture_size": 64, "texture_height": height,
                               "addressing": addressing, "mip_levels": mip_levels})
    assert memory_depth(scene) == sum((64 >> n) * (height >> n) for n in range(mip_levels))
    rng = np.random.default_rng(height)
    words = rng.integers(0, 1 << 24, memory_depth(scene))
    u, v = np.meshgrid(np.arange(-128, 128, 3), np.arange(-128, 128, 3))
    for level in range(8):
        got = fetch_fixed(u.ravel(), v.ravel(), np.full(u.size, level), words, scene)
        want = [reference_word_wh(words, a, b, level, scene, 64, height)
                for a, b in zip(u.ravel().tolist(), v.ravel().tolist(), strict=True)]
        assert got.tolist() == want


@pytest.mark.parametrize("keys", [{"addressing": "wrap", "mip_levels": 3},
                                  {"addressing": "clamp", "mip_levels": 2, "texture": True}])
def test_nonsquare_fetch_streams_bit_exact(keys):
    """The block-RAM fetch of a 32 x 16 map (texture_height 16), with a colour texture of
    the same size: each word bit-exact with the golden fetch, under stalls."""
    scene = load_scene_config({"texture_size": 32, "texture_height": 16, **keys})
    rng = np.random.default_rng(9)
    words = random_map(scene, rng)
    texels = random_texture(scene, rng)
    inputs = random_inputs(scene, 300, rng)
    payloads = [{k: int(inputs[k][n]) for k in ("u", "v", "level", "tag") if k in inputs}
                for n in range(300)]
    dut = BumpMapFetch(scene.hardware, init=words, texture=texels)
    out, _ = simulate_stream(dut, payloads, "both", pipe_handshake=True)
    want = {"word": fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), words, scene)}
    got = [{"word": o["b.phi"] | (o["b.theta"] << scene.angle_bits), "tag": o["tag"]} for o in out]
    if scene.texture:
        want["texel"] = fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), texels, scene)
        for g, o in zip(got, out, strict=True):
            g["texel"] = o["texel.r"] | (o["texel.g"] << 8) | (o["texel.b"] << 16)
    assert_bit_exact(got, want, payloads)


def test_levels_follow_each_other():
    scene = load_scene_config({"texture_size": 64, "mip_levels": 4})
    assert level_bases(scene) == [0, 4096, 4096 + 1024, 4096 + 1024 + 256]
    assert memory_depth(scene) == 4096 + 1024 + 256 + 64


@pytest.mark.parametrize("pattern", list(PATTERNS))
@pytest.mark.parametrize("keys", [{"addressing": "wrap", "mip_levels": 3},
                                  {"addressing": "clamp", "mip_levels": 1},
                                  {"shading": "palette", "addressing": "clamp", "mip_levels": 2}])
def test_fetch_streams_bit_exact(keys, pattern):
    scene = load_scene_config({"texture_size": 16, **keys})
    rng = np.random.default_rng(7)
    words = random_map(scene, rng)
    inputs = random_inputs(scene, 500, rng)
    field = "index" if scene.shading == "palette" else "b"
    payloads = [{k: int(inputs[k][n]) for k in ("u", "v", "level", "tag") if k in inputs}
                for n in range(500)]
    dut = BumpMapFetch(scene.hardware, init=words)
    out, cycles = simulate_stream(dut, payloads, pattern, pipe_handshake=True)
    want = fetch_fixed(inputs["u"], inputs["v"], inputs.get("level"), words, scene)
    flat = {"b": lambda o: o["b.phi"] | (o["b.theta"] << scene.angle_bits), "index": lambda o: o["index"]}
    assert_bit_exact([{"word": flat[field](o), "tag": o["tag"]} for o in out], {"word": want}, payloads)
    if pattern == "no_stall":
        assert cycles <= 500 + dut.port_latency + 1


def test_host_write_port_replaces_texels():
    """Words written through the host port are what later lookups return."""
    from amaranth.sim import Simulator
    scene = load_scene_config({"texture_size": 16})
    dut = BumpMapFetch(scene.hardware)
    writes = {3: 0xABCDE, 17: 0x12345, 255: 0xFFFFFF}
    got = {}

    async def tb(ctx):
        for addr, word in writes.items():
            ctx.set(dut.w_en, 1), ctx.set(dut.w_addr, addr), ctx.set(dut.w_data, word)
            await ctx.tick()
        ctx.set(dut.w_en, 0)
        ctx.set(dut.o.ready, 1)
        for addr in [*writes] + [None] * dut.port_latency:
            ctx.set(dut.i.valid, addr is not None)
            if addr is not None:
                ctx.set(dut.i.payload.u, addr % 16), ctx.set(dut.i.payload.v, addr // 16)
                ctx.set(dut.i.payload.tag, addr)
            if ctx.get(dut.o.valid):
                got[ctx.get(dut.o.payload.tag)] = ctx.get(dut.o.payload.b.as_value())
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(tb)
    sim.run()
    assert got == writes


def test_init_of_the_wrong_size_is_rejected():
    with pytest.raises(ValueError, match="words"):
        BumpMapFetch(load_scene_config({"texture_size": 16}).hardware, init=[0] * 10)


@pytest.mark.parametrize("keys", [{"texture": True, "mip_levels": 2, "addressing": "clamp"},
                                  {"texture": True, "bump_map": "flat"}])
def test_texture_ram_read_at_the_same_address(keys):
    """The colour texture is read beside the map at the same (u, v, level); a flat map
    keeps only the texture RAM (no map port). Against the independent reference."""
    from bumprtl.sim.golden.fixed.pipeline import random_texture
    scene = load_scene_config({"texture_size": 16, **keys})
    rng = np.random.default_rng(11)
    words = random_map(scene, rng) if scene.bump_map == "varying" else None
    texels = random_texture(scene, rng)
    inputs = random_inputs(scene, 300, rng)
    payloads = [{k: int(inputs[k][n]) for k in ("u", "v", "level", "tag") if k in inputs}
                for n in range(300)]
    dut = BumpMapFetch(scene.hardware, init=words, texture=texels)
    assert ("w_en" in dut.signature.members) == (words is not None)
    out, _ = simulate_stream(dut, payloads, "backpressure", pipe_handshake=True)
    got = [o["texel.r"] | (o["texel.g"] << 8) | (o["texel.b"] << 16) for o in out]
    want = [reference_word(texels, p["u"], p["v"], p.get("level", 0), scene) for p in payloads]
    assert got == want and [o["tag"] for o in out] == [p["tag"] for p in payloads]
    if words is not None:
        flat = [o["b.phi"] | (o["b.theta"] << scene.angle_bits) for o in out]
        assert flat == [reference_word(words, p["u"], p["v"], p.get("level", 0), scene) for p in payloads]


def test_texture_words_need_a_textured_scene():
    with pytest.raises(ValueError, match="texture = false"):
        BumpMapFetch(load_scene_config({"texture_size": 16}).hardware, texture=[0] * 256)


@pytest.mark.parametrize("name, outputs", [("default", ["b"]), ("palette", ["index"]),
                                           ("textured", ["b", "texel"])])
def test_fetch_sidecar_lists_every_output(name, outputs):
    from bumprtl.gen.flow.units import build_unit
    from bumprtl.sim.scenes.config import load_scene_config
    dut, sidecar, _ = build_unit("fetch", load_scene_config(name))
    dut._MustUse__silence = True                   # only its ports are read
    assert sidecar.fetch["outputs"] == outputs
    assert set(outputs) <= set(dut.o.payload.shape().members)


# Every mip level of a full mip chain, at several map sizes: the RTL's address of each level
# against the plain-Python reference (not texel_address, which RTL and golden model share).
# A per-level pixel set: the four corners, the centre, and random texels (in and outside).
@pytest.mark.parametrize("size", [16, 32, 64, 128])
def test_fetch_every_mip_level_of_a_full_chain(size):
    scene = load_scene_config({"texture_size": size, "mip_levels": size.bit_length(),
                               "addressing": "wrap" if size % 64 else "clamp", "tag_bits": 12})
    rng = np.random.default_rng(size)
    words = rng.integers(0, 1 << scene.angle_bits * 2, memory_depth(scene))
    payloads = []
    for level in range(1 << level_bits(scene)):             # every level, and past the last
        step = 1 << min(level, scene.mip_levels - 1)
        coords = [(0, 0), (size - 1, 0), (0, size - 1), (size - 1, size - 1), (size // 2, size // 2)]
        coords += [(int(a), int(b)) for a, b in rng.integers(-2 * size, 2 * size, (12, 2))]
        coords += [(int(a) * step, int(b) * step) for a, b in rng.integers(0, size // step, (12, 2))]
        payloads += [{"u": u, "v": v, "level": level, "tag": len(payloads) + k}
                     for k, (u, v) in enumerate(coords)]
    out, _ = simulate_stream(BumpMapFetch(scene.hardware, init=words), payloads, "no_stall", pipe_handshake=True)
    got = [o["b.phi"] | (o["b.theta"] << scene.angle_bits) for o in out]
    want = [reference_word(words, p["u"], p["v"], p["level"], scene) for p in payloads]
    assert [o["tag"] for o in out] == [p["tag"] for p in payloads]
    bad = [(p, g, w) for p, g, w in zip(payloads, got, want, strict=False) if g != w]
    assert not bad, f"{len(bad)} wrong texels, the first (pixel, rtl, reference): {bad[0]}"


@pytest.mark.parametrize("size, levels", [(16, 5), (32, 3)])
def test_host_writes_reach_every_mip_level(size, levels):
    """Host writes into every level of a mip-level map (addresses past level 0's T x T
    words need the full port width), read back at that level."""
    from amaranth.sim import Simulator
    scene = load_scene_config({"texture_size": size, "mip_levels": levels})
    dut = BumpMapFetch(scene.hardware)
    assert len(dut.w_addr) == (memory_depth(scene) - 1).bit_length()
    assert memory_depth(scene) - 1 in [b + ((size >> l) ** 2 - 1) for l, b in enumerate(level_bases(scene))]
    rng = np.random.default_rng(levels)
    writes = {}                                   # address -> (u, v, level, word)
    for level, base in enumerate(level_bases(scene)):
        side = size >> level
        for u, v in [(0, 0), (side - 1, side - 1), *rng.integers(0, side, (3, 2)).tolist()]:
            writes[base + v * side + u] = (u << level, v << level, level,
                                           int(rng.integers(1, 1 << 2 * scene.angle_bits)))
    got = {}

    async def tb(ctx):
        for addr, (_u, _v, _l, word) in writes.items():
            ctx.set(dut.w_en, 1), ctx.set(dut.w_addr, addr), ctx.set(dut.w_data, word)
            await ctx.tick()
        ctx.set(dut.w_en, 0)
        ctx.set(dut.o.ready, 1)
        for k in [*range(len(writes)), *[None] * dut.port_latency]:
            ctx.set(dut.i.valid, k is not None)
            if k is not None:
                u, v, level, _ = list(writes.values())[k]
                ctx.set(dut.i.payload.u, u), ctx.set(dut.i.payload.v, v)
                ctx.set(dut.i.payload.level, level), ctx.set(dut.i.payload.tag, k)
            if ctx.get(dut.o.valid):
                got[ctx.get(dut.o.payload.tag)] = ctx.get(dut.o.payload.b.as_value())
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(tb)
    sim.run()
    tag_mask = (1 << scene.tag_bits) - 1
    assert got == {k & tag_mask: w[3] for k, w in enumerate(writes.values())}


@pytest.mark.parametrize("keys", [{"mip_levels": 5}, {"mip_levels": 3, "texture": True},
                                  {"mip_levels": 2, "shading": "palette"}])
def test_pipeline_host_ports_address_every_mip_level(keys):
    """The pipeline's map (and texture) write addresses reach the last word of the last mip
    level: ceil(log2(depth)) bits, one more than a single level's T x T words need."""
    from bumprtl.rtl.pipeline import BumpPipeline
    scene = load_scene_config({"texture_size": 16, **keys})
    dut = BumpPipeline(scene.hardware)
    dut._MustUse__silence = True                   # only its ports are read
    depth = memory_depth(scene)
    assert depth > 16 * 16 and (depth - 1).bit_length() == 9
    for port in ("map_w_addr", "tex_w_addr"):
        if port in dut.signature.members:
            assert len(getattr(dut, port)) == 9, port


@pytest.mark.parametrize("keys", [{"mip_levels": 3, "texture": True},
                                  {"shading": "palette", "mip_levels": 2}])
def test_without_write_port_the_built_in_words_are_read_and_no_host_port_exists(keys):
    """``write_port=False`` (``bumprtl emit --load initial``): neither the fetch nor the
    pipeline has a map or texture host port, and the fetch still reads its built-in words
    bit for bit (against the independent reference)."""
    from bumprtl.rtl.pipeline import BumpPipeline
    from bumprtl.sim.golden.fixed.pipeline import random_texture
    scene = load_scene_config({"texture_size": 16, **keys})
    rng = np.random.default_rng(5)
    words = random_map(scene, rng)
    texels = random_texture(scene, rng) if scene.texture else None
    dut = BumpMapFetch(scene.hardware, init=words, texture=texels, write_port=False)
    host = {"w_en", "w_addr", "w_data", "tex_w_en", "tex_w_addr", "tex_w_data"}
    assert not host & set(dut.signature.members)
    pipe = BumpPipeline(scene.hardware, init=words, texture=texels, write_port=False)
    pipe._MustUse__silence = True                  # only its ports are read
    assert not {f"map_{p}" for p in host if not p.startswith("tex")} & set(pipe.signature.members)
    assert not {p for p in host if p.startswith("tex")} & set(pipe.signature.members)
    assert "map_w_en" in BumpPipeline(scene.hardware, init=words, texture=texels).signature.members
    inputs = random_inputs(scene, 200, rng)
    payloads = [{k: int(inputs[k][n]) for k in ("u", "v", "level", "tag") if k in inputs}
                for n in range(200)]
    out, _ = simulate_stream(dut, payloads, "backpressure", pipe_handshake=True)
    field = "index" if scene.shading == "palette" else "b"
    flat = {"b": lambda o: o["b.phi"] | (o["b.theta"] << scene.angle_bits),
            "index": lambda o: o["index"]}[field]
    assert [flat(o) for o in out] == [reference_word(words, p["u"], p["v"], p.get("level", 0), scene)
                                      for p in payloads]
