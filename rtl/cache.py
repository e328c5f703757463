"""TextureCache: a set-associative texel cache in front of an AXI4 read-only memory
(docs/memory.md).

The map lives in the user's memory in a tiled layout (:func:`tiled_layout`): each mip
level (W >> l by H >> l texels; W = H for a square map) is cut into square blocks of
``block`` x ``block`` texels, a block is one cache line
(``block**2`` texel slots, row-major inside the block), the blocks of a level row-major,
the levels one after the other from ``base``. A texel slot is the smallest power of two
of bytes that holds a texel (a 28-bit N' angle pair: 4 bytes; an 8-bit palette index: 1
byte). A level smaller than a block takes one whole line, its texels at their (u, v) slots.
The same function places the texels in the RTL (line and slot of a pixel), in the golden
model (sim/golden/cache.py) and in the memory image (:func:`tiled_image`), so the three
cannot drift apart.

Replacement: tree pseudo-LRU over the ``ways`` of a set (``ways - 1`` bits a set; exactly
LRU for 2 ways): the victim is the leaf the bits point to; a pixel that hits turns the bits
on its path away from its way (:func:`plru_victim`, :func:`plru_touch`, shared with the
golden model).
"""

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
from amaranth.hdl import (
    Cat,
    Const,
    Module,
    Mux,
    Shape,
    Signal,
    Value,
    ValueCastable,
    signed,
    unsigned,
)
from amaranth.lib import data, stream, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from bumprtl.rtl.bumpfetch import coord_bits, fetched_field, level_bits, level_coords, texel_shape
from bumprtl.rtl.config import BumpError, check_pow2
from bumprtl.rtl.scene import CACHE_DEFAULTS as SCENE_CACHE
from bumprtl.rtl.scene import HardwareScene, MapSize, check_scene
from bumprtl.rtl.targets import RegisteredRAM

__all__ = ["CacheGeometry", "AXI_DATA_BITS", "axi_read_signature", "tiled_layout",
           "texel_byte_address", "tiled_image", "plru_victim", "plru_touch", "TextureCache",
           "CACHE_DEFAULTS", "SCENE_KEYS", "ARBURST_INCR", "AxiMapFetch", "scene_geometry",
           "scene_levels", "CACHE_LATENCY"]

# Cycles from a pixel taken at TextureCache.i to its texel offered at o when it hits and the
# queue is empty: the tag read, its words' register, their settled register, their stamps'
# distances, the lookup, the queue's write, its read, its output register (where the pixel
# is the queue's head and leaves), the head register, the data read, its words' register,
# the output register.
CACHE_LATENCY = 12

AXI_DATA_BITS = (32, 64)
ARBURST_INCR = 1
MAX_BURST = 256                     # AXI4 INCR: ARLEN + 1 <= 256 beats
AXI_PAGE = 4096                     # a burst never crosses a 4 KiB boundary
# CacheGeometry's parameter -> the scene key that sets it (rtl/scene.CACHE_DEFAULTS)
SCENE_KEYS = {"sets": "cache_sets", "ways": "cache_ways", "block": "cache_block",
              "data_bits": "axi_data_bits", "queue": "cache_queue", "misses": "cache_outstanding"}
# sets, ways, block side, AXI data bits, queue, bursts outstanding: the scene's defaults
CACHE_DEFAULTS = {name: SCENE_CACHE[key] for name, key in SCENE_KEYS.items()}


@dataclass(frozen=True)
class CacheGeometry(MapSize):
    """The map in memory and the cache in front of it.

    Parameters
    ----------
    texture_size : int
        W, the width of mip level 0 (a power of two; the side T of a square map).
    mip_levels : int
        Levels stored, level l of W >> l by H >> l texels, 1 to log2(H) + 1.
    texel_bits : int
        Bits of one stored texel (N' angle pair or palette index), <= ``data_bits``.
    sets, ways, block : int
        Powers of two: sets of the cache, lines a set, side of a line's square block.
    data_bits : int
        AXI RDATA width, 32 or 64.
    base : int
        Byte address of the image in the memory (a multiple of the line's bytes).
    addr_bits : int
        AXI ARADDR width; the image must end below 2**addr_bits.
    queue : int
        Pixels the non-blocking cache holds between its lookup and its output (a power of
        two): what hides the memory's latency (docs/memory.md).
    misses : int
        Line fills (AXI bursts) outstanding at most (a power of two).
    stamp_bits : int or None
        Bits of the sequence numbers of queued pixels (a stamp a line), in
        [log2(queue) + 1, 32]; None: ``max(16, log2(queue) + 2)``, wide enough that a stale
        stamp rarely looks queued (that only delays a miss until the queue drains). A
        narrow one wraps within a short stream (the tests' way to reach the wrap).
    texture_height : int or None
        H, the height of mip level 0, a power of two at most W; None: W (a square map).
    """

    texture_size: int
    mip_levels: int
    texel_bits: int
    sets: int = CACHE_DEFAULTS["sets"]
    ways: int = CACHE_DEFAULTS["ways"]
    block: int = CACHE_DEFAULTS["block"]
    data_bits: int = CACHE_DEFAULTS["data_bits"]
    base: int = 0
    addr_bits: int = 32
    queue: int = CACHE_DEFAULTS["queue"]
    misses: int = CACHE_DEFAULTS["misses"]
    stamp_bits: int | None = None
    texture_height: int | None = None

    def __post_init__(self):
        check_pow2("texture_size", self.texture_size, 1, 1 << 16)
        if self.texture_height is not None:
            check_pow2("texture_height", self.texture_height, 1, self.texture_size)
        top = self.map_height.bit_length()
        if not isinstance(self.mip_levels, int) or not 1 <= self.mip_levels <= top:
            raise BumpError(f"mip_levels must be an integer in [1, {top}], got "
                            f"{self.mip_levels!r}", "mip_levels")
        if self.data_bits not in AXI_DATA_BITS:
            raise BumpError(f"data_bits must be one of 32, 64, got {self.data_bits!r}",
                            "data_bits")
        if not isinstance(self.texel_bits, int) or not 1 <= self.texel_bits <= self.data_bits:
            raise BumpError(f"texel_bits must be an integer in [1, {self.data_bits}], got "
                            f"{self.texel_bits!r}", "texel_bits")
        check_pow2("sets", self.sets, 1, 1 << 14)
        check_pow2("ways", self.ways, 1, 16)
        check_pow2("block", self.block, 2, min(16, self.map_height))
        if self.line_bytes < self.data_bits // 8 or self.beats > MAX_BURST \
                or self.line_bytes > AXI_PAGE:
            raise BumpError(f"block must make a line of {self.data_bits // 8} to "
                            f"{min(AXI_PAGE, MAX_BURST * self.data_bits // 8)} bytes (one AXI "
                            f"INCR burst), got {self.block} x {self.block} texels of "
                            f"{self.slot_bytes} bytes", "block")
        if not isinstance(self.base, int) or self.base < 0 or self.base % self.line_bytes:
            raise BumpError(f"base must be a non-negative multiple of the line's "
                            f"{self.line_bytes} bytes, got {self.base!r}", "base")
        if not isinstance(self.addr_bits, int) or not 12 <= self.addr_bits <= 64:
            raise BumpError(f"addr_bits must be an integer in [12, 64], got "
                            f"{self.addr_bits!r}", "addr_bits")
        check_pow2("queue", self.queue, 2, 1024)
        check_pow2("misses", self.misses, 1, 64)
        least = self.queue.bit_length()          # in_seq - out_seq counts up to queue
        if self.stamp_bits is None:
            object.__setattr__(self, "stamp_bits", max(16, least + 1))
        elif isinstance(self.stamp_bits, bool) or not isinstance(self.stamp_bits, int) \
                or not least <= self.stamp_bits <= 32:
            raise BumpError(f"stamp_bits must be an integer in [{least}, 32] for queue "
                            f"{self.queue}, got {self.stamp_bits!r}", "stamp_bits")
        if self.base + self.image_bytes > 1 << self.addr_bits:
            raise BumpError(f"the map's image ends at byte {self.base + self.image_bytes}, "
                            f"beyond the {self.addr_bits}-bit AXI address space (addr_bits "
                            f"in [{(self.base + self.image_bytes - 1).bit_length()}, 64])",
                            "addr_bits")

    # --- the layout in memory ---
    @property
    def slot_bytes(self):
        """Bytes of one texel slot: the least power of two >= texel_bits / 8."""
        return 1 << max(0, (self.texel_bits - 1).bit_length() - 3)

    @property
    def block_bits(self):
        return self.block.bit_length() - 1

    @property
    def line_texels(self):
        return self.block * self.block

    @property
    def line_bytes(self):
        return self.line_texels * self.slot_bytes

    @property
    def beats(self):
        """Beats of one line's burst (ARLEN + 1)."""
        return self.line_bytes * 8 // self.data_bits

    @property
    def slots_per_beat(self):
        return self.data_bits // (8 * self.slot_bytes)

    def blocks_per_row(self, level):
        return max(1, self.level_size(level)[0] >> self.block_bits)

    def blocks_per_column(self, level):
        return max(1, self.level_size(level)[1] >> self.block_bits)

    def level_blocks(self, level):
        """Lines of ``level``: its blocks a row times its blocks a column."""
        return self.blocks_per_row(level) * self.blocks_per_column(level)

    @property
    def level_lines(self):
        """The first line of each level (levels one after the other)."""
        out, n = [], 0
        for level in range(self.mip_levels):
            out.append(n)
            n += self.level_blocks(level)
        return out

    @property
    def lines(self):
        return self.level_lines[-1] + self.level_blocks(self.mip_levels - 1)

    @property
    def image_bytes(self):
        return self.lines * self.line_bytes

    # --- the cache ---
    @property
    def set_bits(self):
        return self.sets.bit_length() - 1

    @property
    def tag_bits(self):
        """Bits of a line's tag (line >> set_bits), at least 1."""
        return max(1, (self.lines - 1).bit_length() - self.set_bits)

    @property
    def line_bits(self):
        return max(1, (self.lines - 1).bit_length())

    @property
    def way_bits(self):
        return self.ways.bit_length() - 1

    @property
    def cache_bits(self):
        """Block-RAM bits of the cache: data (ways x sets lines) and tags (+ valid bit)."""
        return self.ways * self.sets * (self.line_bytes * 8 + self.tag_bits + 1)


def _is_hdl(x):
    return isinstance(x, (Value, ValueCastable))


def tiled_layout(u, v, level, geom: CacheGeometry):
    """``(line, slot)`` of texel (u, v) of constant mip ``level`` (level coordinates, u in
    [0, W >> level), v in [0, H >> level)): line = first line of the level + (v >> b) *
    blocks a row + (u >> b), slot = (v mod B) * B + (u mod B) for blocks of B = 2**b.
    Amaranth values or int arrays."""
    b, mask = geom.block_bits, geom.block - 1
    row_bits = geom.blocks_per_row(level).bit_length() - 1
    first = geom.level_lines[level]
    if _is_hdl(u):
        u, v = Value.cast(u), Value.cast(v)
        side, tall = (n.bit_length() - 1 for n in geom.level_size(level))
        inner = Cat(u[b:max(b, side)], v[b:max(b, tall)]) if row_bits else Const(0, 1)
        return inner + first, Cat(u[:b], v[:b])
    u, v = np.asarray(u, np.int64), np.asarray(v, np.int64)
    return first + ((v >> b) << row_bits) + (u >> b), ((v & mask) << b) | (u & mask)


def texel_byte_address(u, v, level, geom: CacheGeometry):
    """Byte address of texel (u, v) of ``level`` in the memory (int arrays)."""
    line, slot = tiled_layout(u, v, level, geom)
    return geom.base + line * geom.line_bytes + slot * geom.slot_bytes


def tiled_image(geom: CacheGeometry, levels):
    """The map's memory image (``bytes``, from ``base``: the image's first byte is at
    ``base``): ``levels[l]`` is level l's texel words, a (H >> l) x (W >> l) array indexed
    [v, u]; each word little-endian in its slot, unused slots zero."""
    image = np.zeros(geom.lines * geom.line_texels, np.uint64)
    for level in range(geom.mip_levels):
        side, tall = geom.level_size(level)
        words = np.asarray(levels[level], np.int64)
        if words.shape != (tall, side):
            raise BumpError(f"level {level} must be {side} x {tall} texels (width x height, "
                            f"an array of {tall} rows), got {words.shape}", "levels")
        if words.size and (words.min() < 0 or words.max() >> geom.texel_bits):
            raise BumpError(f"level {level} has words outside [0, 2**{geom.texel_bits})",
                            "levels")
        v, u = np.mgrid[0:tall, 0:side]
        line, slot = tiled_layout(u, v, level, geom)
        image[line * geom.line_texels + slot] = words
    dtype = {1: "<u1", 2: "<u2", 4: "<u4", 8: "<u8"}[geom.slot_bytes]
    return image.astype(dtype).tobytes()


def plru_victim(bits, ways):
    """The way tree pseudo-LRU ``bits`` (an int, heap node n at bit n; 0: the left half is
    older) point to."""
    node = 0
    for _ in range(ways.bit_length() - 1):
        node = 2 * node + 1 + ((bits >> node) & 1)
    return node - (ways - 1)


def plru_touch(bits, way, ways):
    """``bits`` after an access to ``way``: every node on its path points away from it."""
    node, depth = 0, ways.bit_length() - 1
    for level in range(depth):
        d = (way >> (depth - 1 - level)) & 1
        bits = (bits & ~(1 << node)) | ((1 - d) << node)
        node = 2 * node + 1 + d
    return bits


def axi_read_signature(addr_bits, data_bits):
    """An AXI4 read-only manager port (AR and R channels, the manager's view) with one ID:
    ARID is 0 and RID is not read (bursts are served in order)."""
    return wiring.Signature({
        "arid": Out(1), "araddr": Out(addr_bits), "arlen": Out(8), "arsize": Out(3), "arburst": Out(2),
        "arvalid": Out(1), "arready": In(1),
        "rid": In(1), "rdata": In(data_bits), "rresp": In(2), "rlast": In(1), "rvalid": In(1),
        "rready": Out(1)})


class TextureCache(wiring.Component):
    """Texel coordinates in, the stored texel word out, through a non-blocking
    set-associative cache of an AXI4 memory holding the map in the :func:`tiled_layout`.

    Parameters
    ----------
    geom : CacheGeometry
    extra : dict, optional
        Payload fields (name -> shape) carried from ``i`` to ``o`` unchanged.
    target : None or rtl/targets.ECP5
        The form of its RAMs (rtl/targets.RegisteredRAM): None, the generic one.

    Members
    -------
    i : In(stream.Signature({u: unsigned(log2 W), v: unsigned(log2 H), level: unsigned
    (mip_levels > 1), extra}))
        Coordinates of the level (already wrapped or clamped, in [0, W >> level) and
        [0, H >> level)).
    o : Out(stream.Signature({texel: unsigned(texel_bits), extra}))
        Pixels in input order; ``o.valid``/``o.payload`` are a register.
    axi : Out(axi_read_signature(addr_bits, data_bits))
        The memory port: one INCR burst of ``beats`` beats per miss (ARLEN = beats - 1,
        ARSIZE = log2(data_bits / 8)), ARVALID held with a stable payload until ARREADY, up
        to ``geom.misses`` bursts outstanding (one ID: the R beats come back in order),
        RREADY high while a burst is outstanding.

    Misses overlap (prefetching behind a reorder queue, Igehy, Eldridge & Proudfoot, HWWS
    1998): a pixel's set is read as it is taken (tags and sequence stamps), the words land
    in the RAMs' output registers the cycle after and, with the writes they missed, in
    registers of the fabric the cycle after that (through a skid register when those wait,
    so that the RAMs' read enables come from registers), each stamp becomes its distance
    from the youngest queued pixel the cycle after that, its tags are checked as it moves
    on into the lookup, and a miss writes the new tag and issues its line's burst at once; the pixel
    then waits in a queue of ``geom.queue`` entries with its (set, way, word) while the
    pixels behind it are looked up. A pixel leaves the queue in order; a miss's pixel only
    once its line has landed (bursts land in order, so a count of lines landed suffices: a
    later hit to a line still filling leaves after the miss that fetches it). A line a
    queued pixel still needs is never evicted: each (set, way) keeps the sequence number of
    the last pixel queued on it, and a miss whose pseudo-LRU victim is still referenced
    waits at the lookup (so does a miss with ``misses`` bursts outstanding, a pixel with the
    queue full, or a miss while ARVALID is high: in the cycle of its handshake too). The
    hit/miss sequence and the AR stream are the blocking cache's (sim/golden/cache.py).
    The queue RAM is read ahead of the pops, in order, at an address and with an enable that
    are registers, into two fabric registers behind its output register (the head is the
    oldest of them); the pixel's carried fields wait in a LUT-RAM FIFO from its taking to
    its lookup; a skid register in front of the output register keeps ``o.ready`` off the
    pop and the data RAMs' enables. Each register the lookup's advance reaches takes it as
    the last choice before its flip-flop.
    ``i.ready`` is high while the skid register is empty or the words read are, a function of
    registers alone (never of ``i.valid``). Every block-RAM read
    lands in a register before any logic reads it, and no read is transparent (the stages
    forward the writes their reads miss). A hit leaves ``CACHE_LATENCY`` cycles after it is
    taken, one pixel a clock. A reset invalidates every line: the tags are cleared one set a
    cycle (``sets`` cycles, ``i.ready`` low) before the first lookup; the map in memory must
    not change between resets.
    """

    def __init__(self, geom: CacheGeometry, extra=None, target=None):
        self.geom, self.target = geom, target
        self.extra = dict(extra or {})
        K = geom.stamp_bits
        # The control registers, here so that the formal contracts (sim/formal/axi.py, the
        # stream contract of a map_memory = "axi" pipeline) can state lemmas about them.
        self.regs = SimpleNamespace(
            flushing=Signal(init=1, name="flushing"),
            in_valid=Signal(name="in_valid"),                     # a pixel read: its set
            rw_valid=Signal(name="rw_valid"),                     # its words read
            sk_valid=Signal(name="sk_valid"),                     # their skid register
            ws_valid=Signal(name="ws_valid"),                     # its words in registers
            ds_valid=Signal(name="ds_valid"),                     # their stamps' distances
            look_valid=Signal(name="look_valid"),                 # a pixel under lookup
            go=Signal(name="look_go"),            # ~flushing & look_valid & count != queue
            look_hit=Signal(name="look_hit"),     # the pixel looked up hits
            go_hit=Signal(name="look_go_hit"),    # go & look_hit
            go_miss=Signal(name="look_go_miss"),  # go & miss_ok
            in_seq=Signal(K, name="in_seq"), out_seq=Signal(K, name="out_seq"),  # the queue
            x_in=Signal(3, name="extras_in"), x_out=Signal(3, name="extras_out"),  # their FIFO
            count=Signal(range(geom.queue + 1), name="count"),    # in_seq - out_seq
            # the queue's reads, ahead of its pops: the next address read, the entries
            # written and not yet read (and whether any is), the read enable (a register),
            # the entries in the RAM's register and its output register, and in the two
            # fabric registers after them (oldest first: f0, f1, the output register, the
            # RAM's register)
            q_read=Signal(geom.queue.bit_length() - 1, name="q_read"),
            q_unread=Signal(range(geom.queue + 1), name="q_unread"),
            q_avail=Signal(name="q_avail"),                       # q_unread != 0
            q_en=Signal(init=1, name="q_en"),                     # ~(f1 & q_v2)
            q_v1=Signal(name="q_v1"), q_v2=Signal(name="q_v2"),
            q_f0=Signal(name="q_f0"), q_f1=Signal(name="q_f1"),
            q_rd=Signal(name="q_ring_rd"), q_wr=Signal(name="q_ring_wr"),   # the ring's slots
            hd_valid=Signal(name="hd_valid"),                     # the queue's head, registered
            rd_valid=Signal(name="rd_valid"),                     # the data read
            wd_valid=Signal(name="wd_valid"),                     # its words in registers
            o_skid=Signal(name="o_skid"),                         # the output's skid register
            hd_stall=Signal(name="hd_stall"),                     # hd_valid & wd_valid & o_skid
            fills=Signal(range(geom.misses + 1), name="fills"),   # bursts issued, not landed
            fills_any=Signal(name="fills_any"),                   # fills != 0: RREADY
            miss_ok=Signal(init=1, name="miss_ok"),               # ~arvalid & fills != misses
            landed=Signal(range(geom.queue + 1), name="landed"),  # lines landed, miss queued
            landed_any=Signal(name="landed_any"),                 # landed != 0
            head_ok=Signal(name="head_ok"),                       # the queue's head may leave
            pop_ok=Signal(name="pop_ok"),         # the same from this cycle's registers (comb)
            f_in=Signal(range(geom.misses), name="f_in"), f_out=Signal(range(geom.misses), name="f_out"),
            beat=Signal(range(geom.beats), name="beat"))          # the R beat of the line
        tb, hb = geom.texture_bits, geom.height_bits
        fields = {"u": unsigned(max(1, tb)), "v": unsigned(max(1, hb))}
        if geom.mip_levels > 1:
            fields["level"] = unsigned((geom.mip_levels - 1).bit_length())
        super().__init__({
            "i": In(stream.Signature(data.StructLayout({**fields, **self.extra}))),
            "o": Out(stream.Signature(data.StructLayout({"texel": unsigned(geom.texel_bits),
                                                         **self.extra}))),
            "axi": Out(axi_read_signature(geom.addr_bits, geom.data_bits))})

    @staticmethod
    def queue_layout(geom: CacheGeometry, extra=None):
        """One entry of the pixel queue: where its texel is (set, word, way, slot of the
        word) and the carried fields (whether it waits for a line fill is a LUT RAM of its
        own beside it)."""
        sel_bits = geom.slots_per_beat.bit_length() - 1
        word_bits = geom.set_bits + (2 * geom.block_bits - sel_bits if geom.beats > 1 else 0)
        return data.StructLayout({
            "word": unsigned(max(1, word_bits)), "way": unsigned(max(1, geom.way_bits)),
            "sel": unsigned(max(1, sel_bits)), **dict(extra or {})})

    def _locate(self, m, px):
        """(line, slot) of the pixel ``px`` (a Switch on its level; past the last: the last)."""
        g = self.geom
        line, slot = Signal(g.line_bits), Signal(2 * g.block_bits)
        if g.mip_levels == 1:
            ln, sl = tiled_layout(px.u, px.v, 0, g)
            m.d.comb += [line.eq(ln), slot.eq(sl)]
            return line, slot
        with m.Switch(px.level):
            for level in range(g.mip_levels):
                with (m.Case(level) if level < g.mip_levels - 1 else m.Default()):
                    ln, sl = tiled_layout(px.u, px.v, level, g)
                    m.d.comb += [line.eq(ln), slot.eq(sl)]
        return line, slot

    def elaborate(self, platform):
        g = self.geom
        m = Module()
        spb = g.slots_per_beat
        sel_bits = spb.bit_length() - 1           # slot within a data word
        K = g.stamp_bits
        ax = self.axi
        r = self.regs

        # --- memories: a tag, a stamp and a data RAM a way, each read in two stages (the
        # read, then its output register: rtl/targets.RegisteredRAM, a block RAM's output
        # register on ECP5) that move on together. No read sees a write of its own cycle:
        # the writes a read misses are forwarded by the stages below. A line is never read
        # while it fills (a miss's pixel waits for its line, and a line a queued pixel or a
        # later stage still reads is not evicted before its fill's first beat can land). ---
        def ram(name, depth, shape):
            m.submodules[name] = unit = RegisteredRAM(depth, shape, name, target=self.target)
            return unit
        tags = [ram(f"tag{w}", g.sets, g.tag_bits + 1) for w in range(g.ways)]
        stamps = [ram(f"stamp{w}", g.sets, K) for w in range(g.ways)]
        datas = [ram(f"data{w}", g.sets * g.beats, g.data_bits) for w in range(g.ways)]
        # tree pseudo-LRU bits a set (LUT RAM, read in the cycle at the pixel read's set)
        plru_width = max(1, g.ways - 1)
        m.submodules.plru = plru = Memory(shape=plru_width, depth=g.sets, init=[],
                                          attrs={"ram_style": "distributed"})
        plru_r, plru_w = plru.read_port(domain="comb"), plru.write_port()

        flushing = r.flushing
        flush_set = Signal(range(g.sets))

        def split(line, slot):
            word = Cat(slot[sel_bits:], line[:g.set_bits]) if g.beats > 1 else line[:g.set_bits]
            return line[:g.set_bits], line[g.set_bits:], word, slot[:sel_bits]

        def set_of(line):
            return line[:g.set_bits] if g.set_bits else Const(0, 1)

        def tag_of(line):                      # as stored (a line index may have fewer bits)
            t = Signal(g.tag_bits)
            m.d.comb += t.eq(line[g.set_bits:])
            return t

        # The stages from the input to the lookup: the pixel read (``in``: its set's words on
        # the read ports, held there while it waits), the words read (``rw``: the RAMs'
        # output registers), the words settled (``ws``: fabric registers, overrides merged)
        # and the pixel looked up (``look``). The pixel looked up writes its set when it
        # advances (the tag of a miss's victim, its way's stamp, the pseudo-LRU bits): each
        # stage behind it keeps, a way, the last word written to its set since its read
        # (an override), and the words move on with the write of the cycle applied.
        in_valid, rw_valid, ws_valid, look_valid = r.in_valid, r.rw_valid, r.ws_valid, r.look_valid
        in_line, in_slot = Signal(g.line_bits, name="in_line"), Signal(2 * g.block_bits, name="in_slot")
        rw_line, rw_slot = Signal(g.line_bits, name="rw_line"), Signal(2 * g.block_bits, name="rw_slot")
        look_line, look_slot = Signal(g.line_bits, name="look_line"), Signal(2 * g.block_bits, name="look_slot")
        ws_line, ws_slot = Signal(g.line_bits, name="ws_line"), Signal(2 * g.block_bits, name="ws_slot")
        # The carried fields do not move through these stages: they wait, in order, in a
        # LUT-RAM FIFO from the pixel's taking to its lookup's advance (the stages hold
        # six pixels at most), so that the stages' enables reach few registers.
        x_in, x_out = r.x_in, r.x_out
        r.extras = None
        if self.extra:
            m.submodules.extras = xmem = Memory(shape=data.StructLayout(self.extra), depth=8,
                                                init=[], attrs={"ram_style": "distributed"})
            x_w, x_r = xmem.write_port(), xmem.read_port(domain="comb")
            r.extras = xmem
        look_extra = {k: x_r.data[k] for k in self.extra}
        new_line, new_slot = self._locate(m, self.i.payload)

        # --- the pixel looked up: whether each way hits, whether a queued pixel references
        # each way (below) and its stamp's distance from in_seq (the pixels queued since, at
        # most ``queue``: all a referenced one needs), the set's pseudo-LRU bits (all
        # registers) ---
        look_hits = Signal(g.ways, name="look_hits")
        qb = g.queue.bit_length() - 1
        look_dists = [Signal(qb + 1, name=f"look_dist{w}") for w in range(g.ways)]
        look_plru = Signal(plru_width, name="look_plru")
        look_set, _, look_word, look_sel = split(look_line, look_slot)
        if g.set_bits == 0:
            look_set = Const(0, 1)
        look_tag = tag_of(look_line)
        hit = r.look_hit                          # look_hits.any(), a register
        # the victim the bits point to, one-hot, a register of its own (set with the bits,
        # below): the lock, and so the advance, one LUT shorter than decoding the bits
        victim = Signal(g.ways, init=1 << plru_victim(0, g.ways), name="look_victim")
        way_hot = Signal(g.ways)                  # the way the pixel uses, one-hot
        m.d.comb += way_hot.eq(Mux(hit, look_hits, victim))
        way = Signal(max(1, g.way_bits))
        for w in range(g.ways):
            with m.If(way_hot[w]):
                m.d.comb += way.eq(w)

        # --- the pixel queue: pixels in [out_seq, in_seq) wait in order ---
        in_seq, out_seq, count = r.in_seq, r.out_seq, r.count
        layout = self.queue_layout(g, self.extra)
        # read ahead of the pops into the RAM's register, then its output register, then
        # two fabric registers (below)
        qmem = ram("queue", g.queue, layout)
        # the entries' miss bits in LUT RAM beside it, the even entries' and the odd ones'
        # apart: read a cycle ahead of the queue's read, both entries it may read next (its
        # address's and the one after, one in each half) straight into registers, then
        # into registers of the fabric that move on with the RAM's two (no logic reads a
        # block RAM's output to decide the pop, and none comes between a LUT RAM's read and
        # its register)
        m_ports = []
        for p in range(2):
            m.submodules[f"queue_miss{p}"] = mmem = Memory(
                shape=1, depth=g.queue // 2, init=[], attrs={"ram_style": "distributed"})
            m_ports.append((mmem.write_port(), mmem.read_port(domain="comb")))

        # A victim still referenced by a queued pixel (its last pixel not yet left): a way's
        # stamp in [out_seq, in_seq). A register a way: the test as a pixel moves into the
        # lookup, with the queue as it is after that cycle; while it waits (in_seq holds), the
        # same less the pixel that leaves in the cycle (its distance 0: a pop takes one from
        # both the distance and the count, so a distance below the count stays below it).
        referenced = Signal(g.ways, name="look_referenced")
        pop = Signal()
        locked = Signal()
        m.d.comb += locked.eq((referenced & victim).any())

        # --- the bursts outstanding: (set, way) of each, in AR order ---
        fills, landed = r.fills, r.landed
        m.submodules.fillq = fmem = Memory(
            shape=data.StructLayout({"set": unsigned(max(1, g.set_bits)),
                                     "way": unsigned(max(1, g.way_bits))}),
            depth=g.misses, init=[], attrs={"ram_style": "distributed"})
        f_w, f_r = fmem.write_port(), fmem.read_port(domain="comb")
        f_in, f_out = r.f_in, r.f_out

        # (not ARREADY: no port in the lookup's cycle)
        miss_ok = r.miss_ok                        # ~ARVALID & fills != misses, a register
        advance = Signal()
        go = r.go                                  # ~flushing & look_valid & count != queue
        # go & (hit | miss_ok & ~locked), with go & hit and go & miss_ok registers of their
        # own (go_hit, go_miss): the advance, the lookup's latest signal, one LUT and a
        # PFUMX from its registers, the lock's among them
        go_hit, go_miss = r.go_hit, r.go_miss
        m.d.comb += advance.eq(go_hit | (go_miss & ~locked))
        miss = advance & ~hit
        # each stage from the lookup back moves on when it or one after it is empty, or the
        # lookup advances (the valid bits combined apart from the advance)
        full1, full2, full3 = (Signal(name=f"lookup_full{n}", attrs={"keep": 1}) for n in (1, 2, 3))
        m.d.comb += [full1.eq(look_valid), full2.eq(look_valid & r.ds_valid),
                     full3.eq(look_valid & r.ds_valid & ws_valid)]
        move = ~full1 | advance                    # the distances move on to the lookup
        ds_move = ~full2 | advance                 # the words settled move on to the distances
        ws_move = ~full3 | advance                 # the words read move on to the settled
        sk_valid = r.sk_valid
        rw_move = Signal()                         # the pixel read moves on to the words read
        # (registers alone: it enables the block RAMs' reads; the words read go to the skid
        # register when the settled ones wait, and wait there while it is full)
        m.d.comb += rw_move.eq(~sk_valid | ~rw_valid)
        m.d.comb += self.i.ready.eq(~flushing & rw_move)

        # the write of the cycle (the pixel looked up advancing), a way at a time
        tag_written = Cat(look_tag, Const(1, 1))
        touched = self._plru_hdl(look_plru, way_hot)[1]
        # The advance is the lookup's latest signal: each register the write of the cycle
        # reaches takes a choice by the advance between its next value with the advance
        # (a = 1) and without it (a = 0), each from registers alone, so that the advance
        # comes last before the flip-flops.
        def tag_hot_if(a):                 # tag_hot when the advance is a
            return Mux(hit, 0, victim) if a else Const(0, g.ways)

        def stamp_hot_if(a):               # stamp_hot when the advance is a
            return way_hot if a else Const(0, g.ways)

        def late(reg, f):
            m.d.sync += reg.eq(Mux(advance, f(1), f(0)))

        def up_down(reg, up, down):
            """``reg`` + ``up`` - ``down`` (1-bit each): the sums from the register alone,
            the late signals only choosing and enabling."""
            with m.If(up & ~down):
                m.d.sync += reg.eq(reg + 1)
            with m.Elif(down & ~up):
                m.d.sync += reg.eq(reg - 1)
        # The writes of the two cycles before, registered: the tag and stamp RAMs take the
        # one of the cycle before (a write lands the cycle after the lookup's), and a read
        # taken in either cycle misses it.
        def written_in(name):
            return SimpleNamespace(set=Signal.like(look_set, name=f"{name}_set"),
                                   tag=Signal.like(tag_written, name=f"{name}_tag"),
                                   tag_hot=Signal(g.ways, name=f"{name}_tag_hot"),
                                   seq=Signal(K, name=f"{name}_seq"),
                                   stamp_hot=Signal(g.ways, name=f"{name}_stamp_hot"))
        was, was2 = written_in("was"), written_in("was2")
        # (the ways written, one-hot, from registers of their parts: the miss and the victim,
        # the advance and the way used, so that the lookup's signals reach flip-flops' data
        # inputs, no synchronous reset of the ways)
        was_miss, was_adv = Signal(name="was_miss"), Signal(name="was_advance")
        was_victim, was_way = Signal(g.ways, name="was_victim"), Signal(g.ways, name="was_way")
        m.d.sync += [was.set.eq(look_set), was.tag.eq(tag_written), was.seq.eq(in_seq),
                     was_miss.eq(miss), was_victim.eq(victim), was_adv.eq(advance),
                     was_way.eq(way_hot)]
        m.d.comb += [was.tag_hot.eq(Mux(was_miss, was_victim, 0)),
                     was.stamp_hot.eq(Mux(was_adv, was_way, 0))]
        m.d.sync += [getattr(was2, k).eq(getattr(was, k))
                     for k in ("set", "tag", "tag_hot", "seq", "stamp_hot")]

        def overrides(prefix):
            """A stage's override registers: a way's tag and stamp written since its read."""
            return SimpleNamespace(
                tag_hot=Signal(g.ways, name=f"{prefix}_tag_ov"),
                tags=[Signal.like(tag_written, name=f"{prefix}_tag_ov{w}") for w in range(g.ways)],
                stamp_hot=Signal(g.ways, name=f"{prefix}_stamp_ov"),
                stamps=[Signal(K, name=f"{prefix}_stamp_ov{w}") for w in range(g.ways)])

        def assign(dst, src):
            return [dst.tag_hot.eq(src.tag_hot), dst.stamp_hot.eq(src.stamp_hot)] + \
                [d.eq(s) for d, s in zip(dst.tags + dst.stamps, src.tags + src.stamps, strict=True)]

        def fields(ov):
            return [ov.tag_hot, ov.stamp_hot] + ov.tags + ov.stamps

        def by_advance(ovs, name):
            """The overrides ``ovs[1]`` if the advance, else ``ovs[0]``."""
            out = overrides(name)
            m.d.comb += [d.eq(Mux(advance, s1, s0))
                         for d, s0, s1 in zip(fields(out), fields(ovs[0]), fields(ovs[1]), strict=True)]
            return out

        def apply(ov, same, tag_hot, tag, stamp_hot, seq, name):
            """``ov`` with a write of ``tag`` to the ways ``tag_hot`` and of ``seq`` to the
            ways ``stamp_hot`` of the stage's set (``same``) on top."""
            out = overrides(name)
            th = Signal(g.ways, name=f"{name}_tag_hit")
            sh = Signal(g.ways, name=f"{name}_stamp_hit")
            m.d.comb += [th.eq(Mux(same, tag_hot, 0)), sh.eq(Mux(same, stamp_hot, 0)),
                         out.tag_hot.eq(ov.tag_hot | th), out.stamp_hot.eq(ov.stamp_hot | sh)]
            for w in range(g.ways):
                m.d.comb += [out.tags[w].eq(Mux(th[w], tag, ov.tags[w])),
                             out.stamps[w].eq(Mux(sh[w], seq, ov.stamps[w]))]
            return out

        # --- the pixel read: its set's tags and stamps are read as it is taken (the reads
        # address the input and hold while it waits); the writes of that cycle and the one
        # before are added the cycle after, their sets compared with the pixel's as it is
        # taken (registers) ---
        moved = Signal(name="in_moved")          # the pixel read moved on last cycle
        m.d.sync += moved.eq(rw_move)
        fresh = in_valid & moved                 # taken last cycle
        in_set = set_of(in_line)
        for rp in tags + stamps:
            m.d.comb += [rp.r_addr.eq(set_of(new_line)), rp.en.eq(rw_move)]
        in_held = overrides("in_held")
        none = overrides("in_none")
        m.d.comb += assign(none, SimpleNamespace(tag_hot=0, stamp_hot=0, tags=in_held.tags,
                                                 stamps=in_held.stamps))
        same_was = Signal(name="in_same_was")      # was.set == in_set when fresh
        same_was2 = Signal(name="in_same_was2")    # was2.set == in_set when fresh
        in_old = apply(none, same_was2, was2.tag_hot, was2.tag, was2.stamp_hot, was2.seq,
                       "in_old")
        in_new = apply(in_old, same_was, was.tag_hot, was.tag, was.stamp_hot, was.seq,
                       "in_new")
        in_ov = overrides("in_ov")
        with m.If(fresh):
            m.d.comb += assign(in_ov, in_new)
        with m.Else():
            m.d.comb += assign(in_ov, in_held)
        in_same_set = Signal(name="in_same_set")   # in_set == look_set (a register, below)
        in_moved_if = [apply(in_ov, in_same_set & a, tag_hot_if(a), tag_written, stamp_hot_if(a),
                             in_seq, f"in_moved{a}") for a in (0, 1)]
        in_moved = by_advance(in_moved_if, "in_moved")
        m.d.sync += assign(in_held, in_moved)     # with the write of each cycle it waits
        with m.If(rw_move):                      # (the input's terms apart from it)
            m.d.sync += [in_valid.eq(self.i.valid & ~flushing), in_line.eq(new_line),
                         in_slot.eq(new_slot), same_was.eq(set_of(new_line) == look_set),
                         same_was2.eq(set_of(new_line) == was.set)]
        px_taken = rw_move & self.i.valid & ~flushing
        if self.extra:
            m.d.comb += [x_w.addr.eq(x_in), x_w.en.eq(px_taken), x_r.addr.eq(x_out)]
            m.d.comb += [x_w.data[k].eq(self.i.payload[k]) for k in self.extra]
        with m.If(px_taken):
            m.d.sync += x_in.eq(x_in + 1)

        # --- the words read: the RAMs' output registers, the overrides with the write of
        # the cycle the pixel moves in, and of each cycle it waits ---
        rw_set = set_of(rw_line)
        rw_raw_tags = [rp.r_data for rp in tags]
        rw_raw_stamps = [rp.r_data for rp in stamps]
        rw_ov = overrides("rw_ov")
        rw_plru = Signal(plru_width, name="rw_plru")
        m.d.comb += plru_r.addr.eq(in_set)
        # the pseudo-LRU bits are written the cycle after the lookup's (from registers: the
        # advance does not reach the LUT RAM's write enables), that write forwarded here
        pl_addr, pl_data = Signal.like(plru_w.addr, name="plru_w_addr"), Signal(plru_width, name="plru_w_data")
        pl_en = Signal(name="plru_w_en")
        plru_now = Signal(plru_width, name="plru_now")
        m.d.comb += plru_now.eq(Mux(pl_en & (in_set == pl_addr), pl_data, plru_r.data))
        rw_same_set = Signal(name="rw_same_set")   # rw_set == look_set (a register, below)
        rw_moved_if = [apply(rw_ov, rw_same_set & a, tag_hot_if(a), tag_written, stamp_hot_if(a),
                             in_seq, f"rw_moved{a}") for a in (0, 1)]
        with m.If(rw_move):
            m.d.sync += [rw_valid.eq(in_valid), rw_line.eq(in_line), rw_slot.eq(in_slot)]
        late(rw_plru, lambda a: Mux(rw_move, Mux(in_same_set & a, touched, plru_now),
                                    Mux(rw_same_set & a, touched, rw_plru)))
        for d, *src in zip(fields(rw_ov), *(fields(o) for o in in_moved_if + rw_moved_if),
                           strict=True):
            late(d, lambda a, src=src: Mux(rw_move, src[a], src[2 + a]))
        # each way's tag and stamp (its override, else the word read) and the pseudo-LRU
        # bits with the write of the cycle, with the advance a: a word read as (whether it
        # is the word read, its override), so that each register it reaches chooses it
        # right before the advance (a LUT and the advance's mux from a block RAM's output
        # register to a flip-flop)
        rw_tags_if = [[(~o.tag_hot[w], o.tags[w]) for w in range(g.ways)] for o in rw_moved_if]
        rw_stamps_if = [[(~o.stamp_hot[w], o.stamps[w]) for w in range(g.ways)]
                        for o in rw_moved_if]
        rw_plru_if = [Mux(rw_same_set & a, touched, rw_plru) for a in (0, 1)]

        def raw_last(reg, raw, f):
            """``reg``'s next with the advance chosen: f(a) = (whether it is the word read
            ``raw``, else its value) with the advance a."""
            late(reg, lambda a: Mux(f(a)[0], raw, f(a)[1]))

        # --- the skid register: the words read that moved on while the settled ones waited
        # (no write while it is full and they wait: the lookup does not advance) ---
        sk_line, sk_slot = Signal(g.line_bits, name="sk_line"), Signal(2 * g.block_bits, name="sk_slot")
        sk_tags = [Signal.like(tag_written, name=f"sk_tag{w}") for w in range(g.ways)]
        sk_stamps = [Signal(K, name=f"sk_stamp{w}") for w in range(g.ways)]
        sk_plru = Signal(plru_width, name="sk_plru")
        sk_same_set = Signal(name="sk_same_set")   # sk_set == look_set (a register, below)
        # (its words taken whenever it is empty: only its valid bit waits on the advance)
        m.d.sync += sk_valid.eq(~ws_move & (sk_valid | rw_valid))
        with m.If(~sk_valid):
            m.d.sync += [sk_line.eq(rw_line), sk_slot.eq(rw_slot),
                         sk_plru.eq(Mux(advance, rw_plru_if[1], rw_plru_if[0]))]
            for w in range(g.ways):
                raw_last(sk_tags[w], rw_raw_tags[w], lambda a, w=w: rw_tags_if[a][w])
                raw_last(sk_stamps[w], rw_raw_stamps[w], lambda a, w=w: rw_stamps_if[a][w])

        # --- the words settled: from the skid register when it is full, else the words
        # read, with the write of the cycle the pixel moves in, in registers: no block-RAM
        # output drives the lookup's compares ---
        ws_set = set_of(ws_line)
        ws_tags = [Signal.like(tag_written, name=f"ws_tag{w}") for w in range(g.ways)]
        ws_stamps = [Signal(K, name=f"ws_stamp{w}") for w in range(g.ways)]
        ws_plru = Signal(plru_width, name="ws_plru")
        with m.If(ws_move):
            m.d.sync += [ws_valid.eq(sk_valid | rw_valid), ws_line.eq(Mux(sk_valid, sk_line, rw_line)),
                         ws_slot.eq(Mux(sk_valid, sk_slot, rw_slot))]

        def ws_next(a, held, from_sk, from_rw):    # the words settled's next, advance a
            return Mux(~full3 | a, Mux(sk_valid, from_sk, from_rw), held)

        def ws_next_raw(a, held, from_sk, from_rw):   # the same, from_rw a word read's pair
            return ((~full3 | a) & ~sk_valid & from_rw[0],
                    Mux(~full3 | a, Mux(sk_valid, from_sk, from_rw[1]), held))
        late(ws_plru, lambda a: ws_next(a, ws_plru, Mux(sk_same_set & a, touched, sk_plru),
                                        rw_plru_if[a]))
        for w in range(g.ways):
            raw_last(ws_tags[w], rw_raw_tags[w], lambda a, w=w: ws_next_raw(
                a, ws_tags[w], Mux(sk_same_set & tag_hot_if(a)[w], tag_written, sk_tags[w]),
                rw_tags_if[a][w]))
            raw_last(ws_stamps[w], rw_raw_stamps[w], lambda a, w=w: ws_next_raw(
                a, ws_stamps[w], Mux(sk_same_set & stamp_hot_if(a)[w], in_seq, sk_stamps[w]),
                rw_stamps_if[a][w]))

        # --- the stamps' distances: each way's stamp s as e = in_seq - 1 - s (mod 2**K),
        # the pixels queued since its own; it is queued iff e < count. A pixel waits in this
        # stage and the ones before it only while the lookup does not advance, so in_seq
        # holds and e with it: e is taken here, with this cycle's advance and write, as its
        # low log2(queue) bits and whether it is at least ``queue`` (no queued pixel that
        # far), with whether it is 2**K - 1 (an advance makes it 0: a stale stamp equal to
        # in_seq then looks queued, as in the model). in_seq's own copies here (in_seq - 1,
        # in_seq, in_seq + 1, and the bits above the queue's of in_seq - 1 - queue and of
        # in_seq - queue), so that its other loads do not pull it away ---
        ws_same_set = Signal(name="ws_same_set")   # ws_set == look_set (a register, below)
        in_less = Signal(K, init=(1 << K) - 1, name="in_seq_less")   # in_seq - 1
        in_cur = Signal(K, name="in_seq_cur")                         # in_seq
        in_one = Signal(K, init=1, name="in_seq_one")                # in_seq + 1
        hb = K - qb
        in_less_hi = Signal(hb, init=(1 << hb) - 2, name="in_seq_less_hi")  # (in_seq-1-queue)[qb:]
        in_cur_hi = Signal(hb, init=(1 << hb) - 1, name="in_seq_cur_hi")    # (in_seq-queue)[qb:]
        with m.If(advance):
            m.d.sync += [in_less.eq(in_less + 1), in_cur.eq(in_cur + 1), in_one.eq(in_one + 1),
                         in_less_hi.eq(in_less_hi + in_less[:qb].all()),
                         in_cur_hi.eq(in_cur_hi + in_cur[:qb].all())]

        def distance(b, b_hi_less, s):
            """e = b - s (mod 2**K) as (e mod queue, e >= queue): the low bits' difference,
            whose borrow chooses the test of the high bits, an equality (e < queue iff s's
            high bits are b's, or after a borrow b's less one): no K-bit carry chain."""
            diff = b[:qb] - s[:qb]                 # (signed: its top bit the borrow)
            near = Mux(diff[qb], s[qb:] == b_hi_less, s[qb:] == b[qb:])
            return diff[:qb], ~near
        ds_valid = r.ds_valid
        ds_line, ds_slot = Signal(g.line_bits, name="ds_line"), Signal(2 * g.block_bits, name="ds_slot")
        ds_tags = [Signal.like(tag_written, name=f"ds_tag{w}") for w in range(g.ways)]
        ds_dists = [Signal(qb, name=f"ds_dist{w}") for w in range(g.ways)]   # e mod queue
        ds_fars = [Signal(name=f"ds_far{w}") for w in range(g.ways)]          # e >= queue
        ds_tops = [Signal(name=f"ds_top{w}") for w in range(g.ways)]
        ds_plru = Signal(plru_width, name="ds_plru")
        with m.If(ds_move):
            m.d.sync += [ds_valid.eq(ws_valid), ds_line.eq(ws_line), ds_slot.eq(ws_slot)]

        def ds_next(a, held, moved):                # the distances' next, advance a
            return Mux(~full2 | a, moved, held)
        late(ds_plru, lambda a: ds_next(a, ds_plru, Mux(ws_same_set & a, touched, ws_plru)))
        for w in range(g.ways):
            s_w = ws_stamps[w]
            # e without an advance (in_seq - 1 - s), after one (in_seq - s)
            e_if = [distance(in_less, in_less_hi, s_w), distance(in_cur, in_cur_hi, s_w)]
            top_if = [s_w == in_cur, s_w == in_one]
            for a in (0, 1):
                stamped = ws_same_set & stamp_hot_if(a)[w]   # s = in_seq now: e = 0 after the advance
                e_if[a] = (Mux(stamped, 0, e_if[a][0]), ~stamped & e_if[a][1],
                           ~stamped & top_if[a])
            late(ds_tags[w], lambda a, w=w: ds_next(
                a, ds_tags[w], Mux(ws_same_set & tag_hot_if(a)[w], tag_written, ws_tags[w])))
            late(ds_dists[w], lambda a, w=w, e_if=e_if: ds_next(a, ds_dists[w], e_if[a][0]))
            late(ds_fars[w], lambda a, w=w, e_if=e_if: ds_next(a, ds_fars[w], e_if[a][1]))
            late(ds_tops[w], lambda a, w=w, e_if=e_if: ds_next(a, ds_tops[w], e_if[a][2]))

        # --- into the lookup: each way's hit computed here (the write of the cycle to the
        # pixel's set: a miss's tag to its victim), and whether a queued pixel references it
        # after this cycle: e + advance < count + advance - pop (an e of 2**K - 1 wraps to 0
        # on an advance: referenced) ---
        ds_set = set_of(ds_line)
        ds_tag = tag_of(ds_line)
        new_hits_if = [Signal(g.ways, name=f"new_hits{a}") for a in (0, 1)]

        count_less = Signal(len(count), init=(1 << len(count)) - 1, name="count_less")
        up_down(count_less, advance, pop)                         # count - 1

        def below_count(e, p):                     # e < count - p (no sum before a compare)
            # (count - 1 on the queue's bits: its top bit is set only at count = 0, where
            # e < count is not)
            return (e < count) & ~(p & (e == count_less[:qb]))

        # Each register as a choice by the advance (the latest signal here) between its
        # next value with and without it, both from registers and the pop (referenced: each
        # of those a choice by the pop between its value with and without it, from
        # registers alone).
        same_set = Signal(name="ds_same_set")    # ds_set == look_set (a register, below)
        for w in range(g.ways):
            t, e, far, top = ds_tags[w], ds_dists[w], ds_fars[w], ds_tops[w]
            hit_w = t[-1] & (t[:g.tag_bits] == ds_tag)
            for a in (0, 1):
                written = same_set & tag_hot_if(a)[w]
                m.d.comb += new_hits_if[a][w].eq(Mux(written, ds_tag == look_tag, hit_w))
            stamped = same_set & way_hot[w]
            d = look_dists[w]                   # e after this cycle, at most queue

            def ref_if(a, p, w=w, t=t, e=e, far=far, top=top, stamped=stamped, d=d):
                """referenced[w]'s next with the advance a and the pop p."""
                queued = ~far & below_count(e, p)          # e < count - p
                if a:
                    # the lookup's pixel queued, on this way if it uses it (a miss writes
                    # its victim's tag: that way is stamped too), and e + 1 (wrapping at
                    # 2**K - 1 to 0: referenced)
                    return (same_set & ~hit & victim[w]) | (t[-1] & (stamped | queued | top))
                # the lookup's pixel waits (no write), or the distances move in (a way
                # referenced has d < count, so d and count - 1 below ``queue``, compared on
                # the queue's bits: only the pop of its last pixel ends it)
                return Mux(look_valid, referenced[w] & ~(p & (d[:qb] == count_less[:qb])),
                           t[-1] & queued)
            d_on = Mux(stamped | top, 0, Mux(far, g.queue, e + 1))
            d_off = Mux(look_valid, d, Mux(far, g.queue, e))
            m.d.sync += [referenced[w].eq(Mux(advance, Mux(pop, ref_if(1, 1), ref_if(1, 0)),
                                              Mux(pop, ref_if(0, 1), ref_if(0, 0)))),
                         d.eq(Mux(advance, d_on, d_off))]
        # Each stage's set against the lookup's, in registers: compared a cycle ahead, the
        # sets each will hold, the moves (the advance last) choosing
        sk_set = set_of(sk_line)

        def look_set_if(a):
            return Mux(~full1 | a, ds_set, look_set)
        # (the pixel read's move chooses between the compares, not the sets compared)
        late(in_same_set, lambda a: Mux(rw_move, set_of(new_line) == look_set_if(a),
                                        in_set == look_set_if(a)))
        late(rw_same_set, lambda a: Mux(rw_move, in_set == look_set_if(a), rw_set == look_set_if(a)))
        late(sk_same_set, lambda a: Mux(sk_valid, sk_set, rw_set) == look_set_if(a))

        def ws_set_if(a):
            return Mux(~full3 | a, Mux(sk_valid, sk_set, rw_set), ws_set)
        late(ws_same_set, lambda a: ws_set_if(a) == look_set_if(a))
        late(same_set, lambda a: Mux(~full2 | a, ws_set, ds_set) == look_set_if(a))
        with m.If(move):
            m.d.sync += [look_valid.eq(ds_valid), look_line.eq(ds_line), look_slot.eq(ds_slot)]

        def look_next(a, held, moved):              # the lookup's next, advance a
            return Mux(~full1 | a, moved, held)
        def plru_next(a):
            return look_next(a, look_plru, Mux(same_set & a, touched, ds_plru))
        late(look_plru, plru_next)
        late(victim, lambda a: self._plru_hdl(plru_next(a), look_hits)[0])
        late(look_hits, lambda a: look_next(a, look_hits, new_hits_if[a]))
        hit_next = Signal(name="look_hit_next")
        m.d.comb += hit_next.eq(Mux(advance, look_next(1, hit, new_hits_if[1].any()),
                                    look_next(0, hit, new_hits_if[0].any())))
        m.d.sync += hit.eq(hit_next)

        # the pixel advances: queued, its way's stamp and pseudo-LRU bits written
        q_w = qmem.w_data
        m.d.comb += [qmem.w_addr.eq(in_seq[:qb]), qmem.w_en.eq(advance),
                     q_w.word.eq(look_word), q_w.way.eq(way), q_w.sel.eq(look_sel)]
        m.d.comb += [q_w[k].eq(look_extra[k]) for k in self.extra]
        # the miss bits are written the cycle after (from registers), each into its entry's
        # half; that write and the one of the cycle before are forwarded to the reads that
        # miss them (below)
        mq_addr, mq_data, mq_en = Signal(qb, name="miss_w_addr"), Signal(name="miss_w_data"), \
            Signal(name="miss_w_en")
        mq_data2 = Signal(name="miss_w_data2")           # mq_data of the cycle before
        m.d.sync += [mq_addr.eq(in_seq[:qb]), mq_data.eq(~hit), mq_en.eq(advance),
                     mq_data2.eq(mq_data)]
        for p, (m_w, _) in enumerate(m_ports):
            m.d.comb += [m_w.addr.eq(mq_addr[1:]), m_w.en.eq(mq_en & (mq_addr[0] == p)),
                         m_w.data.eq(mq_data)]
        for w, sp in enumerate(stamps):                 # (the cycle after: ``was``)
            m.d.comb += [sp.w_addr.eq(was.set), sp.w_data.eq(was.seq),
                         sp.w_en.eq(was.stamp_hot[w])]
        with m.If(advance):
            m.d.sync += [in_seq.eq(in_seq + 1), x_out.eq(x_out + 1)]
        # count + advance - pop == queue without the sum: full and no pop, or one short and
        # an advance without a pop (no advance when full)
        full_next = ~pop & (count[-1] | (advance & (count == g.queue - 1)))
        up_down(count, advance, pop)
        m.d.sync += [pl_addr.eq(look_set), pl_data.eq(touched),
                     pl_en.eq(advance if g.ways > 1 else 0)]
        with m.If(flushing):                     # the flush clears the bits with the tags
            m.d.sync += [pl_addr.eq(flush_set), pl_data.eq(0), pl_en.eq(1)]
        m.d.comb += [plru_w.addr.eq(pl_addr), plru_w.data.eq(pl_data), plru_w.en.eq(pl_en)]

        # after a reset, every set's tags are cleared (one set a cycle) before the first lookup
        m.d.sync += flush_set.eq(flush_set + 1)
        flushing_next = flushing & (flush_set != g.sets - 1)
        go_next = Signal(name="look_go_next")
        m.d.comb += go_next.eq(~flushing_next & Mux(move, r.ds_valid, look_valid) & ~full_next)
        m.d.sync += [flushing.eq(flushing_next),
                     go.eq(go_next)]
        for w, tp in enumerate(tags):
            m.d.comb += [tp.w_addr.eq(Mux(flushing, flush_set, was.set)),
                         tp.w_data.eq(Mux(flushing, 0, was.tag)),
                         tp.w_en.eq(flushing | was.tag_hot[w])]

        # --- a miss: the victim's new tag (above), its burst and its fill entry ---
        line_shift = g.line_bytes.bit_length() - 1
        m.d.comb += [ax.arlen.eq(g.beats - 1), ax.arsize.eq((g.data_bits // 8).bit_length() - 1),
                     ax.arburst.eq(ARBURST_INCR)]
        with m.If(miss):
            m.d.sync += [ax.arvalid.eq(1),
                         ax.araddr.eq(g.base + Cat(Const(0, line_shift), look_line))]
        with m.Elif(ax.arready):
            m.d.sync += ax.arvalid.eq(0)
        # (written the cycle after, from registers: its burst's first beat comes two cycles
        # after the miss at the earliest, the AR handshake then RVALID)
        fq_addr, fq_en = Signal.like(f_in, name="fill_q_addr"), Signal(name="fill_q_en")
        fq_set, fq_way = Signal.like(f_w.data.set, name="fill_q_set"), Signal.like(way, name="fill_q_way")
        m.d.sync += [fq_addr.eq(f_in), fq_en.eq(miss), fq_set.eq(look_set), fq_way.eq(way)]
        m.d.comb += [f_w.addr.eq(fq_addr), f_w.en.eq(fq_en), f_w.data.set.eq(fq_set),
                     f_w.data.way.eq(fq_way), f_r.addr.eq(f_out)]

        # --- the R beats: into the oldest outstanding burst's line ---
        beat = r.beat
        # RREADY while a burst is outstanding: a register (fills_any), no logic before the
        # beats' and lines' counts
        m.d.comb += ax.rready.eq(r.fills_any)
        beat_in = ax.rready & ax.rvalid
        line_in = beat_in & ax.rlast
        fill_set = f_r.data.set[:g.set_bits] if g.set_bits else Const(0, 1)
        fill_hot = Signal(g.ways)                  # one-hot by a shift: lint-clean Verilog
        m.d.comb += fill_hot.eq(Const(1, g.ways) << f_r.data.way[:max(1, g.way_bits)])
        # A beat is written the cycle after it is taken, from registers (the fill queue's
        # LUT-RAM read stays off the block RAMs' write pins): a miss's pixel reads its word
        # two cycles after its line's last beat at the earliest (the pop, then the head
        # register), once that beat is written.
        fill_addr = Cat(beat, fill_set) if g.beats > 1 else fill_set
        w_addr = Signal(len(fill_addr), name="fill_w_addr")
        w_data = Signal(g.data_bits, name="fill_w_data")
        w_hot = Signal(g.ways, name="fill_w_hot")
        m.d.sync += [w_addr.eq(fill_addr), w_data.eq(ax.rdata),
                     w_hot.eq(Mux(beat_in, fill_hot, 0))]
        for w, dp in enumerate(datas):
            m.d.comb += [dp.w_addr.eq(w_addr), dp.w_data.eq(w_data), dp.w_en.eq(w_hot[w])]
        with m.If(beat_in):
            m.d.sync += beat.eq(beat + 1)
        with m.If(line_in):
            m.d.sync += f_out.eq(f_out + 1)
        with m.If(miss):
            m.d.sync += f_in.eq(f_in + 1)
        up_down(fills, miss, line_in)
        m.d.sync += r.fills_any.eq(miss | (fills > 1) | ((fills == 1) & ~line_in))
        # a miss may go next cycle: ARVALID low then and fewer than ``misses`` bursts
        # outstanding (fills == misses: its top bit, fills in [0, a power of two])
        miss_ok_next = ~miss & ~(ax.arvalid & ~ax.arready) & ~(fills[-1] & ~line_in)
        m.d.sync += [miss_ok.eq(miss_ok_next), go_hit.eq(go_next & hit_next),
                     go_miss.eq(go_next & miss_ok_next)]

        # --- the queue's head leaves in order. The queue RAM is read ahead of the pops, in
        # order, at an address and with an enable that are registers (no pop reaches its
        # pins): into its register, then its output register, then two fabric registers
        # (f0, f1), oldest first. The head is f0 when full, else the output register; it
        # leaves (the pop) into the head register (the data read's address from a
        # flip-flop), its word read into the data RAMs' registers, then their output
        # registers (both stages of a RAM move on together), then the output register
        # (through a skid register when it waits) ---
        o_free = ~self.o.valid | self.o.ready
        hd_valid = r.hd_valid
        hd = Signal(layout, name="hd")
        rd_valid, rd_way, rd_sel = r.rd_valid, Signal(max(1, g.way_bits)), Signal(max(1, sel_bits))
        wd_valid, wd_way, wd_sel = r.wd_valid, Signal(max(1, g.way_bits)), Signal(max(1, sel_bits))
        rd_extra = {k: Signal(s, name=f"rd_{k}") for k, s in self.extra.items()}
        wd_extra = {k: Signal(s, name=f"wd_{k}") for k, s in self.extra.items()}
        wd_words = [dp.r_data for dp in datas]
        r.queue = qmem
        r.rd_extra, r.wd_extra = rd_extra, wd_extra
        r.hd_extra = {k: hd[k] for k in self.extra}
        # the data read and its words move on unless the output's skid register is full
        # behind a full words-read register (registers alone: it enables the data RAMs'
        # reads and, through the head register, the pop); the words that move on while
        # the output register waits go to the skid register
        o_skid = r.o_skid
        wd_move = ~wd_valid | ~o_skid
        # the head register moves on unless it waits behind them: hd_stall, a register (the
        # pop, the head register's enable: one register each, no logic before them)
        hd_stall = r.hd_stall
        hd_move = ~hd_stall
        # The reads: an entry is read once written (a read does not see a write of its own
        # cycle: q_unread counts the writes of the cycles before), whenever the enable is
        # high; the enable is low only while both fabric registers and the output register
        # are full (it is known a cycle ahead: the output register's entry, when the head
        # does not leave, has a fabric register to go to). The fabric registers are a ring
        # of two, written at q_wr whenever the output register's entry moves on (then at
        # most one is full: a free one), from registers alone; the pop moves only the
        # ring's pointers and valid bits.
        landed_any = r.landed_any
        q_read, q_unread, q_avail, q_en = r.q_read, r.q_unread, r.q_avail, r.q_en
        q_v1, q_v2, q_f0, q_f1 = r.q_v1, r.q_v2, r.q_f0, r.q_f1
        fab = r.q_fab = [Signal(layout, name=f"q_fab{n}") for n in range(2)]
        fab_miss = [Signal(name=f"q_fab_miss{n}") for n in range(2)]
        q_rd, q_wr = r.q_rd, r.q_wr
        q_m1, q_m2 = Signal(name="q_miss1"), Signal(name="q_miss2")       # beside v1, v2
        q_out = qmem.r_data
        issue = Signal(name="q_issue")           # a read of an entry this cycle
        # The miss bits' read, a cycle ahead: from q_read's own copy (its parity and each
        # half's address, (q_read + 1) / 2 and q_read / 2), the halves read the entries
        # q_read and q_read + 1, one each, into a register each (m_got), every cycle: the
        # next cycle's q_read is one of the two, its parity (a register then) chooses. The
        # read misses the writes of its cycle and of the next, forwarded: whether the entry
        # then read was written in the cycle before (m_fwd: the write landing then) or two
        # before (m_fwd2: the one landing as the halves were read), from registers.
        m_par = Signal(name="q_read_miss_parity")              # q_read[0]
        m_addr = [Signal(qb - 1, name=f"q_read_miss{p}") for p in range(2)]
        m_got = [Signal(name=f"q_miss_got{p}") for p in range(2)]
        m_fwd = Signal(name="q_miss_fwd")         # the entry read written the cycle before
        m_fwd2 = Signal(name="q_miss_fwd2")       # ... two cycles before
        m.d.comb += [issue.eq(q_en & q_avail), qmem.r_addr.eq(q_read), qmem.en.eq(q_en)]
        for p, (_, m_r) in enumerate(m_ports):
            m.d.comb += m_r.addr.eq(m_addr[p])
            m.d.sync += m_got[p].eq(m_r.data)
        with m.If(issue):
            m.d.sync += [m_par.eq(~m_par), m_addr[0].eq(m_addr[0] + ~m_par),
                         m_addr[1].eq(m_addr[1] + m_par)]
        head = Signal(layout, name="q_head")
        head_miss = Signal(name="head_miss")
        m.d.comb += [head.eq(Mux(q_f0, Mux(q_rd, fab[1], fab[0]), q_out)),
                     head_miss.eq(Mux(q_f0, Mux(q_rd, fab_miss[1], fab_miss[0]), q_m2))]
        # the head may leave: it is read and its line has landed if it missed (a register:
        # head_ok, computed a cycle ahead; pop_ok, the same from this cycle's registers, for
        # the formal contract's lemma)
        pop_ok = r.pop_ok
        head_ok = r.head_ok
        m.d.comb += [pop_ok.eq((q_f0 | q_v2) & (~head_miss | landed_any)),
                     pop.eq(head_ok & hd_move)]
        up_down(q_unread, advance, issue)
        m.d.sync += [q_read.eq(q_read + issue),
                     q_avail.eq(advance | (q_unread > 1) | ((q_unread == 1) & ~issue)),
                     m_fwd.eq(advance & (~q_avail | ((q_unread == 1) & issue))),
                     m_fwd2.eq(mq_en & Mux(issue, q_unread == 2, q_unread == 1))]
        with m.If(q_en):
            m.d.sync += [q_v1.eq(q_avail), q_m2.eq(q_m1),
                         q_m1.eq(Mux(m_fwd, mq_data, Mux(m_fwd2, mq_data2,
                                                         Mux(m_par, m_got[1], m_got[0]))))]
        # the output register's entry goes on into the ring unless it leaves as the head
        moving = q_en & q_v2
        into = Signal(name="q_into")
        m.d.comb += into.eq(moving & ~(pop & ~q_f0))
        taken = pop & q_f0                         # the ring's oldest leaves
        f0_next, f1_next = Signal(name="q_f0_next"), Signal(name="q_f1_next")
        v2_next = Signal(name="q_v2_next")
        m.d.comb += [f0_next.eq(Mux(taken, q_f1 | into, q_f0 | into)),
                     f1_next.eq(Mux(taken, q_f1 & into, q_f1 | (q_f0 & into))),
                     v2_next.eq(Mux(q_en, q_v1, q_v2 & ~(pop & ~q_f0)))]
        m.d.sync += [q_f0.eq(f0_next), q_f1.eq(f1_next), q_v2.eq(v2_next),
                     q_en.eq(~(f1_next & v2_next)), q_rd.eq(q_rd ^ taken), q_wr.eq(q_wr ^ into)]
        for n in range(2):
            with m.If(moving & (q_wr == n)):
                m.d.sync += [fab[n].eq(q_out), fab_miss[n].eq(q_m2)]
        landed_any_next = Signal(name="landed_any_next")
        m.d.comb += landed_any_next.eq(line_in | (landed > 1) | ((landed == 1) & ~(pop & head_miss)))
        m.d.sync += landed_any.eq(landed_any_next)
        # the next head's miss bit and whether it may leave, with the pop (p = 1) and
        # without it (p = 0), each from registers alone: the pop chooses last
        oldest = Mux(q_rd, fab_miss[1], fab_miss[0])      # the ring's oldest
        second = Mux(q_rd, fab_miss[0], fab_miss[1])      # the one after it
        s2_next = Mux(q_en, q_m1, q_m2)                   # the output register's next

        def head_ok_if(p):
            taken_p, into_p = p & q_f0, moving & ~(p & ~q_f0)
            f0_p = Mux(taken_p, q_f1 | into_p, q_f0 | into_p)
            v2_p = Mux(q_en, q_v1, q_v2 & ~(p & ~q_f0))
            if p:
                miss_p = Mux(q_f1, second, Mux(q_f0 & moving, q_m2, s2_next))
            else:
                miss_p = Mux(q_f0, oldest, Mux(moving, q_m2, s2_next))
            landed_p = line_in | (landed > 1) | ((landed == 1) & ~(p & head_miss))
            return (f0_p | v2_p) & (~miss_p | landed_p)
        m.d.sync += head_ok.eq(Mux(pop, head_ok_if(1), head_ok_if(0)))
        with m.If(pop):
            m.d.sync += out_seq.eq(out_seq + 1)
        up_down(landed, line_in, pop & head_miss)
        with m.If(hd_move):
            m.d.sync += [hd_valid.eq(pop), hd.eq(head)]
        for dp in datas:
            m.d.comb += [dp.r_addr.eq(hd.word), dp.en.eq(wd_move)]
        with m.If(wd_move):
            m.d.sync += [rd_valid.eq(hd_valid), rd_way.eq(hd.way), rd_sel.eq(hd.sel),
                         wd_valid.eq(rd_valid), wd_way.eq(rd_way), wd_sel.eq(rd_sel)]
            m.d.sync += [rd_extra[k].eq(hd[k]) for k in self.extra]
            m.d.sync += [wd_extra[k].eq(rd_extra[k]) for k in self.extra]
        word = Signal(g.data_bits)
        wd_hot = Signal(g.ways)
        m.d.comb += wd_hot.eq(Const(1, g.ways) << wd_way)
        for w in range(g.ways):
            with m.If(wd_hot[w]):
                m.d.comb += word.eq(wd_words[w])
        texel = Signal(g.texel_bits)
        with m.Switch(wd_sel[:sel_bits] if sel_bits else Const(0, 1)):   # the pixel's slot
            for k in range(spb):
                with m.Case(k):
                    m.d.comb += texel.eq(word.word_select(k, g.data_bits // spb))
        # the output's skid register: the words read's texel when the output register waits
        # (taken whenever it is empty: only its valid bit waits on o.ready)
        sk_texel = Signal(g.texel_bits, name="o_skid_texel")
        o_sk_extra = r.o_skid_extra = {k: Signal(s, name=f"o_skid_{k}") for k, s in self.extra.items()}
        o_skid_next = ~o_free & (o_skid | wd_valid)
        m.d.sync += [o_skid.eq(o_skid_next),
                     hd_stall.eq(Mux(hd_move, pop, hd_valid) & Mux(wd_move, rd_valid, wd_valid)
                                 & o_skid_next)]
        with m.If(~o_skid):
            m.d.sync += sk_texel.eq(texel)
            m.d.sync += [o_sk_extra[k].eq(wd_extra[k]) for k in self.extra]
        with m.If(o_skid & o_free):
            m.d.sync += [self.o.valid.eq(1), self.o.payload.texel.eq(sk_texel)]
            m.d.sync += [self.o.payload[k].eq(o_sk_extra[k]) for k in self.extra]
        with m.Elif(wd_valid & o_free):
            m.d.sync += [self.o.valid.eq(1), self.o.payload.texel.eq(texel)]
            m.d.sync += [self.o.payload[k].eq(wd_extra[k]) for k in self.extra]
        with m.Elif(self.o.ready):
            m.d.sync += self.o.valid.eq(0)
        return m

    def _plru_hdl(self, bits, hits):
        """:func:`plru_victim` (one-hot) and :func:`plru_touch` by the one-hot ``hits`` on
        Amaranth values, with constant bit indices only (no shifter)."""
        ways = self.geom.ways
        depth = ways.bit_length() - 1

        def victim(node, k):                 # the leaf under node n at depth k, one-hot
            if k == depth:
                return Const(1 << (node - (ways - 1)), ways)
            return Mux(bits[node], victim(2 * node + 2, k + 1), victim(2 * node + 1, k + 1))

        new = []
        for n in range(ways - 1):
            k = (n + 1).bit_length() - 1                     # depth of node n
            span = ways >> k                                 # ways under it
            first = (n - ((1 << k) - 1)) * span
            left = hits[first:first + span // 2].any()
            right = hits[first + span // 2:first + span].any()
            new.append(Mux(left | right, left, bits[n]))     # point away from the way hit
        return victim(0, 0), Cat(*new) if new else bits


def scene_geometry(scene: HardwareScene, **cache):
    """The :class:`CacheGeometry` of ``scene``'s map (its width, height, levels and stored
    texel width) and cache (its ``cache_sets``, ``cache_ways``, ``cache_block``,
    ``axi_data_bits``, ``cache_queue``, ``cache_outstanding``: :data:`SCENE_KEYS`), the
    parameters ``cache`` (CacheGeometry's: sets, ways, block, data_bits, queue, misses,
    base, addr_bits, stamp_bits) overriding them."""
    bits = Shape.cast(texel_shape(scene)).width
    own = {name: getattr(scene, key) for name, key in SCENE_KEYS.items()}
    height = None if scene.map_height == scene.texture_size else scene.map_height
    return CacheGeometry(scene.texture_size, scene.mip_levels, bits,
                         **{**own, "texture_height": height, **cache})


def scene_levels(scene: HardwareScene, words):
    """The block-RAM image of a map (``bumpfetch.level_bases`` order) as one ``[v, u]``
    array a level, what :func:`tiled_image` takes."""
    words, out, base = np.asarray(words, np.int64), [], 0
    for level in range(scene.mip_levels):
        side, tall = scene.level_size(level)
        out.append(words[base:base + side * tall].reshape(tall, side))
        base += side * tall
    return out


class AxiMapFetch(wiring.Component):
    """BumpMapFetch's ports and function with the map in the user's memory: texel
    coordinates are wrapped or clamped into their level (``bumpfetch.level_coords``, the
    block-RAM fetch's own arithmetic: u by the level's width, v by its height) and looked up in a :class:`TextureCache`.

    Parameters
    ----------
    scene : HardwareScene
        ``map_memory = "axi"`` scenes (a varying N' map with per-pixel shading, or the
        palette's index map: the fetched field is ``bumpfetch.fetched_field``'s).
    out_layout : data.StructLayout
        As BumpMapFetch's: the fetched field plus fields carried unchanged.
    cache : dict, optional
        :class:`CacheGeometry` parameters (sets, ways, block, data_bits, base, addr_bits).
    target : None or rtl/targets.ECP5
        The cache's (:class:`TextureCache`).

    Members
    -------
    i : In(stream.Signature({u, v: signed(log2 T + 2), [level], <carried fields>}))
    o : Out(stream.Signature(out_layout))
    axi : Out(axi_read_signature(addr_bits, data_bits))

    Latency :data:`CACHE_LATENCY` on a hit, one pixel a clock while pixels hit; a miss
    issues its line's burst and queues the pixel, and the pixels behind it go on being
    looked up (:class:`TextureCache`); ``i.ready`` falls the cycle after the looked-up
    pixel has to wait and the stages behind it are full (a function of registers alone).
    At most :attr:`capacity` pixels are inside at once.
    """

    latency = CACHE_LATENCY

    @property
    def capacity(self):
        """Pixels taken at ``i`` and not yet taken at ``o``, at most: the pixel read's, its
        words read's, their skid register's, its words settled's, their distances' and the
        lookup's registers, the queue's entries (those read ahead of their pops among them),
        its head register, the data read's and its words' registers, the output's skid
        register and the output register."""
        return self.geom.queue + 11

    def __init__(self, scene: HardwareScene, out_layout, cache=None, target=None):
        check_scene(self, scene)
        self.scene, self.out_layout, self.target = scene, out_layout, target
        self.geom = scene_geometry(scene, **(cache or {}))
        self.field = fetched_field(scene)
        g = self.geom
        self.memories = {}                   # the cache's block RAM, as a Pipe records it
        for w in range(g.ways):
            for name, depth, width in ((f"cache_data{w}", g.sets * g.beats, g.data_bits),
                                       (f"cache_tag{w}", g.sets, g.tag_bits + 1),
                                       (f"cache_stamp{w}", g.sets, g.stamp_bits)):
                self.memories[name] = {"kind": "ram", "depth": depth, "width": width,
                                       "bits": depth * width}
        queue = TextureCache.queue_layout(g, {name: f.shape for name, f in out_layout
                                              if name != fetched_field(scene)}).size
        self.memories["cache_queue"] = {"kind": "ram", "depth": g.queue, "width": queue,
                                        "bits": g.queue * queue}
        fields = {"u": signed(coord_bits(scene)), "v": signed(coord_bits(scene))}
        if scene.mip_levels > 1:
            fields["level"] = unsigned(level_bits(scene))
        self.carried = {name: f.shape for name, f in out_layout if name != self.field}
        super().__init__({
            "i": In(stream.Signature(data.StructLayout({**fields, **self.carried}))),
            "o": Out(stream.Signature(out_layout)),
            "axi": Out(axi_read_signature(self.geom.addr_bits, self.geom.data_bits))})

    def elaborate(self, platform):
        m, scene = Module(), self.scene
        m.submodules.cache = cache = TextureCache(self.geom, self.carried, self.target)
        px, to = self.i.payload, cache.i.payload
        last = scene.mip_levels - 1
        if last == 0:
            u_l, v_l = level_coords(px.u, px.v, 0, scene)
            m.d.comb += [to.u.eq(u_l), to.v.eq(v_l)]
        else:
            with m.Switch(px.level):
                for level in range(last + 1):
                    with (m.Case(level) if level < last else m.Default()):
                        u_l, v_l = level_coords(px.u, px.v, level, scene)
                        m.d.comb += [to.u.eq(u_l), to.v.eq(v_l), to.level.eq(level)]
        m.d.comb += [to[name].eq(px[name]) for name in self.carried]
        m.d.comb += [cache.i.valid.eq(self.i.valid), self.i.ready.eq(cache.i.ready),
                     self.o.valid.eq(cache.o.valid), cache.o.ready.eq(self.o.ready),
                     self.o.payload[self.field].eq(cache.o.payload.texel)]
        m.d.comb += [self.o.payload[name].eq(cache.o.payload[name]) for name in self.carried]
        wiring.connect(m, wiring.flipped(self.axi), cache.axi)
        return m
