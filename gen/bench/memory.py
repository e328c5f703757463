"""``bumprtl bench memory``: the texel cache (rtl/cache.py) on the demo scenes' texel streams.

For each scene's geometry (plane, sphere, cylinder) at a magnification of one texel per
pixel (a frame of T x T pixels on a T x T map, level 0), each method's stored texel (the
exact method's N' angle pair, the palette's index), map size and cache geometry, the golden
cache model (sim/golden/cache.py, the RTL's hit/miss sequence) runs a band of frame rows
through a cold cache: hit rate and bytes fetched per pixel. Cycles per pixel follow from
sim/golden/cache.stream_cycles (the non-blocking cache's schedule, misses overlapping;
checked against the RTL's count by tests/rtl/test_cache.py) for a memory that never stalls
and answers each burst ``latency`` cycles after its AR handshake, its beats one a clock;
throughput is given against the zero-wait memory (latency 1: the first beat the cycle
after the handshake), beside a blocking cache's with the same hits and misses
(sim/golden/cache.blocking_cycles: one a pixel, ``latency + beats + 2`` a miss).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bumprtl.gen.tools.docs import made_at
from bumprtl.rtl.cache import CACHE_DEFAULTS, CACHE_LATENCY, CacheGeometry
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.palette import index_bits
from bumprtl.sim.golden.cache import blocking_cycles, run_cache, stream_cycles
from bumprtl.sim.scenes import SCENES, texel_coordinates

__all__ = ["MEMORY_SCENES", "MAP_SIZES", "LATENCIES", "CACHES", "METHODS", "MemoryRow",
           "memory_rows", "memory_bench", "COMMAND"]

COMMAND = "bumprtl bench memory --doc docs/memory.md"
MEMORY_SCENES = ("bricks", "globe", "cylinder")      # one a geometry: plane, sphere, cylinder
MAP_SIZES = (256, 1024, 4096)
LATENCIES = (1, 2, 20, 60)
ZERO_WAIT = 1
# name -> CacheGeometry parameters: the default, four times the sets and ways, 8 x 8 lines
CACHES = {"64x2 4x4": {}, "256x4 4x4": {"sets": 256, "ways": 4},
          "64x2 8x8": {"block": 8}}
METHODS = ("exact", "palette")
BAND_ROWS = 64                    # frame rows through the cache, centred in the frame


def texel_bits(method, cfg=None):
    """Bits of one stored texel: the exact method's N' angle pair, or a palette index."""
    cfg = cfg or Config()
    return index_bits(cfg) if method == "palette" else 2 * cfg.angle_bits


@dataclass(frozen=True)
class MemoryRow:
    """One point: ``pixels`` run, ``hit_rate``, ``bytes_per_pixel`` fetched, and per latency
    (``LATENCIES``) ``cycles_per_pixel`` and a blocking cache's ``blocking_cycles_per_pixel``;
    ``cache_kib`` the cache's data and tag bits."""
    scene: str
    method: str
    size: int
    cache: str
    cache_kib: float
    pixels: int
    hit_rate: float
    bytes_per_pixel: float
    cycles_per_pixel: dict
    blocking_cycles_per_pixel: dict

    def ratio(self, latency, against=ZERO_WAIT, blocking=False):
        """Throughput at ``latency`` against the zero-wait memory's (or, ``against`` None,
        against one pixel a clock); ``blocking``: a blocking cache's."""
        cycles = self.blocking_cycles_per_pixel if blocking else self.cycles_per_pixel
        ref = 1.0 if against is None else cycles[against]
        return ref / cycles[latency]


def band(geometry, size, rows=BAND_ROWS):
    """Texel coordinates of the covered pixels of ``rows`` frame rows at the frame's centre
    (a ``size`` x ``size`` frame on a ``size`` x ``size`` map), in raster order."""
    u, v, mask = texel_coordinates(geometry, size, size)
    top = (size - min(rows, size)) // 2
    sel = slice(top, top + min(rows, size))
    return u[sel][mask[sel]], v[sel][mask[sel]]


def memory_rows(scenes=MEMORY_SCENES, sizes=MAP_SIZES, caches=tuple(CACHES), methods=METHODS,
                latencies=LATENCIES, rows=BAND_ROWS):
    """Every (scene, method, size, cache) point as a :class:`MemoryRow`."""
    for name in scenes:
        if name not in SCENES:
            raise BumpError(f"scene must be one of {', '.join(SCENES)}, got {name!r}", "scene")
    for name in caches:
        if name not in CACHES:
            raise BumpError(f"cache must be one of {', '.join(CACHES)}, got {name!r}", "cache")
    if isinstance(rows, bool) or not isinstance(rows, int) or rows < 1:
        raise BumpError(f"rows must be an integer >= 1, got {rows!r}", "rows")
    latencies = sorted({ZERO_WAIT, *latencies})
    out = []
    for name in scenes:
        for size in sizes:
            u, v = band(SCENES[name][1], size, rows)
            for method in methods:
                for cache in caches:
                    geom = CacheGeometry(size, 1, texel_bits(method), **CACHES[cache])
                    run = run_cache(geom, u, v, np.zeros_like(u))
                    n = len(u)
                    out.append(MemoryRow(
                        name, method, size, cache, geom.cache_bits / 8192, n, run.hit_rate,
                        run.bytes_fetched / n,
                        {lat: stream_cycles(run, geom, lat) / n for lat in latencies},
                        {lat: blocking_cycles(run, geom, lat) / n for lat in latencies}))
    return out


def _table(rows, latencies):
    head = ("| scene | method | map | cache (sets x ways, line) | KiB | hit rate | bytes/px | "
            + " | ".join(f"cycles/px L={lat}" for lat in latencies)
            + " | " + " | ".join(f"vs zero-wait L={lat}" for lat in latencies if lat != ZERO_WAIT)
            + " | " + " | ".join(f"blocking L={lat}" for lat in latencies if lat >= 20)
            + " |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        cells = [r.scene, r.method, f"{r.size}²", r.cache, f"{r.cache_kib:.1f}",
                 f"{100 * r.hit_rate:.2f} %", f"{r.bytes_per_pixel:.2f}",
                 *[f"{r.cycles_per_pixel[lat]:.2f}" for lat in latencies],
                 *[f"{100 * r.ratio(lat):.1f} %" for lat in latencies if lat != ZERO_WAIT],
                 *[f"{100 * r.ratio(lat, blocking=True):.1f} %" for lat in latencies if lat >= 20]]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _worst(rows, latency, blocking=False):
    """The least throughput against the zero-wait memory at ``latency``, as a percentage."""
    if latency not in rows[0].cycles_per_pixel:
        return "(not run)"
    worst = min(rows, key=lambda r: r.ratio(latency, blocking=blocking))
    return f"{100 * worst.ratio(latency, blocking=blocking):.1f} %"


def _plot(rows, path):
    import matplotlib  # optional dependency: [bench]

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # optional dependency: [bench]

    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=80)
    size = max(r.size for r in rows)
    for r in rows:
        if r.size == size and r.cache == next(iter(CACHES)):
            lats = sorted(r.cycles_per_pixel)
            line, = ax.plot(lats, [100 * r.ratio(lat) for lat in lats], "-o",
                            label=f"{r.scene} {r.method}")
            ax.plot(lats, [100 * r.ratio(lat, blocking=True) for lat in lats], ":",
                    color=line.get_color())
    ax.set_xlabel("memory latency (cycles, AR handshake to first R beat)")
    ax.set_ylabel("throughput vs zero-wait memory (%)")
    ax.set_title(f"Texel cache {next(iter(CACHES))}, {size}² map, 1 texel/pixel "
                 "(dotted: blocking)", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def _page(rows, latencies, plot):
    d = CACHE_DEFAULTS
    return f"""# The texel cache: hit rates and throughput

Generated by `{COMMAND}`; do not edit. {made_at(Config(), "the exact method's texel is the two angles")}

A scene with `map_memory = "axi"` keeps its map in the user's memory, in the tiled layout
of `rtl/cache.tiled_layout` (`bumprtl emit pipeline --map-memory axi` writes it as
`<name>_map.bin`; the sidecar's `memory_images.map` gives its base, size and layout; a
map `texture_size` wide and `texture_height` high is tiled row of blocks by row of blocks,
docs/integration.md), and
reads it through `TextureCache`: set-associative, {d["sets"]} sets x {d["ways"]} ways of
{d["block"]} x {d["block"]}-texel lines by default, tree pseudo-LRU (LRU for 2 ways), one
AXI4 INCR burst of a whole line ({d["data_bits"]}-bit data by default) a miss. It does not
block on a miss (prefetching behind a reorder queue, after Igehy, Eldridge & Proudfoot,
HWWS 1998): a pixel's set is read as it arrives (its tags and stamps land in registers of
their own the cycle after) and its tags checked as it moves on to the lookup, a miss issues
its burst at once (up
to {d["misses"]} outstanding), and the pixel waits in a queue of {d["queue"]} entries with
its line's place while the pixels behind it are looked up and their misses issued; pixels
leave in order, a miss once its line has landed. A line a queued pixel still needs is not
evicted (a miss whose victim is still referenced waits). The scene
keys `cache_sets`, `cache_ways`, `cache_block` and `axi_data_bits` (flags `--cache-sets`,
`--cache-ways`, `--cache-block`, `--axi-data-bits` of `bumprtl emit pipeline`) size it,
`cache_queue` (`--cache-queue`, a power of two in [2, 1024], default {d["queue"]}) and
`cache_outstanding` (`--cache-outstanding`, a power of two in [1, 64], default
{d["misses"]}) set its queue and the bursts it keeps outstanding;
a cache that does not fit the device's block RAM beside the pipeline's tables is refused. A full
queue, or a miss that has to wait, holds the pixel at the pipeline's input; the
free-running chain behind the credit edge never stops, and its outputs are bit-exact with the golden model under any memory latency
(tests/rtl/test_cache.py, tests/sim/tb/test_tb_pipeline_axi.py against cocotbext-axi's
AxiRam).

## The AXI4 read port

`bumprtl emit pipeline --map-memory axi` adds to the pipeline's stream ports the manager side
of an AXI4 read channel (Amaranth's flattened names; `rtl/cache.axi_read_signature`):
`axi__arid` (1 bit, always 0), `axi__araddr` (32 bits), `axi__arlen` (beats - 1),
`axi__arsize` (log2 of the data bytes), `axi__arburst` (1, INCR), `axi__arvalid`,
`axi__arready`, `axi__rid` and `axi__rresp` (not read), `axi__rdata` (32 bits by default),
`axi__rlast`, `axi__rvalid`, `axi__rready`. A burst is a whole line, aligned to its size
(never across 4 KiB); up to {d["misses"]} are outstanding, all with ARID 0, so the memory
returns them in order; ARVALID stays high with a stable payload until ARREADY; RREADY is
high while a burst is outstanding, and each line's fill ends with RLAST (these rules are
proved by k-induction against any subordinate that keeps AXI4's: `make formal`,
docs/formal.md, The texel cache's AXI4 port). Put
`<name>_map.bin` at byte `base` (0) of the memory the port reads; the sidecar's
`memory_images.map` gives `file`, `base`, `bytes` and the `layout` in words. A reset clears
the tags one set a cycle (`i.ready` low for `sets` cycles); the map must not change between
resets. `i.ready` is the cache's: it falls the cycle after the looked-up pixel waits (queue
full, a miss with its victim still needed, {d["misses"]} bursts outstanding, or ARVALID
waiting for ARREADY) with the stages behind it full, a function of registers alone (never
of `i.valid`). A hit reaches `o` {CACHE_LATENCY} cycles after it is taken.

## Hit rates and throughput

Method: each demo geometry (bricks: plane, globe: sphere, cylinder) at one texel per pixel
(a T x T frame on a T x T map, level 0), the {BAND_ROWS} frame rows at its centre in raster
order through a cold cache in the golden cache model (the RTL's hit/miss sequence). Cycles
per pixel: `sim/golden/cache.stream_cycles`, the RTL's own count for a memory that never
stalls, answers each burst L cycles after its AR handshake with one beat a clock, and an
output always taken (tests/rtl/test_cache.py); L = 1 is the zero-wait memory. "blocking":
a cache that holds the pixel on a miss (one pixel a cycle plus `L + beats + 2` a miss,
`sim/golden/cache.blocking_cycles`, the first version of this cache), against its own
zero-wait throughput.
exact: 28-bit N' angle pairs in 4-byte slots; palette: {texel_bits("palette")}-bit indices
in 1-byte slots (the palette scene's index map with `map_memory = "axi"`, its colour table
behind the cache).

With misses overlapping, the latency is hidden: at L = 20 every case keeps at least
{_worst(rows, 20)} of its zero-wait throughput (the blocking cache: {_worst(rows, 20, True)}),
at L = 60 at least {_worst(rows, 60)} (blocking: {_worst(rows, 60, True)}). What remains is
the memory's bandwidth: a miss costs `beats` cycles of the R channel whatever the latency,
so a stream that misses more than once per `beats` pixels runs at the memory's pace
(exact 4 x 4 lines of a 1024² map in the 64 x 2 cache: 16 beats every 4th pixel, 4 cycles a
pixel). A raster scan of a map wider than the cache refetches each line for every texel
row of its block. The loss left at L = 60 is the queue's: a run of misses faster than the
memory (the first texel row of each block row) fills its {d["queue"]} entries, and the
latency shows once it is full. Fewer entries, or fewer bursts outstanding (`cache_queue`,
`cache_outstanding`), hide less (Little's law: {d["queue"]} pixels, or {d["misses"]} lines,
every L + beats cycles).

![throughput against latency]({plot})

{_table(rows, latencies)}
"""


def memory_bench(scenes=MEMORY_SCENES, sizes=MAP_SIZES, caches=tuple(CACHES), methods=METHODS,
                 latencies=LATENCIES, rows=BAND_ROWS, doc=None, plot=None):
    """Print the table; with ``doc`` write the page (and its plot, default
    ``docs/img/memory.png`` beside it)."""
    points = memory_rows(scenes, sizes, caches, methods, latencies, rows)
    lats = sorted({ZERO_WAIT, *latencies})
    print(_table(points, lats))
    if doc is not None:
        doc = Path(doc)
        plot = Path(plot) if plot is not None else doc.parent / "img" / "memory.png"
        _plot(points, plot)
        doc.write_text(_page(points, lats, Path("img") / plot.name
                             if plot.parent == doc.parent / "img" else plot))
        print(f"wrote {doc}\nwrote {plot}")
    return 0
