"""The PaletteLUT's cycle model and host traffic (sim/golden/fixed/palette_lut.py) as their
docstrings state them: a pixel reads the front bank as it was in its cycle, host writes go
to the back bank, a swap exchanges the banks at the end of its cycle (a write in the same
cycle lands in the bank being published), indices and write addresses at or past sN read
as transparent black with oor = 1 and are ignored; the traffic writes and swaps at the
rates asked, over the whole index port, RGBA words with r in the low bits."""

import random

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.rtl.palette import index_bits
from bumprtl.sim.golden.fixed.palette_lut import PaletteLUTModel, host_op, pack_rgba, unpack_rgba


def test_rgba_words_hold_r_in_the_low_bits_and_unpack_to_the_same():
    cfg = Config()
    rgba = np.array([[1, 2, 3, 4], [255, 0, 128, 7]])
    words = pack_rgba(rgba, cfg)
    assert words.tolist() == [1 | 2 << 8 | 3 << 16 | 4 << 24, 255 | 128 << 16 | 7 << 24]
    back = unpack_rgba(words, cfg)
    assert sorted(back) == ["a", "b", "g", "r"]
    assert np.array_equal(np.stack([back[c] for c in "rgba"], -1), rgba)


def test_writes_reach_the_front_only_after_a_swap():
    cfg = Config(palette_size=20)                          # 5 index bits: 20..31 out of range
    lut = PaletteLUTModel(cfg)
    word = int(pack_rgba([10, 20, 30, 40], cfg))
    entry = {"color.r": 10, "color.g": 20, "color.b": 30, "color.a": 40, "oor": 0}
    black = {"color.r": 0, "color.g": 0, "color.b": 0, "color.a": 0}
    lut.clock(write=(3, word))
    assert lut.lookup(3) == {**black, "oor": 0}            # written to the back bank
    lut.clock(swap=True)
    assert lut.lookup(3) == entry
    lut.clock(write=(3, 0), swap=True)                     # lands in the bank being published
    assert lut.lookup(3) == {**black, "oor": 0}
    lut.clock(swap=True)
    assert lut.lookup(3) == entry                          # the other bank kept its word
    lut.clock(write=(19, word), swap=True)                 # the last index: in range
    assert lut.lookup(19) == entry
    lut.clock(write=(20, word), swap=True)                 # the first past sN: ignored
    assert lut.lookup(20) == {**black, "oor": 1}
    assert lut.lookup(31) == {**black, "oor": 1} and lut.banks.shape == (2, 20)


def test_host_traffic_writes_and_swaps_at_the_rates_asked_over_the_whole_port():
    cfg = Config(palette_size=20)
    rng = random.Random(1)
    n = 20_000
    ops = [host_op(rng, cfg, write_p=0.3, swap_p=0.1) for _ in range(n)]
    writes = [w for w, _ in ops if w is not None]
    assert abs(len(writes) / n - 0.3) < 0.02 and abs(sum(s for _, s in ops) / n - 0.1) < 0.01
    addrs = [a for a, _ in writes]
    assert min(addrs) == 0 and max(addrs) == (1 << index_bits(cfg)) - 1
    assert any(a >= cfg.palette_size for a in addrs)
    words = np.array([w for _, w in writes])
    for c, v in unpack_rgba(words, cfg).items():
        assert v.min() == 0 and v.max() == 255, c
    assert words.max() < 1 << 32
    rng = random.Random(3)                                 # the defaults: 1/2 and 3/100
    many = [host_op(rng, cfg) for _ in range(n)]
    assert abs(sum(w is not None for w, _ in many) / n - 0.5) < 0.02
    assert abs(sum(s for _, s in many) / n - 0.03) < 0.006


def test_a_blended_lookup_is_eq_2_of_the_entry_and_the_base_colour():
    """blend=True: the entry blended with the base colour by Tarini eq. 2 (rtl/palette.py's
    blend_eq2); without it the entry itself."""
    from bumprtl.rtl.palette import blend_eq2
    cfg = Config()
    lut = PaletteLUTModel(cfg)
    lut.clock(write=(5, int(pack_rgba([200, 100, 50, 128], cfg))), swap=True)
    base = {"r": 40, "g": 250, "b": 0, "a": 255}
    entry = {"r": 200, "g": 100, "b": 50, "a": 128}
    want = blend_eq2(entry, base, cfg)
    got = lut.lookup(5, base, blend=True)
    assert {c: got[f"color.{c}"] for c in want} == {c: int(v) for c, v in want.items()}
    assert want != {c: entry[c] for c in want}
    plain = lut.lookup(5, base)
    assert {c: plain[f"color.{c}"] for c in "rgba"} == entry


def test_palette_colours_are_each_pixels_entry_and_with_a_texture_eq_2_of_the_texel():
    """palette_colors: pixel i shows table entry index[i] (r, g, b, a from the packed
    word); with a colour texture the entry is blended by eq. 2 with the pixel's texel as
    the base colour (opaque: alpha 255; its r in the low byte)."""
    from bumprtl.rtl.palette import blend_eq2
    from bumprtl.sim.golden.fixed.palette_lut import palette_colors
    from bumprtl.sim.scenes.config import load_scene_config
    rng = np.random.default_rng(5)
    rgba = rng.integers(0, 256, (256, 4))
    table = pack_rgba(rgba, Config())
    index = rng.integers(0, 256, 50)
    plain = load_scene_config("palette", {"texture_size": 16})
    got = palette_colors({"index": index}, table, plain)
    assert sorted(got) == ["color.a", "color.b", "color.g", "color.r"]
    for n, c in enumerate("rgba"):
        assert np.array_equal(got[f"color.{c}"], rgba[index, n]), c
    textured = load_scene_config("palette", {"texture_size": 16, "texture": True})
    texel = rng.integers(0, 1 << 24, 50)
    got = palette_colors({"index": index, "texel": texel}, table, textured)
    base = {"r": texel & 255, "g": (texel >> 8) & 255, "b": texel >> 16, "a": np.full(50, 255)}
    entry = {c: rgba[index, n] for n, c in enumerate("rgba")}
    want = blend_eq2(entry, base, textured.config)
    for c in "rgba":
        assert np.array_equal(got[f"color.{c}"], np.asarray(want[c])), c
    assert got["color.a"].tolist() == [255] * 50
