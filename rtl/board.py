"""The board top: a scene's BumpPipeline rendering an animated, bump-mapped plane or turning
globe to HDMI (docs/board.md).

Everything but the serializer runs in one clock domain, ``sync``, at the pixel clock;
the serializer runs in ``shift`` at 5 x the pixel clock (two bits a cycle on DDR output
registers). Per pixel of the active raster, in order:

1. :class:`PixelSource` makes the pipeline's input payload in hardware: the screen position
   (x, y) becomes texel coordinates by :func:`texel_coords` (the same function gives the
   numpy inputs of the golden frames, sim/golden/board.py); the plane's normal N is a
   constant; light j's L and H come from a table of ``steps`` entries indexed by the frame
   number (the light turns one step a frame). The table and the constants are data,
   computed outside rtl/ and passed in; so is the bump map (the pipeline's block-RAM
   initial contents). With a globe (:class:`GlobeSource`) the screen position goes through
   :class:`~bumprtl.rtl.globe.GlobeGeometry` instead, which gives N and (u, v) of a turning
   sphere (:func:`globe_config`); the tag's top bit carries "inside" to the display, which
   shows black outside.
2. The scene's :class:`~bumprtl.rtl.pipeline.BumpPipeline` shades it.
3. The pipeline's own credit edge is the elastic buffer: its FIFO, ``depth`` pixels deep
   (the pipeline's ``fifo_depth``), sits between its last unit and the scan-out, and the
   source runs ahead of the display on the pipeline's credits: it offers a pixel every
   cycle and the pipeline takes it while a credit is free (``i.ready``), so the FIFO never
   overflows; the display takes ``o`` while it shows the active raster (``o.ready`` =
   ``de``). ``depth`` = latency + BUFFER_MARGIN keeps the display fed
   (:func:`buffer_depth`, docs/board.md has the derivation); ``underflow`` (sticky) says if
   it ever was not, ``order_error`` (sticky) if a pixel reached the screen out of order (the
   pipeline's tag carries the pixel count).
4. :class:`~bumprtl.rtl.video.VideoTiming` scans out; three :class:`~bumprtl.rtl.tmds.TMDSEncoder`
   lanes (blue carries hsync, vsync) and the :class:`~bumprtl.rtl.tmds.Serializer`.

:class:`BoardCore` is all of that; :class:`ULX3STop` adds the ECP5 PLL (EHXPLLL, 25 MHz ->
pixel and 5 x pixel clocks) and the ``hdmi`` pins' DDR registers (an ODDRX1F a pin); :class:`SimTop` replaces both by ports: the testbench drives ``clk`` and
``shift_clk`` at the same ratio and the DDR registers become the multiplexer they are
(``o0`` while the shift clock is high, ``o1`` while low), on ``tmds_data_p`` (lane k on bit
k) and ``tmds_clk_p``.
"""

import math

from amaranth.hdl import (
    Cat,
    ClockDomain,
    ClockSignal,
    DomainRenamer,
    Elaboratable,
    Instance,
    Module,
    Mux,
    Signal,
)
from amaranth.lib import io, stream, wiring
from amaranth.lib.cdc import ResetSynchronizer
from amaranth.lib.fifo import AsyncFIFO, SyncFIFOBuffered
from amaranth.lib.memory import Memory

from bumprtl.rtl.cache import scene_geometry
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.flash import FlashLoader, spi_signature
from bumprtl.rtl.globe import GlobeConfig, GlobeGeometry
from bumprtl.rtl.pipe import RAM_LATENCY
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.scene import HardwareScene
from bumprtl.rtl.sdram import SdramController, sdram_signature
from bumprtl.rtl.targets import RegisteredRAM
from bumprtl.rtl.tmds import CLOCK_WORD, Serializer, TMDSEncoder
from bumprtl.rtl.video import VideoMode, VideoTiming

__all__ = ["texel_coords", "buffer_depth", "BUFFER_MARGIN", "payload_field", "RasterSource",
           "register_slice",
           "PixelSource",
           "GlobeSource", "DisplayBuffer", "ar_queue", "globe_config", "globe_offsets", "globe_turn_step", "globe_rotation",
           "GLOBE_TURN_FRAMES",
           "GLOBE_RADIUS", "BoardCore", "ULX3STop", "SimTop", "pll_params", "pll_dividers", "pll_clock",
           "cdc_depth", "CDC_SYNC_STAGES", "pll_pipe_divider", "sdram_clock",
           "SDRAM_PIN_CYCLES", "ULX3SSdramIO"]

BUFFER_MARGIN = 8
# The globe: its radius is GLOBE_RADIUS of the screen's height (224 pixels at 480 lines, 336
# at 720), and it turns once in about GLOBE_TURN_FRAMES frames (17 s at 60 Hz).
GLOBE_RADIUS = (7, 15)
GLOBE_TURN_FRAMES = 1024
# Synchronizer stages of the clock-crossing FIFO's pointers (amaranth.lib.fifo.AsyncFIFO's
# default): a pointer written in one domain is seen in the other that many clocks later.
CDC_SYNC_STAGES = 2


def cdc_depth(pixel_hz, pipe_hz, stall_cycles=0):
    """Entries of the asynchronous FIFO between the pipeline's clock domain (``pipe_hz``)
    and the pixel clock (docs/board.md, The pipeline in its own clock domain): the display
    takes one entry a pixel clock through an active line, and a slot it frees is filled
    again, at the latest, after the round trip ``3 + CDC_SYNC_STAGES`` pixel clocks (the
    read pointer's register and synchronizer, the entry's register) plus ``2 +
    CDC_SYNC_STAGES + stall_cycles`` pipe clocks (the write side's synchronizer, the write,
    and the longest the pipeline's output may pause: 0 for a map in block RAM, which never
    pauses while credits are held), so that many entries and one more keep it fed; the
    next power of two (AsyncFIFO's depths). BumpError when the pipeline's clock is slower
    than the pixel clock: a line's pixels would outrun it."""
    if not pipe_hz >= pixel_hz:
        raise BumpError(f"pipe clock must be at least the pixel clock {pixel_hz / 1e6:g} MHz "
                        f"(one pixel a clock through a line), got {pipe_hz / 1e6:g} MHz", "pipe_hz")
    if not isinstance(stall_cycles, int) or stall_cycles < 0:
        raise BumpError(f"stall_cycles must be an int >= 0, got {stall_cycles!r}", "stall_cycles")
    pipe_side = math.ceil((2 + CDC_SYNC_STAGES + stall_cycles) * pixel_hz / pipe_hz)
    need = 3 + CDC_SYNC_STAGES + pipe_side + 1
    return 1 << (need - 1).bit_length()


def texel_coords(x, y, zoom, size, height=None):
    """Screen pixel (x, y) -> texel (u, v) of a ``size`` x ``height`` map (width x height,
    powers of two; ``height`` None: ``size``) tiled over the screen, ``2**zoom`` pixels a
    texel: u wraps by the width, v by the height. Amaranth values and numpy integer arrays
    alike."""
    height = size if height is None else height
    return (x >> zoom) & (size - 1), (y >> zoom) & (height - 1)


def buffer_depth(latency):
    """The elastic buffer's depth for a pipeline of ``latency`` (docs/board.md)."""
    return latency + BUFFER_MARGIN


def payload_field(view, key):
    """The field of a payload view named by a flattened key (``"n.phi"``,
    ``"extra_lights.0.l.theta"``)."""
    for part in key.split("."):
        view = view[int(part)] if part.isdigit() else view[part]
    return view


class RasterSource(Elaboratable):
    """What the board's sources share: the raster counters (``px``, ``py``, the pixel count
    ``count`` of ``count_bits``) and the light table (``table``: one {key: code} per light
    step, L and H of every light), the next step's entry read ahead into a register the
    pipeline's payload comes from, its step register ``frame`` moving on after the last
    pixel of a frame. ``allow``: the source may
    offer a pixel this cycle. It drives ``port``: the pipeline's input stream, or with
    ``register`` a stream of the same shape that :func:`register_slice` joins to it, so
    that the source's counters and the table's address see a registered ready (the texel
    cache's ready is combinational: with the map in the SDRAM it would chain the cache's
    lookup into the source)."""

    def __init__(self, pipeline, mode: VideoMode, table, count_bits, register=False):
        self.pipeline, self.mode = pipeline, mode
        self.register = register
        self.port = (stream.Signature(pipeline.i.payload.shape()).create(path=("source_out",))
                     if register else pipeline.i)
        self.table = [dict(t) for t in table]
        self.keys = sorted(self.table[0])
        self.widths = [len(payload_field(pipeline.i.payload, k)) for k in self.keys]
        self.allow = Signal()
        self.px = Signal(range(mode.h_active), name="src_x")
        self.py = Signal(range(mode.v_active), name="src_y")
        self.frame = Signal(range(len(self.table)), name="light_step")
        self.count = Signal(count_bits, name="src_count")
        # the table's read port answers a cycle late: no pixel in the cycle after reset
        self.primed = Signal(name="table_primed")

    def raster(self, m, take):
        """Advance the raster on ``take``; returns (last column, last row)."""
        md = self.mode
        last_x, last_y = self.px == md.h_active - 1, self.py == md.v_active - 1
        with m.If(take):
            m.d.sync += [self.px.eq(Mux(last_x, 0, self.px + 1)), self.count.eq(self.count + 1)]
            with m.If(last_x):
                m.d.sync += self.py.eq(Mux(last_y, 0, self.py + 1))
        return last_x, last_y

    def lights(self, m, wrap):
        """The light table into the pipeline's payload: the entry of ``frame`` from a
        register (``light_entry``, the table's entry 0 after reset), which takes the next
        step's entry in the cycle after ``wrap`` (the last pixel of a frame taken). The
        table's read port is always at the next step, so its answer has waited at least a
        cycle when it is taken (a frame of 2 pixels or more): the block RAM's output
        (about 6 ns from its clock on the ECP5 without its output register) reaches one
        flip-flop's data input, not the payload's registers beyond it."""
        words = [sum(int(t[k]) << sum(self.widths[:n]) for n, k in enumerate(self.keys))
                 for t in self.table]
        m.submodules.light_table = rom = Memory(shape=sum(self.widths), depth=len(words),
                                                init=words)
        rd = rom.read_port()
        m.d.sync += self.primed.eq(1)
        step = Mux(self.frame == len(self.table) - 1, 0, self.frame + 1)
        entry = Signal(sum(self.widths), init=words[0], name="light_entry")
        m.d.comb += rd.addr.eq(step)
        with m.If(wrap):
            m.d.sync += [self.frame.eq(step), entry.eq(rd.data)]
        at = 0
        for k, w in zip(self.keys, self.widths, strict=False):
            m.d.comb += payload_field(self.port.payload, k).eq(entry[at:at + w])
            at += w
        if self.register:
            register_slice(m, self.port, self.pipeline.i)


def register_slice(m, src, dst):
    """``src`` -> ``dst`` (streams of one payload shape) through two registers, full rate:
    ``src.ready`` is a register (the spare register empty) and ``dst``'s ready reaches only
    the output register's enable and the two valid flags. The spare register takes
    ``src``'s payload whenever it is empty; a pixel ``src`` offers is taken into the output
    register if that moves on this cycle, else into the spare one; the output register
    takes the spare one first. Order kept, nothing dropped or doubled."""
    shape = src.payload.shape()
    out, spare = Signal(shape, name="slice_out"), Signal(shape, name="slice_spare")
    out_valid, spare_valid = Signal(name="slice_out_valid"), Signal(name="slice_spare_valid")
    move = ~out_valid | dst.ready
    m.d.comb += [src.ready.eq(~spare_valid), dst.valid.eq(out_valid), dst.payload.eq(out)]
    with m.If(~spare_valid):
        m.d.sync += spare.eq(src.payload)
    with m.If(move):
        m.d.sync += [out.eq(Mux(spare_valid, spare, src.payload)),
                     out_valid.eq(spare_valid | src.valid), spare_valid.eq(0)]
    with m.Else():
        m.d.sync += spare_valid.eq(spare_valid | src.valid)


class PixelSource(RasterSource):
    """The per-pixel input generator of the plane (module docstring, 1.). ``constants``:
    {key: code} of payload fields that never change (the plane's N); ``table``: one
    {key: code} per light step (L and H of every light); the pipeline's input stream
    (valid, payload; ready from it) is driven."""

    def __init__(self, pipeline, mode: VideoMode, constants, table, register=False):
        super().__init__(pipeline, mode, table, pipeline.cfg.tag_bits, register)
        self.constants = dict(constants)

    def elaborate(self, platform):
        m, md, p, port = Module(), self.mode, self.pipeline, self.port
        issue = Signal()
        m.d.comb += [port.valid.eq(self.allow & self.primed), issue.eq(port.valid & port.ready)]
        last_x, last_y = self.raster(m, issue)
        self.lights(m, issue & last_x & last_y)
        pay = port.payload
        u, v = texel_coords(self.px, self.py, md.zoom, p.scene.texture_size, p.scene.map_height)
        m.d.comb += [pay.u.eq(u), pay.v.eq(v), pay.tag.eq(self.count)]
        m.d.comb += [payload_field(pay, k).eq(c) for k, c in self.constants.items()]
        return m


def globe_config(scene: HardwareScene, mode: VideoMode):
    """The board's globe (rtl/globe.GlobeConfig) in ``mode``: radius GLOBE_RADIUS of the
    active height, the scene's map read as the software sphere reads it (u over the
    longitude and the width W = ``texture_size``, v over the colatitude and the height H =
    ``texture_height``: W = H, a square map, or W = 2H, an equirectangular one), offsets
    wide enough for the whole screen, the pipeline's angle and tag widths, the scene's mip
    levels (with more than one the globe picks each pixel's level)."""
    num, den = GLOBE_RADIUS
    radius = max(1, mode.v_active * num // den)
    reach = max(mode.h_active, mode.v_active) // 2
    coord = max(reach.bit_length() + 1, radius.bit_length() + 1)
    return GlobeConfig(radius=radius, map_width=scene.texture_size, map_height=scene.map_height,
                       pipeline=scene.config, coord_bits=coord, mip_levels=scene.mip_levels)


def globe_offsets(x, y, mode: VideoMode):
    """Screen pixel (x, y) (y down from the top row) -> the globe's offsets from the centre
    (x right, y up): ``(x - h_active // 2, v_active // 2 - y)``. Amaranth values and numpy
    arrays alike."""
    return x - mode.h_active // 2, mode.v_active // 2 - y


def globe_turn_step(cfg):
    """The globe's rotation added each frame, in angle codes: a full turn in about
    GLOBE_TURN_FRAMES frames, at least one code."""
    return max(1, cfg.full_circle // GLOBE_TURN_FRAMES)


def globe_rotation(cfg, frame):
    """The globe's rotation in frame ``frame`` (codes): 3/4 turn in frame 0, where u is the
    software sphere's (u = phi / 2pi W: the map's seam at the right-hand limb), then
    :func:`globe_turn_step` more each frame."""
    return (3 * cfg.full_circle // 4 + frame * globe_turn_step(cfg)) % cfg.full_circle


class GlobeSource(RasterSource):
    """The per-pixel input generator of the globe (module docstring, 1.): the raster position
    and the globe's rotation into ``globe`` (a :class:`~bumprtl.rtl.globe.GlobeGeometry`
    with its own credit edge, elaborated by the caller), its output and light j's L and H
    from the table into the pipeline.

    The rotation starts at :func:`globe_rotation` of frame 0 and advances by
    :func:`globe_turn_step` codes after the last pixel of a frame enters the globe; the
    light step after the last pixel of a frame enters the pipeline (the globe's tag carries
    the pixel count below a "last of the frame" bit, and the pipeline's tag the count below
    the globe's ``inside``)."""

    def __init__(self, pipeline, mode: VideoMode, globe: GlobeGeometry, table, register=False):
        bits = pipeline.cfg.tag_bits
        if bits < 2:
            self._MustUse__silence = True          # refused: never to be elaborated
            raise BumpError(f"tag_bits must be >= 2 for the globe (the pixel count and the "
                            f"inside bit), got {bits}", "tag_bits")
        super().__init__(pipeline, mode, table, bits - 1, register)
        self.globe = globe
        self.turn_step = globe_turn_step(pipeline.cfg)
        self.rotation = Signal(globe.gcfg.angle_bits, name="globe_rotation",
                               init=globe_rotation(pipeline.cfg, 0))

    def elaborate(self, platform):
        m, g = Module(), self.globe
        # the globe's side: the raster and the rotation
        take = Signal()
        m.d.comb += [g.i.valid.eq(self.allow), take.eq(g.i.valid & g.i.ready)]
        last_x, last_y = self.raster(m, take)
        with m.If(take & last_x & last_y):
            m.d.sync += self.rotation.eq(self.rotation + self.turn_step)
        x, y = globe_offsets(self.px, self.py, self.mode)
        gi = g.i.payload
        m.d.comb += [gi.x.eq(x), gi.y.eq(y), gi.rotation.eq(self.rotation),
                     gi.tag.eq(Cat(self.count, last_x & last_y))]
        # the pipeline's side: the globe's output and the light table
        go, issue, port = g.o.payload, Signal(), self.port
        m.d.comb += [port.valid.eq(g.o.valid & self.primed),
                     g.o.ready.eq(port.ready & self.primed), issue.eq(port.valid & port.ready)]
        self.lights(m, issue & go.tag[-1])
        pay = port.payload
        m.d.comb += [pay.u.eq(go.u), pay.v.eq(go.v), pay.n.phi.eq(go.n.phi),
                     pay.n.theta.eq(go.n.theta), pay.tag.eq(Cat(go.tag[:-1], go.inside))]
        if g.gcfg.mip_levels > 1:         # the mip level from the globe's derivative
            m.d.comb += pay.level.eq(go.level)
        return m


def _check_memory(scene, pipe_hz, sdram, flash):
    """BumpError unless the map's place and the memory parts agree: a map in the SDRAM
    (``map_memory = "axi"``) with an SdramConfig, a FlashConfig and a pipe clock, the
    three data widths equal (the cache's AXI port, the controller's, the loader's); a map
    in block RAM with neither."""
    axi = scene.map_memory == "axi"
    if not axi:
        if sdram is not None or flash is not None:
            raise BumpError("sdram and flash serve a map in the SDRAM: the scene's map_memory "
                            f"must be 'axi', got {scene.map_memory!r}", "map_memory")
        return
    if sdram is None or flash is None or pipe_hz is None:
        raise BumpError("map_memory = 'axi' on the board needs the SDRAM and the flash "
                        "loader (sdram, flash) and the pipe clock (pipe_hz)", "map_memory")
    bits = scene_geometry(scene).data_bits
    if not sdram.data_bits == flash.data_bits == bits:
        raise BumpError(f"data_bits: the cache's AXI port has {bits}, the SDRAM controller's "
                        f"{sdram.data_bits}, the flash loader's {flash.data_bits}: they must "
                        f"be equal", "data_bits")


def _display_buffer(pipe_hz, entries):
    """BoardCore's ``display_buffer``, or BumpError."""
    if entries is None:
        return None
    if pipe_hz is None:
        raise BumpError("display_buffer sits ahead of the clock crossing: it needs the "
                        "pipeline in its own clock domain (pipe_hz)", "display_buffer")
    return _check_entries(entries)


def _check_entries(entries):
    if isinstance(entries, bool) or not isinstance(entries, int) or entries < 2 \
            or entries & (entries - 1):
        raise BumpError(f"display_buffer must be a power of two >= 2, got {entries!r}",
                        "display_buffer")
    return entries


AR_FIELDS = ("arid", "araddr", "arlen", "arsize", "arburst")


def ar_queue(m, manager, subordinate, depth, name="ar_queue", domain="sync"):
    """Join an AXI4 read ``manager`` port to a ``subordinate`` (rtl/cache.axi_read_signature)
    through a queue of ``depth`` read addresses (a ``SyncFIFOBuffered`` in ``domain``,
    submodule ``name``),
    the R channel straight through: the manager's bursts are taken while the queue has
    room, and the subordinate serves them one after another. The SDRAM controller takes an
    AR only once its burst before is issued, and the texel cache looks up no pixel while
    its AR waits, so without the queue the cache could run at most one miss ahead of the
    SDRAM; with ``depth`` at least the cache's bursts outstanding it never waits for one."""
    width = sum(len(getattr(manager, f)) for f in AR_FIELDS)
    m.submodules[name] = q = DomainRenamer(domain)(SyncFIFOBuffered(width=width, depth=depth))
    m.d.comb += [q.w_data.eq(Cat(*(getattr(manager, f) for f in AR_FIELDS))),
                 q.w_en.eq(manager.arvalid), manager.arready.eq(q.w_rdy),
                 subordinate.arvalid.eq(q.r_rdy), q.r_en.eq(subordinate.arready)]
    at = 0
    for f in AR_FIELDS:
        n = len(getattr(manager, f))
        m.d.comb += getattr(subordinate, f).eq(q.r_data[at:at + n])
        at += n
    m.d.comb += [manager.rid.eq(subordinate.rid), manager.rdata.eq(subordinate.rdata),
                 manager.rresp.eq(subordinate.rresp), manager.rlast.eq(subordinate.rlast),
                 manager.rvalid.eq(subordinate.rvalid), subordinate.rready.eq(manager.rready)]
    return q


class DisplayBuffer(Elaboratable):
    """A FIFO of ``depth`` words (a power of two, at least 2) of ``width`` bits in block
    RAM: BoardCore's ``display_buffer``, ahead of the clock crossing. It has
    ``amaranth.lib.fifo``'s port names (``w_en``, ``w_data``, ``w_rdy``, ``r_en``,
    ``r_data``, ``r_rdy``) and ``level``.

    The memory is a :class:`~bumprtl.rtl.targets.RegisteredRAM` (on ECP5 DP16KD blocks read
    through their output registers, so that no route from a block RAM spread over the die
    ends in logic): a word is read from it RAM_LATENCY cycles after its address, into an
    output queue of OUT_SLOTS words (a ``SyncFIFOBuffered`` beside the crossing). A read is
    issued while the memory holds a word and the queue has room for it and for the reads in
    flight, so the queue never overflows. A word holds its slot from the cycle after its
    read's issue until it leaves the queue: its flight, the queue's memory and its output
    register, RAM_LATENCY + 3 cycles when read at once, so that many slots let a word a
    cycle through (one fewer loses cycles: tests/rtl/test_display_buffer.py). ``w_rdy`` is
    one bit of the memory's count, a register. Never read, it holds ``depth`` + OUT_SLOTS
    words."""

    OUT_SLOTS = RAM_LATENCY + 3

    def __init__(self, width, depth, target=None):
        self.width, self.depth, self.target = width, _check_entries(depth), target
        self.bits = depth.bit_length() - 1
        self.w_en, self.w_rdy, self.w_data = Signal(), Signal(), Signal(width)
        self.r_en, self.r_rdy, self.r_data = Signal(), Signal(), Signal(width)
        self.level = Signal(range(depth + self.OUT_SLOTS + RAM_LATENCY + 1))
        self.count = Signal(self.bits + 1, name="buffer_count")     # words in the memory

    def elaborate(self, platform):
        m, bits = Module(), self.bits
        m.submodules.ram = ram = RegisteredRAM(self.depth, self.width, "display_buffer",
                                               target=self.target)
        m.submodules.out = out = SyncFIFOBuffered(width=self.width, depth=self.OUT_SLOTS)
        wp = Signal(bits, name="buffer_write")
        rp = Signal(bits, name="buffer_read")
        stored = Signal(name="buffer_stored")                   # count != 0, a register
        flight = Signal(RAM_LATENCY, name="buffer_flight")      # reads on their way
        put = self.w_en & self.w_rdy
        in_flight = sum(flight[k] for k in range(RAM_LATENCY))
        issue = stored & (out.level + in_flight < self.OUT_SLOTS)
        m.d.comb += [self.w_rdy.eq(~self.count[bits]),
                     ram.w_en.eq(put), ram.w_addr.eq(wp), ram.w_data.eq(self.w_data),
                     ram.en.eq(1), ram.r_addr.eq(rp),
                     out.w_en.eq(flight[-1]), out.w_data.eq(ram.r_data),
                     out.r_en.eq(self.r_en), self.r_rdy.eq(out.r_rdy),
                     self.r_data.eq(out.r_data),
                     self.level.eq(self.count + in_flight + out.level)]
        m.d.sync += [wp.eq(wp + put), rp.eq(rp + issue),
                     self.count.eq(self.count + put - issue),
                     flight.eq(Cat(issue, flight[:-1]))]
        with m.If(put & ~issue):
            m.d.sync += stored.eq(1)
        with m.Elif(issue & ~put):
            m.d.sync += stored.eq(self.count != 1)
        return m


class BoardCore(Elaboratable):
    """Source, pipeline, elastic buffer, timing, TMDS encoders and serializer (module
    docstring). ``o0``, ``o1``: the serializer's bits of lanes 0-2 (blue, green, red) and 3
    (clock) each shift cycle; ``underflow``, ``order_error``: sticky status; ``frame``: the
    source's light step; ``pixel``: the bytes (blue, green, red) the encoders are given,
    0 outside the active raster."""

    def __init__(self, scene: HardwareScene, mode, words, constants, table, texels=None,
                 target=None, depth=None, pipe_hz=None, globe=False, sdram=None, flash=None,
                 preloaded=False, display_buffer=None):
        """``depth``: the pipeline's FIFO depth (None: :func:`buffer_depth` of its latency;
        below ``min_fifo_depth`` of the latency the pipeline refuses it). ``pipe_hz``: None
        runs the source and the pipeline at the pixel clock (domain ``sync``); a frequency
        (at least the mode's pixel clock) runs them in their own domain ``pipe`` behind an
        :class:`~amaranth.lib.fifo.AsyncFIFO` of :func:`cdc_depth` entries into ``sync``;
        ``display_buffer`` (a power of two, at least 2; None: none) adds a
        :class:`DisplayBuffer` of that many entries in ``pipe`` between the pipeline and
        the crossing: more pixels held ahead of the display, for a map in the SDRAM whose
        misses come in bursts (the pixel and the tag only, not the pipeline's whole
        payload).
        ``globe``: a turning globe (:class:`GlobeSource`, :func:`globe_config`) instead of
        the plane; ``constants`` is then unused. ``sdram`` (an
        :class:`~bumprtl.rtl.sdram.SdramConfig`) and ``flash`` (a
        :class:`~bumprtl.rtl.flash.FlashConfig`): the scene's map lives in the SDRAM
        (``map_memory = "axi"``, the pipeline's texel cache reading it through an
        :class:`~bumprtl.rtl.sdram.SdramController`), copied there after reset from the SPI
        flash by a :class:`~bumprtl.rtl.flash.FlashLoader`; the source starts once the copy
        is done. Both run in ``pipe`` (``pipe_hz`` is the SDRAM's clock); the pins are
        ``sdram_pins`` and ``spi``. The display starts showing at the first frame whose
        first pixel is ready, black before it (``underflow`` counts from there).
        ``preloaded`` (simulation only, with ``sdram``): no loader and no flash pins; the
        map counts as loaded once the controller's initialisation is done, the SDRAM's
        model holding the image already (its write port stays idle)."""
        _check_memory(scene, pipe_hz, sdram, flash)
        if preloaded and sdram is None:
            raise BumpError("preloaded applies to a map in the SDRAM (sdram and flash)",
                            "preloaded")
        self.mode = mode
        self.pipe_hz = pipe_hz
        self.cdc_depth = None if pipe_hz is None else cdc_depth(mode.pixel_hz, pipe_hz)
        self.display_buffer = _display_buffer(pipe_hz, display_buffer)
        self.target = target
        self.pipeline = BumpPipeline(scene, init=words, texture=texels, target=target,
                                     fifo_depth=buffer_depth if depth is None else depth)
        self.scene = self.pipeline.scene
        self.depth = self.pipeline.fifo_depth
        # the texel cache's ready depends on its lookup: a register slice after the source
        slice_ = self.scene.map_memory == "axi"
        if globe:
            self.globe = GlobeGeometry(globe_config(self.scene, mode), target)
            self.source = GlobeSource(self.pipeline, mode, self.globe, table, slice_)
        else:
            self.globe = None
            self.source = PixelSource(self.pipeline, mode, constants, table, slice_)
        self.sdram, self.flash = sdram, flash
        self.preloaded = bool(preloaded)
        self.loader = self.spi = None
        if sdram is not None:     # (in this order: the elaborated names follow it)
            self.controller = SdramController(sdram)
            if not self.preloaded:
                self.loader = FlashLoader(flash)
            self.sdram_pins = sdram_signature(sdram).flip().create(path=("sdram",))
            if not self.preloaded:
                self.spi = spi_signature().flip().create(path=("spi",))
        self.timing = VideoTiming(mode)
        self.shows = Signal(name="display_shows")   # the display takes pixels (from a frame's start)
        self.underflow = Signal()
        self.order_error = Signal()
        self.o0, self.o1 = Signal(4), Signal(4)
        self.pixel = Signal(24, name="shown_pixel")   # what the encoders get: blue, green, red

    def elaborate(self, platform):
        m, p = Module(), self.pipeline
        tag_bits = p.cfg.tag_bits
        src = self.source
        inner = {"pipeline": p, "source": src}
        if self.globe is not None:
            inner["globe"] = self.globe
        if self.sdram is not None:
            inner["sdram"] = self.controller
            if self.loader is not None:
                inner["flash_loader"] = self.loader
            # the cache's bursts queue in front of the controller
            ar_queue(m, p.axi, self.controller.rd, scene_geometry(self.scene).misses,
                     domain="pipe")
            if self.loader is not None:
                wiring.connect(m, self.loader.axi, self.controller.wr)
            wiring.connect(m, self.controller.sdram, self.sdram_pins)
            if self.loader is not None:
                wiring.connect(m, self.loader.spi, self.spi)
        for name, sub in inner.items():
            m.submodules[name] = sub if self.pipe_hz is None else DomainRenamer("pipe")(sub)
        m.submodules.timing = t = self.timing
        # the pixel's colour: grey from the shade, or the colour-texture blend's RGB
        o = p.o.payload
        if self.scene.texture:
            rgb = Cat(o.color.b, o.color.g, o.color.r)
        else:                         # grey: one byte through the buffers, three to the encoders
            rgb = o.color
        if self.globe is not None:    # the tag's top bit is the globe's inside: black outside
            rgb = Mux(o.tag[-1], rgb, 0)
        count_bits = len(src.count)   # the tag's bits that count pixels, as the source counts
        # a pixel every cycle, once the map is in place; the credits decide when it is taken
        if self.sdram is None:
            m.d.comb += src.allow.eq(1)
        else:                         # the loader's done (a comparison) as a register
            loaded = Signal(name="map_loaded")
            # preloaded (simulation): the controller's initialisation done instead
            done = self.controller.regs.run if self.loader is None else self.loader.done
            m.d.pipe += loaded.eq(done)
            m.d.comb += src.allow.eq(loaded)
        # the display shows from the first frame whose first pixel is ready
        running, shows = Signal(name="display_running"), self.shows
        if self.pipe_hz is None:      # the pipeline's FIFO is the buffer, read at the display
            valid, color, tag = p.o.valid, rgb, o.tag
            m.d.comb += p.o.ready.eq(t.de & shows)
        else:                         # its FIFO feeds the crossing, which the display reads
            m.submodules.cdc = cdc = AsyncFIFO(width=len(rgb) + tag_bits, depth=self.cdc_depth,
                                               w_domain="pipe", r_domain="sync")
            valid, data, ready = p.o.valid, Cat(rgb, o.tag), p.o.ready
            if self.display_buffer is not None:     # more pixels ahead, in the pipe domain
                buf = DomainRenamer("pipe")(DisplayBuffer(len(data), self.display_buffer,
                                                          self.target))
                m.submodules.display_buffer = buf
                m.d.comb += [buf.w_data.eq(data), buf.w_en.eq(valid), ready.eq(buf.w_rdy)]
                valid, data, ready = buf.r_rdy, buf.r_data, buf.r_en
            m.d.comb += [cdc.w_data.eq(data), cdc.w_en.eq(valid), ready.eq(cdc.w_rdy),
                         cdc.r_en.eq(t.de & shows)]
            valid, color, tag = cdc.r_rdy, cdc.r_data[:len(rgb)], cdc.r_data[len(rgb):]
        # x == 0 as ~|x: an equality with 0 would be Verilog's ! of a vector, which lint refuses
        first = t.de & ~t.x.any() & ~t.y.any()
        m.d.comb += shows.eq(running | (first & valid))
        with m.If(first & valid):
            m.d.sync += running.eq(1)
        take = t.de & valid & shows
        shown = Signal(count_bits, name="shown_count")
        with m.If(take):
            m.d.sync += shown.eq(shown + 1)
            with m.If(tag[:count_bits] != shown):
                m.d.sync += self.order_error.eq(1)
        with m.If(t.de & ~valid & shows):
            m.d.sync += self.underflow.eq(1)
        if not self.scene.texture:
            color = Cat(color, color, color)
        pixel = Mux(take, color, 0)                   # bytes: blue, green, red
        m.d.comb += self.pixel.eq(pixel)
        # the encoders' inputs registered, syncs and DE with the pixel: the display's
        # decisions (the raster's position, the buffer's valid) and the encoders' first
        # stage are a pixel clock each (at 720p, 13.5 ns)
        enc_pixel, enc_de = Signal(24, name="enc_pixel"), Signal(name="enc_de")
        enc_hsync = Signal(init=int(self.mode.h_negative), name="enc_hsync")
        enc_vsync = Signal(init=int(self.mode.v_negative), name="enc_vsync")
        m.d.sync += [enc_pixel.eq(pixel), enc_de.eq(t.de), enc_hsync.eq(t.hsync),
                     enc_vsync.eq(t.vsync)]
        words = []
        for lane in range(3):
            enc = TMDSEncoder()
            m.submodules[f"tmds{lane}"] = enc
            m.d.comb += [enc.data.eq(enc_pixel[8 * lane:8 * lane + 8]), enc.de.eq(enc_de)]
            if lane == 0:
                m.d.comb += [enc.c0.eq(enc_hsync), enc.c1.eq(enc_vsync)]
            words.append(enc.q)
        clock_word = Signal(10, init=CLOCK_WORD, name="clock_word")
        m.submodules.serializer = ser = Serializer([*words, clock_word])
        m.d.comb += [self.o0.eq(ser.o0), self.o1.eq(ser.o1)]
        return m


# ECP5 EHXPLLL limits (Lattice FPGA-TN-02200, sysCLOCK PLL), in Hz: the phase detector's
# input (reference / CLKI_DIV) at least PFD_MIN_HZ, the VCO (CLKOP x CLKOP_DIV) within
# VCO_HZ, each output at most OUT_MAX_HZ, every divider 1 .. DIV_MAX.
PFD_MIN_HZ, VCO_HZ, OUT_MAX_HZ, DIV_MAX = 3.125e6, (400e6, 800e6), 400e6, 128
# registers of the shift domain between the serializer and the HDMI pins' ODDRX1F
# (ULX3STop), besides the serializer's own output register
PIN_STAGES = 3


def pll_dividers(pixel_hz, ref_hz=25e6):
    """``(clki_div, clkfb_div, clkop_div)`` of the EHXPLLL that makes the shift clock
    (CLKOP, the feedback: ref / clki_div x clkfb_div) nearest 5 x ``pixel_hz`` within the
    limits above, the smallest dividers among equals; CLKOS = CLKOP / 5 is the pixel clock.
    BumpError when no setting is within 0.5 % (the CEA-861 / VESA clock tolerance)."""
    shift = 5 * pixel_hz
    best = None                          # ((error, clki), dividers); CLKOP_DIV 5 where it fits
    for clki in range(1, DIV_MAX + 1):
        if ref_hz / clki < PFD_MIN_HZ:
            break
        fb = max(1, min(DIV_MAX, round(shift * clki / ref_hz)))
        got = ref_hz / clki * fb
        ops = [d for d in range(1, DIV_MAX // 5 + 1) if VCO_HZ[0] <= got * d <= VCO_HZ[1]]
        if got > OUT_MAX_HZ or not ops:
            continue
        key = (abs(got - shift), clki)
        if best is None or key < best[0]:
            best = (key, (clki, fb, 5 if 5 in ops else max(ops)))
    if best is None or best[0][0] > 0.005 * shift:
        raise BumpError(f"pixel clock {pixel_hz / 1e6:g} MHz: no EHXPLLL setting from a "
                        f"{ref_hz / 1e6:g} MHz reference within 0.5 %", "mode")
    return best[1]


def pll_clock(pixel_hz, ref_hz=25e6):
    """The pixel clock the PLL of :func:`pll_dividers` gives (Hz)."""
    clki, fb, _ = pll_dividers(pixel_hz, ref_hz)
    return ref_hz / clki * fb / 5


def pll_pipe_divider(pixel_hz, pipe_hz, ref_hz=25e6, at_most=False):
    """``(clkos2_div, hz)``: the EHXPLLL's CLKOS2 divider of the VCO of
    :func:`pll_dividers` that gives the pipeline's clock nearest ``pipe_hz`` from above (never
    below it: :func:`cdc_depth` assumes at least that rate), or with ``at_most`` nearest at
    or below it (the SDRAM's clock: never faster than the clock its timing was counted
    for), and that clock. BumpError when no divider gives a clock within [``pipe_hz``,
    OUT_MAX_HZ] (``at_most``: within [VCO / DIV_MAX, ``pipe_hz``])."""
    clki, fb, op_div = pll_dividers(pixel_hz, ref_hz)
    vco = ref_hz / clki * fb * op_div
    div = 0
    if pipe_hz > 0:               # a clock the PLL gives exactly keeps its own divider
        ratio = vco / pipe_hz
        div = math.ceil(ratio - 1e-9) if at_most else math.floor(ratio + 1e-9)
    if not 1 <= div <= DIV_MAX or vco / div > OUT_MAX_HZ:
        raise BumpError(f"pipe clock must be in [{vco / DIV_MAX / 1e6:g}, {OUT_MAX_HZ / 1e6:g}] MHz "
                        f"(the VCO {vco / 1e6:g} MHz over a divider 1 .. {DIV_MAX}), got "
                        f"{pipe_hz / 1e6:g} MHz", "pipe_hz")
    return div, vco / div


def sdram_clock(pixel_hz, sdram_max_hz, ref_hz=25e6):
    """The pipe clock of a board whose map is in the SDRAM: the PLL's CLKOS2 nearest
    ``sdram_max_hz`` at or below it (:func:`pll_pipe_divider` with ``at_most``), in Hz; the
    SdramConfig is then made for exactly this clock. BumpError naming ``pipe_hz`` when it
    would be below the pixel clock (:func:`cdc_depth`)."""
    _, hz = pll_pipe_divider(pixel_hz, sdram_max_hz, ref_hz, at_most=True)
    if hz < pixel_hz:
        raise BumpError(f"pipe clock: the PLL's clock at or below {sdram_max_hz / 1e6:g} MHz is "
                        f"{hz / 1e6:g} MHz, below the pixel clock {pixel_hz / 1e6:g} MHz; it must "
                        f"be in [{pixel_hz / 1e6:g}, {sdram_max_hz / 1e6:g}] MHz", "pipe_hz")
    return hz


def pll_params(pixel_hz, ref_hz=25e6, pipe_hz=None, sdram=False):
    """EHXPLLL parameters: CLKOP = 5 x pixel (the shift clock, also the feedback), CLKOS =
    the pixel clock, from ``ref_hz`` (:func:`pll_dividers`); with ``pipe_hz``, CLKOS2 = the
    pipeline's clock (:func:`pll_pipe_divider`, from above; with ``sdram`` at or below);
    with ``sdram`` also CLKOS3 = the same clock half a period later (the SDRAM's read
    capture, docs/sdram.md): the coarse phase counts VCO cycles after the divider's own
    ``div - 1``, the fine phase eighths of one (docs/sdram.md, The pins on the ULX3S)."""
    clki, fb, op_div = pll_dividers(pixel_hz, ref_hz)
    extra = {}
    if pipe_hz is not None:
        div, _ = pll_pipe_divider(pixel_hz, pipe_hz, ref_hz, at_most=sdram)
        extra = {"p_CLKOS2_ENABLE": "ENABLED", "p_CLKOS2_DIV": div,
                 "p_CLKOS2_CPHASE": div - 1, "p_CLKOS2_FPHASE": 0,
                 "p_OUTDIVIDER_MUXC": "DIVC"}
        if sdram:               # half of div VCO cycles: div // 2 whole ones, 4/8 if div is odd
            extra.update({"p_CLKOS3_ENABLE": "ENABLED", "p_CLKOS3_DIV": div,
                          "p_CLKOS3_CPHASE": div - 1 + div // 2,
                          "p_CLKOS3_FPHASE": 4 * (div % 2), "p_OUTDIVIDER_MUXD": "DIVD"})
    return {**extra, "p_CLKI_DIV": clki, "p_CLKFB_DIV": fb, "p_FEEDBK_PATH": "CLKOP",
            "p_CLKOP_ENABLE": "ENABLED", "p_CLKOP_DIV": op_div, "p_CLKOP_CPHASE": op_div - 1,
            "p_CLKOP_FPHASE": 0, "p_CLKOS_ENABLE": "ENABLED", "p_CLKOS_DIV": 5 * op_div,
            "p_CLKOS_CPHASE": 5 * op_div - 1, "p_CLKOS_FPHASE": 0,
            "p_OUTDIVIDER_MUXA": "DIVA", "p_OUTDIVIDER_MUXB": "DIVB",
            "p_PLLRST_ENA": "DISABLED", "p_INTFB_WAKE": "DISABLED", "p_STDBY_ENABLE": "DISABLED",
            "p_DPHASE_SOURCE": "DISABLED", "p_PLL_LOCK_MODE": 0}


# Clock cycles the ULX3S top's SDRAM I/O adds to a READ's round trip (SdramConfig.pin_cycles):
# the commands' output registers in the I/O cells (1) and DQ captured half a cycle late, on
# CLKOS3, then re-registered by the controller's dq_i register a half cycle on (1).
SDRAM_PIN_CYCLES = 2


class ULX3SSdramIO(Elaboratable):
    """The SDRAM's and the SPI flash's pins of the ULX3S for ``core`` (docs/sdram.md, The
    pins on the ULX3S): every SDRAM output (CKE, CS#, RAS#, CAS#, WE#, BA, A, DQM, DQ and
    its output enable) in an I/O-cell register clocked by ``pipe`` (FFBuffer), the SDRAM
    clock from a DDR output register (ODDRX1F) sending 0 then 1 each ``pipe`` cycle, so its
    rising edge is mid-way in the cycle (the ``pipe`` clock inverted); DQ captured by a
    flip-flop clocked by ``sdram_rd`` (CLKOS3: ``pipe`` half a period later) after its input
    buffer, read by the controller's ``dq_i`` register in ``pipe``. The flash: SCLK through
    ``USRMCLK`` (the configuration clock pin is no user I/O), CS#, MOSI, MISO through plain
    buffers (the loader's outputs are registers; it samples MISO ``half_period - 1`` clocks
    after SCLK falls), HOLD# and WP# high."""

    def __init__(self, core: BoardCore):
        self.core = core

    def elaborate(self, platform):
        m, pins, spi = Module(), self.core.sdram_pins, self.core.spi
        sd = platform.request("sdram", 0, dir="-")
        m.submodules.sdram_clk = clk = io.DDRBuffer("o", sd.clk, o_domain="pipe")
        m.d.comb += [clk.o[0].eq(0), clk.o[1].eq(1)]       # low, then high: the inverted clock
        # the resource's cs, we, ras, cas are PinsN (active high here, inverted at the pin)
        outs = {"clk_en": pins.cke, "cs": ~pins.cs_n, "we": ~pins.we_n, "ras": ~pins.ras_n,
                "cas": ~pins.cas_n, "ba": pins.ba, "a": pins.a, "dqm": pins.dqm}
        for name, value in outs.items():
            m.submodules[f"sdram_{name}"] = buf = io.FFBuffer("o", getattr(sd, name),
                                                                  o_domain="pipe")
            m.d.comb += buf.o.eq(value)
        # DQ: output and output enable in the I/O cell's registers (``pipe``), as above; an
        # ECP5 I/O cell has one clock for all its registers (nextpnr refuses an IOLOGIC with
        # two), so the capture on ``sdram_rd`` is the flip-flop after the input buffer
        dq_in = Signal(len(pins.dq_i), name="sdram_dq_capture")
        for k in range(len(pins.dq_i)):
            q, t, i = Signal(name=f"sdram_dq_q{k}"), Signal(name=f"sdram_dq_t{k}"), \
                Signal(name=f"sdram_dq_i{k}")
            m.submodules[f"sdram_dq_o{k}"] = Instance(
                "OFS1P3DX", i_SCLK=ClockSignal("pipe"), i_SP=1, i_CD=0, i_D=pins.dq_o[k], o_Q=q)
            m.submodules[f"sdram_dq_oe{k}"] = Instance(
                "OFS1P3DX", i_SCLK=ClockSignal("pipe"), i_SP=1, i_CD=0, i_D=~pins.dq_oe, o_Q=t)
            m.submodules[f"sdram_dq_bb{k}"] = Instance("BB", i_I=q, i_T=t, o_O=i, io_B=sd.dq.io[k])
            m.d.sdram_rd += dq_in[k].eq(i)
        m.d.comb += pins.dq_i.eq(dq_in)

        fl = platform.request("spi_flash", 0, dir="-")
        m.submodules.usrmclk = Instance("USRMCLK", i_USRMCLKI=spi.sclk, i_USRMCLKTS=0,
                                        a_keep=1)
        for name, value in (("cs", ~spi.cs_n), ("copi", spi.mosi), ("hold", 0), ("wp", 0)):
            m.submodules[f"flash_{name}"] = buf = io.Buffer("o", getattr(fl, name))
            m.d.comb += buf.o.eq(value)
        m.submodules.flash_cipo = cipo = io.Buffer("i", fl.cipo)
        m.d.comb += spi.miso.eq(cipo.i)
        return m


class ULX3STop(Elaboratable):
    """The ULX3S top (``ULX3S_85F_Platform``): PLL, reset from its lock, the core on the
    ``hdmi`` pins (DDR), LEDs 0/1: underflow / order error, LED 7: light step bit 4. With
    the map in the SDRAM, :class:`ULX3SSdramIO` on the ``sdram`` and ``spi_flash`` pins, the
    PLL's CLKOS3 for the read capture (:func:`pll_params` with ``sdram``), LEDs 2/3: the
    flash copy done / its error; the core's SdramConfig must be made for the PLL's pipe
    clock (:func:`sdram_clock`) with ``pin_cycles`` = SDRAM_PIN_CYCLES, else BumpError."""

    def __init__(self, core: BoardCore):
        self.core = core
        if core.sdram is not None:
            cfg, pixel_hz = core.sdram, core.mode.pixel_hz
            _, hz = pll_pipe_divider(pixel_hz, core.pipe_hz, at_most=True)
            if not abs(hz - cfg.freq_mhz * 1e6) <= 1e-6 * hz:
                self._MustUse__silence = True          # refused: never to be elaborated
                raise BumpError(f"freq_mhz: the SdramConfig's clock must be the PLL's pipe clock "
                                f"{hz / 1e6:.6g} MHz (its timings and refresh are counted in its "
                                f"cycles), got {cfg.freq_mhz:.6g} MHz", "freq_mhz")
            if cfg.pin_cycles != SDRAM_PIN_CYCLES:
                self._MustUse__silence = True
                raise BumpError(f"pin_cycles must be {SDRAM_PIN_CYCLES} on the ULX3S top (its "
                                f"I/O registers), got {cfg.pin_cycles}", "pin_cycles")

    def elaborate(self, platform):
        m, core = Module(), self.core
        m.domains.sync = ClockDomain("sync")
        m.domains.shift = ClockDomain("shift")
        clk25 = platform.request("clk25", 0)
        locked = Signal()
        shift_clk, pixel_clk = Signal(name="pll_clkop"), Signal(name="pll_clkos")
        pipe_hz, sdram = self.core.pipe_hz, self.core.sdram is not None
        pipe = {}
        if pipe_hz is not None:          # the pipeline's own clock on CLKOS2
            m.domains.pipe = ClockDomain("pipe")
            pipe_clk = Signal(name="pll_clkos2")
            _, hz = pll_pipe_divider(self.core.mode.pixel_hz, pipe_hz, at_most=sdram)
            pipe = {"o_CLKOS2": pipe_clk, "a_FREQUENCY_PIN_CLKOS2": f"{hz / 1e6:g}"}
            m.d.comb += ClockSignal("pipe").eq(pipe_clk)
            m.submodules.rst_pipe = ResetSynchronizer(~locked, domain="pipe")
        if sdram:                        # the SDRAM's read capture on CLKOS3, 180 degrees on
            m.domains.sdram_rd = ClockDomain("sdram_rd", reset_less=True)
            rd_clk = Signal(name="pll_clkos3")
            pipe.update({"o_CLKOS3": rd_clk, "a_FREQUENCY_PIN_CLKOS3": f"{hz / 1e6:g}"})
            m.d.comb += ClockSignal("sdram_rd").eq(rd_clk)
        m.submodules.pll = Instance(
            "EHXPLLL", i_CLKI=clk25.i, i_CLKFB=shift_clk, i_RST=0, i_STDBY=0,
            i_PHASESEL0=0, i_PHASESEL1=0, i_PHASEDIR=0, i_PHASESTEP=0, i_PHASELOADREG=0,
            i_PLLWAKESYNC=0, i_ENCLKOP=0, i_ENCLKOS=0,
            o_CLKOP=shift_clk, o_CLKOS=pixel_clk, o_LOCK=locked,
            a_FREQUENCY_PIN_CLKI="25", a_FREQUENCY_PIN_CLKOP=f"{5 * self.core.mode.pixel_hz / 1e6:g}",
            a_FREQUENCY_PIN_CLKOS=f"{self.core.mode.pixel_hz / 1e6:g}",
            **pipe, **pll_params(self.core.mode.pixel_hz, pipe_hz=pipe_hz, sdram=sdram))
        m.d.comb += [ClockSignal("sync").eq(pixel_clk), ClockSignal("shift").eq(shift_clk)]
        m.submodules.rst_sync = ResetSynchronizer(~locked, domain="sync")
        m.submodules.rst_shift = ResetSynchronizer(~locked, domain="shift")
        # nextpnr derives both clocks' constraints from clk25's through the PLL
        m.submodules.core = core
        # the lanes' DDR registers: an ODDRX1F a pin before a plain output buffer, not the
        # platform's DDR buffer (xdr=2), whose output enable of an output-only pin comes
        # from two fabric flip-flops in the shift domain (Amaranth's ECP5 DDRBuffer), a
        # route to the I/O cell as long as 720p's shift period. The serializer's bits pass
        # PIN_STAGES more shift-domain registers on the way (every lane alike, the clock's
        # too): flip-flops of one input and one load each, which the placer spreads between
        # the serializer and the pins. The serializer sits near the encoders that feed it
        # (a word a lane from the pixel domain, routes nextpnr does not time), which may be
        # half the die from the HDMI pins: one register in between can still leave a route
        # longer than the period (docs/board.md).
        o0, o1 = core.o0, core.o1
        for k in range(PIN_STAGES):
            r0 = Signal.like(core.o0, name=f"hdmi_o0_s{k}", reset_less=True)
            r1 = Signal.like(core.o1, name=f"hdmi_o1_s{k}", reset_less=True)
            m.d.shift += [r0.eq(o0), r1.eq(o1)]
            o0, o1 = r0, r1
        hdmi = platform.request("hdmi", 0, dir="-")
        for name, port, bits in (("d", hdmi.d, range(3)), ("clk", hdmi.clk, [3])):
            m.submodules[f"hdmi_{name}"] = buf = io.Buffer("o", port)
            for k, lane in enumerate(bits):
                m.submodules[f"hdmi_{name}_ddr{k}"] = Instance(
                    "ODDRX1F", i_SCLK=ClockSignal("shift"), i_RST=0, i_D0=o0[lane],
                    i_D1=o1[lane], o_Q=buf.o[k])
        leds = [platform.request("led", n) for n in (0, 1, 7)]
        m.d.comb += [leds[0].o.eq(core.underflow), leds[1].o.eq(core.order_error),
                     leds[2].o.eq(core.source.frame[4] if len(core.source.frame) > 4 else 0)]
        if sdram:
            m.submodules.memory_pins = ULX3SSdramIO(core)
            done, error = platform.request("led", 2), platform.request("led", 3)
            m.d.comb += [done.o.eq(core.loader.done), error.o.eq(core.loader.error)]
        return m


class SimTop(wiring.Component):
    """The core for simulation: ``clk``/``rst`` (pixel) and ``shift_clk``/``shift_rst`` are
    ports; the DDR registers become ``shift_clk ? o0 : o1``. With the map in the SDRAM also
    ``pipe_clk``/``pipe_rst``, the SDRAM's pins ``sdram__*`` registered in ``pipe`` as the
    ULX3S top's I/O cells register them (every output once, DQ's input once more: the
    core's SdramConfig counts SDRAM_PIN_CYCLES), the flash's ``spi__*`` and
    ``display_shows`` (the display has started, at a frame's first pixel)."""

    def __init__(self, core: BoardCore):
        self.core = core
        ports = {"tmds_clk_p": wiring.Out(1), "tmds_data_p": wiring.Out(3),
                 "underflow": wiring.Out(1), "order_error": wiring.Out(1),
                 "light_step": wiring.Out(len(core.source.frame))}
        if core.sdram is not None:
            ports["sdram"] = wiring.Out(sdram_signature(core.sdram))
            if core.spi is not None:
                ports["spi"] = wiring.Out(spi_signature())
            ports["display_shows"] = wiring.Out(1)
        super().__init__(ports)

    def elaborate(self, platform):
        m, core = Module(), self.core
        m.submodules.core = core
        hi = ClockSignal("shift")
        m.d.comb += [self.tmds_data_p.eq(Mux(hi, core.o0[:3], core.o1[:3])),
                     self.tmds_clk_p.eq(Mux(hi, core.o0[3], core.o1[3])),
                     self.underflow.eq(core.underflow), self.order_error.eq(core.order_error),
                     self.light_step.eq(core.source.frame)]
        if core.sdram is not None:
            inner, pins = core.sdram_pins, self.sdram
            spi = self.spi if core.spi is not None else None
            idle = {"cke": 1, "cs_n": 1, "ras_n": 1, "cas_n": 1, "we_n": 1}
            for name in ("cke", "cs_n", "ras_n", "cas_n", "we_n", "ba", "a", "dqm", "dq_o",
                         "dq_oe"):
                reg = Signal.like(getattr(inner, name), init=idle.get(name, 0),
                                  name=f"io_{name}")
                m.d.pipe += reg.eq(getattr(inner, name))
                m.d.comb += getattr(pins, name).eq(reg)
            m.d.pipe += inner.dq_i.eq(pins.dq_i)
            if core.spi is not None:
                m.d.comb += [spi.sclk.eq(core.spi.sclk), spi.cs_n.eq(core.spi.cs_n),
                             spi.mosi.eq(core.spi.mosi), core.spi.miso.eq(spi.miso)]
            m.d.comb += self.display_shows.eq(core.shows)
        return m
