"""``bumprtl vectors``: stimulus and expected outputs for an emitted pipeline, with the
design and a self-checking Verilog testbench (gen/flow/vectors.py, gen/flow/vectors_tb.py)."""

import argparse
import re
import shlex
from pathlib import Path

from bumprtl.gen.cli.flags import (
    add_config_flags,
    add_map_flags,
    config_flags_only,
    config_from_args,
    map_overrides,
    scene_from_args,
)
from bumprtl.gen.flow.memories import DEFAULT_DEVICE, DEVICE_BRAM, LOADS, scene_command
from bumprtl.gen.flow.units import UNITS, canonical_command, default_module
from bumprtl.gen.flow.vectors import (
    DEFAULT_COUNT,
    MAX_COUNT,
    SOURCES,
    UNIT_SOURCES,
    check_count,
    pipeline_vectors,
    run_commands,
    unit_vectors,
    write_vectors,
)
from bumprtl.rtl.config import BumpError
from bumprtl.sim.scenes.config import BUILTIN

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")

EXAMPLES = """examples:
  bumprtl vectors --pipeline default --count 1000 --out build/vec
      the default scene's pipeline, 1000 random pixels; then in build/vec:
      iverilog -g2005 -s bumprtl_pipeline_tb -o tb.vvp bumprtl_pipeline_tb.v \\
          bumprtl_pipeline_named.v bumprtl_pipeline.v && vvp -n tb.vvp      -> PASS 1000
  bumprtl vectors --pipeline palette --source frame --load port --out build/vec_pal
  bumprtl vectors --height-map my_map.png --source my_pixels.csv --name my_bump --out build/mine
      your map and your own pixels: a CSV with a header row u,v,n_phi,n_theta,l_phi,
      l_theta,h_phi,h_theta[,tag] (texel coordinates; angles in radians, phi in [0, 2*pi],
      theta in [0, pi]; the columns of another scene: a wrong header lists them)
  bumprtl vectors --unit rotation --method lee --source frame --count 500 --out build/rot
      the rotation unit alone (module bumprtl_rotation_named), the default scene's pixels
  bumprtl vectors --pipeline default --load port --top my_top --out build/top
      a bench for your own top module my_top (the named ports' clk, rst, in_*, out_*),
      which loads the map through the host write port itself
"""


def _identifier(flag, value):
    if value is not None and (not _IDENT.fullmatch(value) or len(value) > 200):
        raise BumpError(f"{flag} must be a Verilog identifier (letters, digits, _; not starting "
                        f"with a digit), got {value!r}")
    return value


def _command(scene, args, module, top, count):
    """The ``bumprtl vectors`` line that reproduces the files (no output directory): the
    scene and its flags as emit's reproducing line gives them."""
    # the map's own flags too (emit's line leaves them out under --load port: the Verilog
    # is the same for every map; the expected outputs are not)
    emit = scene_command("pipeline", scene, "initial", module)
    scene_part = emit[len("bumprtl emit pipeline --scene "):]
    parts = [f"--source {shlex.quote(str(args.source))}", f"--count {count}",
             f"--seed {args.seed}"] + ([f"--load {args.load}"] if args.load == "port" else []) \
        + ([f"--top {top}"] if top else []) \
        + ([f"--device {args.device}"] if args.device not in (None, DEFAULT_DEVICE) else [])
    return f"bumprtl vectors --pipeline {scene_part} " + " ".join(parts)


def _unit_vectors(args, module):
    """``--unit``: the vectors of a datapath unit and the line that reproduces them."""
    if args.pipeline is not None:
        raise BumpError(f"--unit {args.unit} and --pipeline {args.pipeline}: give one of them")
    given = [*map_overrides(args), *(k for k in ("load", "top", "device")
                                     if getattr(args, k) is not None)]
    if given:
        raise BumpError(f"--{given[0].replace('_', '-')} applies to --pipeline (a scene's "
                        f"memories and host ports), not to --unit {args.unit}")
    config_flags_only(args, UNITS[args.unit].flags, f"--unit {args.unit}")
    cfg = config_from_args(args)
    vectors = unit_vectors(args.unit, cfg, args.source, args.count, args.seed)
    emit = canonical_command(UNITS[args.unit], cfg, module)
    flags = emit[len(f"bumprtl emit {args.unit}"):]
    return vectors, (f"bumprtl vectors --unit {args.unit}{flags} --source "
                     f"{shlex.quote(str(args.source))} --count {len(vectors)} --seed {args.seed}")


def _scene_flags_used(args, scene):
    """Refuse a scene flag that changes neither the design nor the pixels: the surface a map
    is wrapped on shapes only the scene's own frame, and a per-pixel scene has no colour
    table."""
    if args.geometry is not None and args.source != "frame":
        raise BumpError(f"--geometry shapes the scene's frame (--source frame), not --source "
                        f"{args.source}")
    if args.palette_size is not None and scene.shading == "per-pixel":
        raise BumpError("--palette-size does not apply to a scene with per-pixel shading "
                        "(no colour table)")


def run(args):
    module = _identifier("--name", args.name) or default_module(args.unit or "pipeline")
    top = _identifier("--top", args.top)
    if args.count is not None:
        check_count(args.count)
    if args.unit is not None:
        vectors, command = _unit_vectors(args, module)
    else:
        pipeline = args.pipeline or "default"
        if pipeline not in BUILTIN and not Path(pipeline).is_file():
            raise BumpError(f"--pipeline must be a scene TOML file or one of "
                            f"{', '.join(BUILTIN)}, got {pipeline!r}")
        scene = scene_from_args(args, pipeline)
        _scene_flags_used(args, scene)
        vectors = pipeline_vectors(scene, args.source, args.count, args.seed)
        command = _command(scene, args, module, top, len(vectors))
    paths = write_vectors(vectors, args.out, module, args.load or "initial", top,
                          args.device or DEFAULT_DEVICE, command)
    print(f"wrote {len(paths)} files to {args.out}: {module}_tb.v, the design "
          f"({module}.v, {module}_named.v) and {len(vectors)} pixels' stimulus and expected "
          f"words ({module}_in_*.hex, {module}_out_*.hex)")
    print(f"run it in {args.out}:")
    for sim, line in run_commands(module, top).items():
        print(f"  {sim:<9} {line}")
    return 0


def add_parser(sub):
    sources = ", ".join(SOURCES)
    p = sub.add_parser("vectors", help="test vectors and a self-checking Verilog bench for an "
                                       "emitted pipeline",
                       description="Write the pipeline of a scene (as `bumprtl emit pipeline "
                                   "--ports named`; or a datapath unit, --unit), stimulus and the bit-exact golden model's "
                                   "expected outputs as $readmemh files (one per field), and "
                                   "NAME_tb.v, a self-checking plain Verilog-2005 bench for "
                                   "Icarus and Verilator: input gaps and output backpressure "
                                   "from a seeded LFSR, every output field of every pixel "
                                   "compared in order, one last line PASS n or FAIL (the "
                                   "first mismatch: pixel, field, got, expected), a timeout if "
                                   "the pipeline hangs.\n\n" + EXAMPLES,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--pipeline", default=None, metavar="FILE|NAME",
                   help="the scene class: a built-in scene (sim/scenes/config.py) or a TOML "
                        "file, as emit --scene and render --pipeline (default: default)")
    p.add_argument("--unit", default=None, choices=sorted(UNIT_SOURCES),
                   help="a datapath unit instead of a pipeline, as bumprtl emit UNIT names it, "
                        "with the Config flags (--method, --angle-bits, ...); rotation takes "
                        "every source, illumination frame or random (its inputs are the "
                        "rotation's outputs of those pixels)")
    p.add_argument("--source", default="random", metavar="frame|random|FILE",
                   help=f"the pixels: one of {sources} (the scene's own frame, the stimulus "
                        f"render streams; seeded random valid pixels), or a .csv (header row) "
                        f"or .npy file of your pixels as physical values: texel coordinates u, "
                        f"v, angles in radians (default: random)")
    p.add_argument("--count", type=int, default=None, metavar="N",
                   help=f"pixels, in [1, {MAX_COUNT}] (default: {DEFAULT_COUNT}; with a file "
                        f"every row)")
    p.add_argument("--seed", type=int, default=1, metavar="S",
                   help="seed of --source random and the bench's default LFSR seed (the gaps "
                        "and stalls; +seed=N at run time changes it) (default: 1)")
    p.add_argument("--out", type=Path, default=Path("build/vectors"),
                   help="output directory (default: build/vectors)")
    p.add_argument("--name", default=None, metavar="PREFIX",
                   help="module and file prefix, as emit's --name (default: bumprtl_pipeline)")
    p.add_argument("--load", default=None, choices=LOADS,
                   help="initial: the map is the design's own initial contents; port: the "
                        "bench writes NAME_map.hex through the host write port first "
                        "(default: initial)")
    p.add_argument("--top", default=None, metavar="MODULE",
                   help="the bench instantiates your top module MODULE (the named ports' clk, "
                        "rst, in_*, out_*; it loads its memories itself) instead of "
                        "NAME_named")
    p.add_argument("--device", default=None, choices=sorted(DEVICE_BRAM),
                   help=f"refuse memories that do not fit this ECP5's block RAM (default: "
                        f"{DEFAULT_DEVICE})")
    add_map_flags(p)
    add_config_flags(p)
    p.set_defaults(func=run)
