"""The golden texture cache: rtl/cache.TextureCache's hits, misses, line fills and
evictions, pixel by pixel, every AXI read request it issues, and its cycles
(docs/memory.md).

The RTL looks pixels up in order and, though its misses overlap (a miss's line is
allocated and its burst issued at the lookup, the pixel queued until the line lands), it
updates tags and replacement bits in lookup order exactly as a blocking cache would: a
miss takes the pseudo-LRU victim (waiting, never choosing another way, while a queued
pixel still needs it). So its hit/miss sequence is a blocking cache's, and its AR stream
is the sequence of misses: one INCR burst of a whole line (address of the line's first
byte, ARLEN = beats - 1) a miss. Placement (:func:`rtl.cache.tiled_layout`) and replacement (tree pseudo-LRU,
:func:`rtl.cache.plru_victim` / :func:`rtl.cache.plru_touch`) are the RTL's own functions;
the texel a pixel gets is read from the map itself, not from the model's lines, so a fill
of the wrong bytes or a stale line in the RTL differs from it.
"""

import bisect
from dataclasses import dataclass, field

import numpy as np

from bumprtl.rtl.bumpfetch import level_coords
from bumprtl.rtl.cache import (
    CacheGeometry,
    plru_touch,
    plru_victim,
    scene_levels,
    texel_byte_address,
    tiled_layout,
)

__all__ = ["CacheModel", "CacheRun", "run_cache", "pixel_lines", "miss_cycles", "blocking_cycles",
           "stream_cycles", "run_scene_cache", "random_levels",
           "cache_stimulus", "image_words"]


@dataclass
class CacheRun:
    """What the cache did with a pixel sequence: per pixel ``texel`` and ``hit``; the AR
    requests ``(araddr, arlen)`` in order; ``evictions`` (set, way, line evicted) in order;
    per pixel the ``set`` and ``way`` it reads and, for a miss, whether its victim way held
    a line (``victim_valid``: what the timing of :func:`stream_cycles` needs)."""
    texel: np.ndarray
    hit: np.ndarray
    line_bytes: int
    set: np.ndarray = None
    way: np.ndarray = None
    victim_valid: np.ndarray = None
    requests: list = field(default_factory=list)
    evictions: list = field(default_factory=list)

    @property
    def hit_rate(self):
        return float(self.hit.mean()) if self.hit.size else 0.0

    @property
    def bytes_fetched(self):
        return len(self.requests) * self.line_bytes


def miss_cycles(geom: CacheGeometry, latency):
    """Cycles a miss adds to its pixel's one in a *blocking* cache (the pixel held while its
    line is fetched, none behind it looked up): the AR offered (1), ``latency`` cycles to the
    first beat, ``beats`` beats, the re-read (1). ``latency``: cycles from the AR handshake to
    the first R beat offered (1 is the least AXI allows: RVALID after the handshake)."""
    return latency + geom.beats + 2


def blocking_cycles(run, geom: CacheGeometry, latency):
    """Cycles a blocking cache with the same hits and misses takes for ``run``: one a pixel
    plus :func:`miss_cycles` a miss (what :func:`stream_cycles` is compared against)."""
    return len(run.hit) + len(run.requests) * miss_cycles(geom, latency)


def stream_cycles(run, geom: CacheGeometry, latency):
    """Cycles TextureCache (non-blocking) takes for the pixels of ``run`` (a :class:`CacheRun`)
    offered back to back, its output always taken, the memory never stalling and
    answering each burst ``latency`` cycles after its AR handshake, its beats in order
    one a clock. Pixel k is looked up at cycle A_k, the earliest after A_{k-1} with a
    free queue entry (pixel k - queue left), for a miss at least two cycles after the
    one before (its AR handshake, at A + 1, frees the AR register), fewer than
    ``misses`` bursts outstanding and a victim no queued pixel references (the RTL's
    sequence-stamp test, wrap-around included); it leaves the
    queue at P_k = max(A_k + 3, P_{k-1} + 1, the cycle after its line's last beat for a
    miss). A miss's AR handshake is at A_k + 1, its first beat at max(A_k + 1 + latency,
    the cycle after the previous burst's last beat). Returns P_last - 3 (every pixel a
    hit: one cycle a pixel); the RTL takes the reset's flush (``sets`` cycles) and its
    hit latency (rtl/cache.CACHE_LATENCY) more (tests/rtl/test_cache.py checks the count
    against the RTL's)."""
    n = len(run.hit)
    if n == 0:
        return 0
    wrap = 1 << geom.stamp_bits
    pops, fills, stamps = [], [], {}
    look, miss, last_miss = 0, 0, -2
    for k in range(n):
        key = (int(run.set[k]), int(run.way[k]))
        c = look + 1
        if k >= geom.queue:
            c = max(c, pops[k - geom.queue] + 1)
        if not run.hit[k]:
            c = max(c, last_miss + 2)               # the AR register free again
            if miss >= geom.misses:
                c = max(c, fills[miss - geom.misses] + 1)
            if run.victim_valid[k]:
                stamp = stamps[key]
                while True:                         # queued pixels left before cycle c
                    out = bisect.bisect_left(pops, c)
                    if (stamp - out) % wrap < k - out:
                        c = pops[out] + 1           # locked until the next pixel leaves
                    else:
                        break
        stamps[key] = k % wrap
        leave = c + 3                               # queued, read, in the output register
        if not run.hit[k]:
            first = c + 1 + latency
            if fills:
                first = max(first, fills[-1] + 1)
            fills.append(first + geom.beats - 1)
            leave = max(leave, fills[-1] + 1)
            miss += 1
            last_miss = c
        if pops:
            leave = max(leave, pops[-1] + 1)
        pops.append(leave)
        look = c
    return pops[-1] - 3


class CacheModel:
    """The cache's state: the line held by each (set, way), or None, and the pseudo-LRU bits
    of each set. :meth:`access` of one pixel's (line) returns ``(hit, way, evicted line or
    None)`` and updates the state as the RTL does at the lookup: a miss gives the victim way
    to the line (the RTL writes the tag then; the burst fills the line later), and the
    access turns the set's bits from the way it used."""

    def __init__(self, geom: CacheGeometry):
        self.geom = geom
        self.lines = [[None] * geom.ways for _ in range(geom.sets)]
        self.plru = [0] * geom.sets

    def access(self, line):
        g = self.geom
        s = line % g.sets
        held = self.lines[s]
        evicted = None
        if line in held:
            way, hit = held.index(line), True
        else:
            way, hit = plru_victim(self.plru[s], g.ways), False
            evicted = held[way]
            held[way] = line
        self.plru[s] = plru_touch(self.plru[s], way, g.ways)
        return hit, way, evicted


def pixel_lines(geom: CacheGeometry, u, v, level):
    """The line (:func:`rtl.cache.tiled_layout`) of each pixel, int64 arrays in, out."""
    u, v = np.asarray(u, np.int64), np.asarray(v, np.int64)
    level = np.minimum(np.asarray(level, np.int64), geom.mip_levels - 1)
    lines = np.zeros_like(u)
    for lv in range(geom.mip_levels):
        at = level == lv
        lines[at] = tiled_layout(u[at], v[at], lv, geom)[0]
    return lines


def run_cache(geom: CacheGeometry, u, v, level, levels=None):
    """Run the pixels (level coordinates ``u``, ``v`` and ``level`` arrays; ``level`` past
    the last reads the last) through a cold cache; ``levels[l]`` is level l's texel words
    ([v, u]; None: no texels, for hit rates alone). Returns a :class:`CacheRun`."""
    u, v = np.asarray(u, np.int64), np.asarray(v, np.int64)
    level = np.minimum(np.asarray(level, np.int64), geom.mip_levels - 1)
    model = CacheModel(geom)
    n = len(u)
    run = CacheRun(np.zeros(n, np.int64), np.zeros(n, bool), geom.line_bytes,
                   np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, bool))
    prev, way = None, 0
    for k, line in enumerate(pixel_lines(geom, u, v, level).tolist()):
        run.set[k] = line % geom.sets
        if line == prev:             # the line just used: a hit that leaves the bits as they are
            run.hit[k], run.way[k] = True, way
            continue
        prev = line
        hit, way, evicted = model.access(line)
        run.hit[k], run.way[k] = hit, way
        run.victim_valid[k] = not hit and evicted is not None
        if not hit:
            run.requests.append((geom.base + line * geom.line_bytes, geom.beats - 1))
            if evicted is not None:
                run.evictions.append((line % geom.sets, way, evicted))
    for lv in range(geom.mip_levels if levels is not None else 0):
        at = level == lv
        run.texel[at] = np.asarray(levels[lv], np.int64)[v[at], u[at]]
    return run


def random_levels(geom: CacheGeometry, seed=0):
    """Random texel words for every level of ``geom`` (``[v, u]`` arrays)."""
    rng = np.random.default_rng(seed)
    return [rng.integers(0, 1 << geom.texel_bits, geom.level_size(lv)[::-1])
            for lv in range(geom.mip_levels)]


def cache_stimulus(geom: CacheGeometry, n, seed):
    """``(u, v, level)`` arrays of ``n`` pixels a cache must serve: short raster runs (hits),
    random jumps (misses and evictions), every level."""
    rng = np.random.default_rng(seed)
    u, v, level = [], [], []
    while len(u) < n:
        lv = int(rng.integers(0, geom.mip_levels))
        side, tall = geom.level_size(lv)
        u0, v0, run = int(rng.integers(0, side)), int(rng.integers(0, tall)), int(rng.integers(1, 12))
        for k in range(run):
            u.append((u0 + k) % side)
            v.append(v0)
            level.append(lv)
    return np.array(u[:n]), np.array(v[:n]), np.array(level[:n])


def run_scene_cache(scene, geom: CacheGeometry, inputs, words):
    """:func:`run_cache` of a ``map_memory = "axi"`` pipeline's pixels: ``inputs`` (arrays
    ``u``, ``v``, [``level``], level-0 signed coordinates) wrapped or clamped into their
    level as rtl/cache.AxiMapFetch does (``bumpfetch.level_coords``); ``words`` the map in
    block-RAM order."""
    u, v = np.asarray(inputs["u"], np.int64), np.asarray(inputs["v"], np.int64)
    level = np.minimum(np.asarray(inputs.get("level", np.zeros_like(u)), np.int64),
                       scene.mip_levels - 1)
    u_l, v_l = np.zeros_like(u), np.zeros_like(v)
    for n in range(scene.mip_levels):
        cu, cv = level_coords(u, v, n, scene)
        u_l, v_l = np.where(level == n, cu, u_l), np.where(level == n, cv, v_l)
    return run_cache(geom, u_l, v_l, level, scene_levels(scene, words))


def image_words(scene, geom: CacheGeometry, image):
    """The map words in block-RAM order (``bumpfetch.level_bases``) read back from a memory
    image (``bytes`` from ``base`` on, :func:`rtl.cache.tiled_image`'s layout)."""
    buf = np.frombuffer(image, np.uint8)
    out = []
    for level in range(scene.mip_levels):
        side, tall = scene.level_size(level)
        v, u = np.mgrid[0:tall, 0:side]
        at = texel_byte_address(u.ravel(), v.ravel(), level, geom) - geom.base
        word = sum(buf[at + k].astype(np.int64) << (8 * k) for k in range(geom.slot_bytes))
        out.append(word & ((1 << geom.texel_bits) - 1))
    return np.concatenate(out)
