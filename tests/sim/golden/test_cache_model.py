"""The tiled layout (rtl/cache.tiled_layout) and the golden cache model (sim/golden/cache.py):
the layout is a bijection onto the image that :func:`tiled_image` writes, read back through
an independent per-texel formula; the model's hit rate on scans and its evictions follow
the stated pseudo-LRU."""

import numpy as np
import pytest

from bumprtl.rtl.cache import (
    CacheGeometry,
    plru_touch,
    plru_victim,
    texel_byte_address,
    tiled_image,
)
from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.cache import (
    CacheModel,
    blocking_cycles,
    cache_stimulus,
    random_levels,
    run_cache,
    stream_cycles,
)


def reference_address(u, v, level, g):
    """Plain Python: the byte of texel (u, v) of ``level``: whole lines of the earlier levels
    (at least one each), then block row, block column, row and column inside the block."""
    before = sum(max(1, (g.texture_size >> n) // g.block) ** 2 for n in range(level))
    per_row = max(1, (g.texture_size >> level) // g.block)
    line = before + (v // g.block) * per_row + u // g.block
    slot = (v % g.block) * g.block + u % g.block
    return g.base + line * g.line_bytes + slot * g.slot_bytes


@pytest.mark.parametrize("texel_bits,block,levels", [(28, 4, 5), (8, 4, 6), (16, 8, 3), (28, 2, 1)])
def test_layout_round_trip(texel_bits, block, levels):
    g = CacheGeometry(texture_size=32, mip_levels=levels, texel_bits=texel_bits, block=block,
                      base=4096)
    words = random_levels(g, texel_bits)
    image = tiled_image(g, words)
    assert len(image) == g.image_bytes
    seen = set()
    for lv in range(levels):
        side = g.level_size(lv)[0]
        v, u = np.mgrid[0:side, 0:side]
        addr = texel_byte_address(u, v, lv, g)
        for uu, vv, a in zip(u.ravel(), v.ravel(), addr.ravel(), strict=True):
            assert a == reference_address(int(uu), int(vv), lv, g)
            off = int(a) - g.base
            got = int.from_bytes(image[off:off + g.slot_bytes], "little")
            assert got == words[lv][vv, uu], (lv, uu, vv)
            seen.add(off)
    assert len(seen) == sum(g.level_size(lv)[0] ** 2 for lv in range(levels))   # a bijection


def _nonsquare_image(width, height, levels, block, slot, texel_bits, seed):
    """Written here, without rtl/cache: the tiled image of a ``width`` x ``height`` map.
    Level l is (width >> l) x (height >> l) texels; it is cut into block x block tiles,
    ceil((width >> l) / block) a row and ceil((height >> l) / block) a column (a level
    smaller than a block takes one whole tile); the tiles follow each other row by row,
    level after level, each one a line of block * block slots of ``slot`` bytes, the
    texels row-major inside their tile, little-endian. Returns (image bytes, the levels'
    [v][u] words, line count)."""
    rng = np.random.default_rng(seed)
    tiles, words = [], []
    for lv in range(levels):
        w, h = width >> lv, height >> lv
        level = rng.integers(0, 1 << texel_bits, (h, w))
        words.append(level)
        across, down = -(-w // block), -(-h // block)
        for ty in range(down):
            for tx in range(across):
                tile = bytearray(block * block * slot)
                for r in range(block):
                    for c in range(block):
                        u, v = tx * block + c, ty * block + r
                        if u < w and v < h:
                            at = (r * block + c) * slot
                            tile[at:at + slot] = int(level[v, u]).to_bytes(slot, "little")
                tiles.append(bytes(tile))
    return b"".join(tiles), words, len(tiles)


@pytest.mark.parametrize("width,height,levels,block,texel_bits", [
    (64, 32, 2, 4, 28), (32, 16, 5, 4, 8), (64, 16, 3, 8, 16), (16, 16, 3, 4, 28)])
def test_nonsquare_tiled_image_is_the_independent_one(width, height, levels, block, texel_bits):
    """A W x H map (texture_height < texture_size) in the tiled layout: tiled_image's bytes,
    the line count and image size equal the image built here tile by tile; every texel's
    byte address (texel_byte_address, what the RTL and the golden cache read) holds its
    word."""
    g = CacheGeometry(width, levels, texel_bits, block=block,
                      texture_height=None if height == width else height)
    want, words, lines = _nonsquare_image(width, height, levels, block, g.slot_bytes,
                                          texel_bits, width + levels)
    assert g.map_height == height and g.lines == lines and g.image_bytes == len(want)
    assert [g.blocks_per_row(lv) * g.blocks_per_column(lv) for lv in range(levels)] == \
        [max(1, (width >> lv) // block) * max(1, (height >> lv) // block) for lv in range(levels)]
    assert [w.shape for w in random_levels(g)] == [(height >> lv, width >> lv) for lv in range(levels)]
    assert tiled_image(g, words) == want
    for lv in range(levels):
        v, u = np.mgrid[0:height >> lv, 0:width >> lv]
        at = texel_byte_address(u.ravel(), v.ravel(), lv, g)
        got = [int.from_bytes(want[a:a + g.slot_bytes], "little") for a in at.tolist()]
        assert got == words[lv].ravel().tolist()


def test_nonsquare_levels_of_the_wrong_shape_are_refused():
    """tiled_image takes level l as an (H >> l, W >> l) array: the transposed one is refused."""
    g = CacheGeometry(32, 1, 8, texture_height=16)
    with pytest.raises(BumpError, match=r"level 0 must be 32 x 16 texels"):
        tiled_image(g, [np.zeros((32, 16), np.int64)])


def test_geometry_refusals():
    with pytest.raises(BumpError, match="ways must be a power of two"):
        CacheGeometry(64, 1, 28, ways=3)
    with pytest.raises(BumpError, match="data_bits must be one of 32, 64"):
        CacheGeometry(64, 1, 28, data_bits=128)
    with pytest.raises(BumpError, match="addr_bits"):
        CacheGeometry(4096, 1, 28, addr_bits=20)
    with pytest.raises(BumpError, match="block must make a line"):
        CacheGeometry(64, 1, 8, block=2, data_bits=64)        # 4 bytes < one 8-byte beat
    with pytest.raises(BumpError, match=r"texture_height must be a power of two in \[1, 64\]"):
        CacheGeometry(64, 1, 28, texture_height=128)           # taller than wide
    with pytest.raises(BumpError, match=r"mip_levels must be an integer in \[1, 5\]"):
        CacheGeometry(64, 6, 28, texture_height=16)            # levels stop at H's last


def test_plru_is_lru_for_two_ways_and_tree_for_four():
    bits = plru_touch(0, 0, 2)
    assert plru_victim(bits, 2) == 1
    assert plru_victim(plru_touch(bits, 1, 2), 2) == 0
    bits = 0
    for way in (0, 1, 2, 3):
        bits = plru_touch(bits, way, 4)
    assert plru_victim(bits, 4) == 0          # least recently used of the four
    bits = plru_touch(bits, 0, 4)
    assert plru_victim(bits, 4) == 2          # the tree: the other half's older leaf


def test_evictions_follow_lru():
    """Three lines of one set in a 2-way cache, A B A C: C evicts B (the least recent)."""
    g = CacheGeometry(64, 1, 28, sets=4, ways=2)
    model = CacheModel(g)
    a, b, c = 1, 1 + 4, 1 + 8
    assert model.access(a)[0] is False and model.access(b)[0] is False
    assert model.access(a) == (True, 0, None)
    hit, way, evicted = model.access(c)
    assert (hit, way, evicted) == (False, 1, b)
    assert model.access(a)[0] is True and model.access(b)[0] is False


def test_scan_hit_rate_and_requests():
    """A raster scan of a 64 x 64 level 0 that fits the cache: one miss a line (1/16 of the
    pixels with 4 x 4 blocks), each request the line's first byte and a 16-beat burst."""
    g = CacheGeometry(64, 1, 28, sets=128, ways=2)
    v, u = np.mgrid[0:64, 0:64]
    run = run_cache(g, u.ravel(), v.ravel(), np.zeros(u.size, int), random_levels(g))
    assert run.hit_rate == 1 - 1 / 16
    assert len(run.requests) == g.lines == 256 and not run.evictions
    assert sorted(run.requests) == [(n * 64, 15) for n in range(256)]
    assert run.bytes_fetched == 64 * 64 * 4


def test_scan_of_a_map_larger_than_the_cache_evicts():
    """The same scan of 256 x 256 through 16 sets x 2 ways: a block row (64 lines) does not
    fit, so every texel row refetches its lines: a hit rate of 3/4, one eviction a miss
    after the first 32."""
    g = CacheGeometry(256, 1, 28, sets=16, ways=2)
    v, u = np.mgrid[0:256, 0:256]
    run = run_cache(g, u.ravel(), v.ravel(), np.zeros(u.size, int), random_levels(g))
    assert run.hit_rate == 3 / 4
    assert len(run.evictions) == len(run.requests) - 32
    levels = random_levels(g, 5)
    assert (run_cache(g, u.ravel(), v.ravel(), np.zeros(u.size, int), levels).texel
            == levels[0][v.ravel(), u.ravel()]).all()


def test_cycle_model_orders_and_limits():
    """stream_cycles (the non-blocking cache's schedule): one cycle a pixel when every pixel
    hits, never fewer cycles at a longer latency, never more than a blocking cache with the
    same misses; with one burst outstanding and a queue of two it can overlap little, and a
    lone miss costs what it costs the blocking cache but the re-read, the AR cycle and the
    queue's read and output register (a hit's cycles, which the wait for the line hides)."""
    g = CacheGeometry(64, 3, 28, sets=8)
    u, v, level = cache_stimulus(g, 400, 3)
    run = run_cache(g, u, v, level)
    cycles = [stream_cycles(run, g, lat) for lat in (1, 2, 20, 60)]
    assert len(u) < cycles[0] and cycles == sorted(cycles)
    assert cycles[-1] < blocking_cycles(run, g, 60) / 2
    tight = CacheGeometry(64, 3, 28, sets=8, queue=2, misses=1)
    assert cycles[-1] < stream_cycles(run, tight, 60) <= blocking_cycles(run, tight, 60)
    one = run_cache(g, [0] * 5, [0] * 5, [0] * 5)              # a miss, then four hits
    assert stream_cycles(one, g, 20) == blocking_cycles(one, g, 20) - 4 == 4 + 20 + 15
    again = run_cache(g, [0, 1, 2, 3] * 50, [0] * 200, [0] * 200)
    assert stream_cycles(again, g, 60) == 199 + 60 + 15


def test_an_empty_pixel_run_takes_no_cycles():
    g = CacheGeometry(64, 1, 28)
    empty = run_cache(g, [], [], [])
    assert len(empty.hit) == 0 and stream_cycles(empty, g, 20) == 0
    one = run_cache(g, [0], [0], [0])                 # one cold miss: at least its latency
    assert stream_cycles(one, g, 20) >= 20
