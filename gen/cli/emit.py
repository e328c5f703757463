"""``bumprtl emit UNIT``: write ``UNIT.v`` and its ``UNIT.json`` sidecar."""

from pathlib import Path

from bumprtl.rtl.config import BumpError
from bumprtl.rtl.scene import load_scene_config
from bumprtl.gen.cli.flags import add_config_flags, config_from_args
from bumprtl.gen.flow.axis import emit_axis
from bumprtl.gen.flow.emit import lint
from bumprtl.gen.flow.units import SCENE_UNITS, UNITS, emit_unit


def run(args):
    cfg = config_from_args(args)
    if args.unit in SCENE_UNITS:                     # built from a SceneConfig, not flags
        cfg = load_scene_config(args.scene)
    if args.interface == "axis":
        v_path, j_path = emit_axis(args.unit, cfg, args.out, args.tdata_width)
    elif args.tdata_width is not None:
        raise BumpError("--tdata-width needs --interface axis")
    else:
        v_path, j_path = emit_unit(args.unit, cfg, args.out)
    print(f"wrote {v_path}")
    print(f"wrote {j_path}")
    if args.lint:
        problems = lint(v_path)
        for line in problems:
            print(line)
        print(f"lint: {'clean' if not problems else f'{len(problems)} problem(s)'}")
        return 1 if problems else 0
    return 0


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
    p.add_argument("--lint", action="store_true", help="run verilator --lint-only -Wall (with the three generator-artefact waivers) afterwards")
    p.add_argument("--scene", default="default", metavar="FILE|NAME",
                   help="pipeline/fetch: a scene TOML file or built-in scene (default: default)")
    p.add_argument("--interface", choices=("stream", "axis"), default="stream",
                   help="stream: Amaranth stream ports i__*/o__* (default); axis: AXI4-Stream "
                        "ports s_axis_*/m_axis_*, aclk/aresetn, tuser = tag, tlast passed "
                        "through with its pixel; writes UNIT_axis.v (rtl/axis.py)")
    p.add_argument("--tdata-width", type=int, default=None, metavar="BITS",
                   help="axis: width of both tdata buses, a multiple of 8 (default: the wider "
                        "payload rounded up to whole bytes); too narrow is refused")
    add_config_flags(p)
    p.set_defaults(func=run)
