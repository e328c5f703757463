"""Block-RAM contents of a scene's pipeline (or fetch unit) as ``$readmemh`` files, the
word layout of each memory, and whether the memories fit a device's block RAM.

``bumprtl emit pipeline|fetch`` writes, beside ``<unit>.v`` and ``<unit>.json``, one file
per memory: ``<unit>_map.hex`` (the bump vector map or palette index map), with a colour
texture ``<unit>_texture.hex``, with palette shading ``<unit>_lut.hex`` (the colour table of
one frame). Each file holds one word per line in hexadecimal, without address markers or
comments, word 0 first: what Verilog's ``$readmemh`` (and every FPGA flow's memory
initialisation) reads. The sidecar's ``memory_images`` gives each file's depth, width,
word layout and, with ``load = "port"``, host write port. The Verilog takes the contents
either as its built-in initial contents (``load = "initial"``, the same words as the file;
the map and texture then have no write port at all: not in the module, the named wrapper or
the sidecar) or through the host write port (``load = "port"``: the memory starts at zero
and the host writes word ``a`` of the file at address ``a``, one per clock, before the first
pixel). The palette colour table is always written through its port.
"""

import math
from pathlib import Path

import numpy as np

from bumprtl.gen.flow.emit import emit, port_table
from bumprtl.gen.flow.fpga import DEVICES
from bumprtl.gen.flow.units import UNITS, name_flag, unit_memories
from bumprtl.rtl.bumpfetch import TEXEL_BITS, BumpMapFetch, level_bases, memory_depth
from bumprtl.rtl.cache import scene_geometry, scene_levels, tiled_image
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.palette import index_bits
from bumprtl.rtl.pipe import DP16KD_MODES
from bumprtl.rtl.pipeline import BumpPipeline
from bumprtl.rtl.sidecar import from_facts
from bumprtl.sim.scenes.config import load_scene_config

__all__ = ["LOADS", "DEFAULT_DEVICE", "DEVICE_BRAM", "BRAM_BITS", "BRAM_SHAPES", "bram_blocks", "map_blocks",
           "table_blocks", "memory_blocks",
           "check_fits", "check_scene_fits", "hex_text", "memory_images", "emit_scene_unit", "host_writes",
           "has_write_port", "image_records",
           "scene_command"]

LOADS = ("initial", "port")

DEFAULT_DEVICE = "LFE5U-85F"
# ECP5 block RAM: DP16KD blocks of 18 kbit per device (Lattice ECP5 family data sheet,
# "EBR SRAM blocks"; nextpnr-ecp5's utilization report lists the same counts).
DEVICE_BRAM = {"LFE5U-25F": 56, "LFE5U-45F": 108, "LFE5U-85F": 208}
BRAM_BITS = 18 * 1024
BRAM_SHAPES = ((16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36))  # depth x width
if set(DEVICE_BRAM) != set(DEVICES):
    raise ImportError("gen/flow/memories.py DEVICE_BRAM must list the devices of gen/flow/fpga.py")

# memory name (last part of the sidecar's ``roms`` key) -> host write port prefix, per unit
_PORTS = {"pipeline": {"map": "map_", "texture": "tex_", "lut": "lut_"},
          "fetch": {"map": "", "texture": "tex_"}}


def bram_blocks(depth, width):
    """DP16KD blocks a ``depth`` x ``width`` memory needs: the cheapest tiling by one of
    the block's aspect ratios (:data:`BRAM_SHAPES`)."""
    return min(math.ceil(depth / d) * math.ceil(width / w) for d, w in BRAM_SHAPES)


def _is_map(name):
    return name.split(".")[-1] in ("map", "texture")


def table_blocks(depth, width):
    """DP16KD blocks of a table as rtl/pipe.RegisteredROM lays it out on ECP5: a table of
    2**n + 1 words keeps its last word in a flip-flop, the rest sits in the widest DP16KD
    mode that holds every word in one block, blocks side by side for the width."""
    n = depth - 1
    return map_blocks(n if n > 1 and n & (n - 1) == 0 else depth, width)


def map_blocks(depth, width):
    """DP16KD blocks of a map as rtl/pipe.RegisteredRAM lays it out on ECP5: the widest
    DP16KD mode that holds every word in one block, blocks side by side for the width; a map
    deeper than any mode is left to Yosys, counted in its cheapest tiling."""
    bits = next((b for b, d, _ in DP16KD_MODES if d >= depth), None)
    return bram_blocks(depth, width) if bits is None else math.ceil(width / bits)


def memory_blocks(roms):
    """``(map blocks, table blocks)``: the DP16KD blocks of the maps of ``roms`` (the
    sidecar's memories, :func:`map_blocks`) and of its other memories, the pipeline's tables
    (:func:`table_blocks`), each counted as laid out on ECP5."""
    maps = sum(map_blocks(v["depth"], v["width"]) for k, v in roms.items() if _is_map(k))
    tables = sum(table_blocks(v["depth"], v["width"]) for k, v in roms.items() if not _is_map(k))
    return maps, tables


def check_fits(roms, device, what):
    """Raise a BumpError (naming ``what``, the bits it needs and the device's block RAM) when
    the maps of ``roms`` (the sidecar's memories, :func:`map_blocks`) and the pipeline's
    tables (:func:`table_blocks`), each counted as laid out on ECP5, do not fit ``device``. Returns
    ``(blocks needed, blocks available)``."""
    if device not in DEVICE_BRAM:
        raise BumpError(f"device must be one of {', '.join(DEVICE_BRAM)}, got {device!r}")
    map_bits = sum(v["bits"] for k, v in roms.items() if _is_map(k))
    maps_need, other = memory_blocks(roms)
    have = DEVICE_BRAM[device]
    if maps_need + other > have:
        raise BumpError(f"{what}: the map needs {map_bits:,} bits of block RAM ({maps_need} "
                        f"DP16KD of 18 kbit) beside {other} for the pipeline's tables; "
                        f"{device} has {have} DP16KD of 18 kbit ({have * BRAM_BITS:,} bits)")
    return maps_need + other, have


def check_scene_fits(scene, device, unit="pipeline"):
    """:func:`check_fits` for the memories of ``scene``'s pipeline (or fetch unit)."""
    build = BumpPipeline if unit == "pipeline" else BumpMapFetch
    roms = unit_memories(build(scene.hardware))
    if scene.map_memory == "axi" and device in DEVICE_BRAM:
        cache = {k: v for k, v in roms.items() if k.startswith("fetch.cache_")}
        need, other = memory_blocks(cache)[1], memory_blocks(roms)[1] - memory_blocks(cache)[1]
        if need + other > DEVICE_BRAM[device]:
            raise BumpError(f"cache_sets x cache_ways = {scene.cache_sets} x {scene.cache_ways} "
                            f"lines need {need} DP16KD of 18 kbit beside {other} for the "
                            f"pipeline's tables; {device} has {DEVICE_BRAM[device]}: fewer sets "
                            f"or ways", "cache_sets")
    return check_fits(roms, device, scene.picture or scene.name)


def hex_text(words, width):
    """``$readmemh`` text: one word per line, ``ceil(width / 4)`` hex digits, word 0 first."""
    digits = max(1, (width + 3) // 4)
    return "".join(f"{int(w):0{digits}x}\n" for w in np.asarray(words, np.int64).tolist())


def _width_name(scene):
    """What the layouts call the map's width: T (a square map) or W (W x H)."""
    return "T" if scene.square else "W"


def _layout(name, scene):
    a, lv, t = scene.angle_bits, level_bases(scene), _width_name(scene)
    size = (f"T = {scene.texture_size}" if scene.square else
            f"W = {scene.texture_size}, H = {scene.map_height} (v in [0, H >> l))")
    where = (f"texel (u, v) of mip level l at word level_bases[l] + v * ({t} >> l) + u, "
             f"{size}, level_bases = {lv}")
    if name == "map" and scene.shading == "palette":
        return f"palette index of the texel's quantized normal (Tarini Sec. 4), {index_bits(scene.config)} bits; {where}"
    if name == "map":
        return (f"N' of the texel as binary angles (Lee Sec. 2, bump vector map): phi in bits "
                f"[{a - 1}:0], theta in bits [{2 * a - 1}:{a}] (full circle = 2^{a}); {where}")
    if name == "texture":
        return f"RGB colour texel, r in bits [7:0], g [15:8], b [23:16]; {where}"
    return ("colour-table entry i (palette normal i shaded for one frame): r [7:0], g [15:8], "
            "b [23:16], a [31:24] (Lambert intensity, Tarini Sec. 5.1); written through lut_w_* "
            "(a write is taken when lut_w_ready is high), then lut_swap (double-buffered), "
            "never initial contents")


def memory_images(unit, scene, words, texels=None, table=None, load="initial"):
    """``{name: {"words", "width", "file", "layout", "port", "load"}}`` of the unit's memories
    (``unit``: ``pipeline`` or ``fetch``)."""
    if load not in LOADS:
        raise BumpError(f"load must be one of {', '.join(LOADS)}, got {load!r}")
    ports = _PORTS[unit]
    out = {}
    if words is not None:
        width = index_bits(scene.config) if scene.shading == "palette" else 2 * scene.angle_bits
        out["map"] = (words, width)
    if texels is not None:
        out["texture"] = (texels, TEXEL_BITS)
    if table is not None and "lut" in ports:
        out["lut"] = (table, 4 * scene.config.color_bits)
    images = {}
    for name, (w, width) in out.items():
        w = np.asarray(w, np.int64)
        depth = memory_depth(scene) if name != "lut" else len(w)
        if len(w) != depth:
            raise BumpError(f"{name} has {len(w)} words, the memory holds {depth}")
        p = ports[name]
        if name == "map" and scene.map_memory == "axi":
            images[name] = _axi_image(unit, scene, w, width, depth)
            continue
        images[name] = {"words": w, "width": width, "depth": depth,
                        **(_map_size(scene) if name != "lut" else {}),
                        "file": f"{unit}_{name}.hex", "layout": _layout(name, scene),
                        "port": [f"{p}w_en", f"{p}w_addr", f"{p}w_data"] +
                                (["lut_w_ready", "lut_swap"] if name == "lut" else []),
                        "load": "port" if name == "lut" else load}
    return images


def _axi_image(unit, scene, words, width, depth):
    """The map of a ``map_memory = "axi"`` pipeline: ``<unit>_map.bin``, the bytes the user
    puts in memory from ``base`` on (rtl/cache.tiled_image; the scene's cache geometry): N'
    angle pairs, or a palette scene's indices, each in a ``slot_bytes`` slot."""
    g = scene_geometry(scene.hardware)
    return {"words": words, "width": width, "depth": depth, **_map_size(scene),
            "file": f"{unit}_map.bin",
            "load": "axi", "base": g.base, "bytes": g.image_bytes, "slot_bytes": g.slot_bytes,
            "bin": tiled_image(g, scene_levels(scene, words)),
            "layout": (f"tiled (rtl/cache.tiled_layout): level l's texels in lines of "
                       f"{g.block} x {g.block} texels ({g.line_bytes} bytes, one AXI INCR burst "
                       f"of {g.beats} x {g.data_bits} bits), lines row-major, levels one after "
                       f"the other (first lines {g.level_lines}); texel (u, v) of level l at "
                       f"byte base + line * {g.line_bytes} + ((v mod {g.block}) * {g.block} + "
                       f"(u mod {g.block})) * {g.slot_bytes}, line = first line of l + "
                       f"(v div {g.block}) * max(1, ({_width_name(scene)} >> l) / {g.block}) + "
                       f"(u div {g.block}); "
                       f"each texel little-endian in its {g.slot_bytes}-byte slot, as in "
                       f"block RAM: {_layout('map', scene).split('; texel (u, v)')[0]}")}


def _map_size(scene):
    """The sidecar's record of the map's size: texels of level 0, width and height."""
    return {"map_width": scene.texture_size, "map_height": scene.map_height}


def image_records(images, write_port):
    """The sidecar's ``memory_images``: each image without its words; the map's and the
    texture's ``port`` only where the unit has it (``write_port``)."""
    return {n: {k: v for k, v in img.items() if k not in ("words", "bin") and
                (k != "port" or write_port or n == "lut")} for n, img in images.items()}


def host_writes(images, meta):
    """Host set-up cycles (``{port: value}`` per clock) that write the map and texture
    images with ``load = "port"`` through their write ports, word ``a`` at address ``a``.
    (The palette colour table belongs to a frame: its set-up writes it.)"""
    cycles = []
    for name, img in images.items():
        if img["load"] != "port" or name == "lut":
            continue
        en, addr, data = img["port"][:3]
        if en not in meta.ports:
            raise BumpError(f"the emitted unit has no {en} port for the {name} image")
        cycles += [{en: 1, addr: a, data: int(w)} for a, w in enumerate(img["words"].tolist())]
    return cycles


# Scene keys with a command-line flag of ``bumprtl emit`` (gen/cli/flags.py), in this order.
_FLAG_KEYS = ("height_map", "normal_map", "normal_convention", "geometry", "height_scale",
              "resample", "texture_size", "method", "angle_bits", "frac_bits", "tag_bits",
              "spec_exponent", "spec_index_bits", "ka", "kd", "ks", "lights", "specular",
              "palette_size", "map_memory", "cache_sets", "cache_ways", "cache_block",
              "axi_data_bits", "cache_queue", "cache_outstanding")


_PICTURE_FLAGS = ("height_map", "normal_map", "normal_convention", "geometry", "height_scale",
                  "resample")


def scene_command(unit, scene, load="initial", module=None, picture=False):
    """The ``bumprtl emit`` line that reproduces ``unit``'s Verilog for ``scene``: ``--scene
    NAME`` plus a flag for every key with a flag that differs from the named scene's. With
    ``load = "port"`` the Verilog holds no map, so the keys that only shape the map's
    contents are left out: every map of one size gives the same Verilog; ``picture`` keeps
    them (the memory images do depend on them: the sidecar's full command)."""
    parts = ["bumprtl", "emit", unit, "--scene", scene.name]
    try:
        base = load_scene_config(scene.name)
    except BumpError:                                  # a scene built in code: no source
        base = None
    for key in _FLAG_KEYS if base is not None else ():
        if load == "port" and key in _PICTURE_FLAGS and not picture:
            continue
        value = getattr(scene, key)
        if value == getattr(base, key) or value is None:
            continue
        flag = "--" + key.replace("_", "-")
        if isinstance(value, bool):
            parts.append(flag if value else "--no-" + key.replace("_", "-"))
        else:
            parts += [flag, str(value)]
    if load != "initial":
        parts += ["--load", load]
    return " ".join(parts) + name_flag(unit, module)


def has_write_port(images):
    """The map or texture of ``images`` (:func:`memory_images`) is loaded through the host
    write port (``load = "port"``); with ``load = "initial"`` the unit has no such port."""
    return any(img["load"] == "port" for n, img in images.items() if n != "lut")


def emit_scene_unit(unit, scene, out_dir, images, device=DEFAULT_DEVICE, command=None,
                    module=None, write_port=None):
    """Build ``unit`` (``pipeline`` or ``fetch``) of ``scene`` with the ``images`` of
    :func:`memory_images` (built-in initial contents where ``load = "initial"``), check its
    memories fit ``device`` (``None``: no check), then write ``<unit>.v``, ``<unit>.json``
    (with ``memory_images``) and one ``$readmemh`` file per image. Returns the paths
    ``(v, json, [hex...])``; nothing is written when a check fails. ``module`` (default
    ``unit``) names the top module and every file, the images ``<module>_<memory>.hex``.
    ``write_port`` (default :func:`has_write_port`): the map's and texture's host write
    ports; True with initial contents is the testbenches' unit whose built-in map the host
    overwrites in part (no ``bumprtl emit`` flag gives it)."""
    init = lambda n: images[n]["words"] if n in images and images[n]["load"] == "initial" else None
    spec = UNITS[unit]
    build = BumpPipeline if unit == "pipeline" else BumpMapFetch
    write_port = has_write_port(images) if write_port is None else write_port
    fit = None
    if device is not None:                      # before building a large map's contents
        fit = check_scene_fits(scene, device, unit)
    dut = build(scene.hardware, init=init("map"), texture=init("texture"), write_port=write_port)
    facts = {"config": scene.config.to_dict(), **spec.sidecar(scene, dut)}
    if fit is not None:
        facts["block_ram"] = {"device": device, "dp16kd_needed": fit[0],
                                "dp16kd_available": fit[1],
                                "note": "maps tiled into DP16KD shapes, one block per other table"}
    if module is not None:
        images = {n: {**img, "file": f"{module}_{n}{Path(img['file']).suffix}"}
                  for n, img in images.items()}
    facts["memory_images"] = image_records(images, write_port)
    texts = {img["file"]: img["bin"] if "bin" in img else hex_text(img["words"], img["width"])
             for img in images.values()}
    load = images["map"]["load"] if "map" in images and "bin" not in images["map"] else "initial"
    command = command or scene_command(unit, scene, load, module)
    v, j = emit(dut, unit, command, out_dir, from_facts(unit, command, port_table(dut), facts),
                flatten=True, module=module)
    paths = []
    for name, text in texts.items():
        path = Path(out_dir) / name
        path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text)
        paths.append(path)
    return v, j, paths
