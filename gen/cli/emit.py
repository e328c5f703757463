"""``bumprtl emit UNIT``: write ``UNIT.v`` and its ``UNIT.json`` sidecar."""

from pathlib import Path

from bumprtl.gen.flow.units import SCENE_UNITS, UNITS, emit_unit


def run(args):
    from bumprtl.gen.cli.flags import config_from_args
    from bumprtl.gen.flow.emit import lint
    cfg = config_from_args(args)
    if args.unit in SCENE_UNITS:                     # built from a SceneConfig, not flags
        from bumprtl.rtl.scene import load_scene_config
        cfg = load_scene_config(args.scene)
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
    from bumprtl.gen.cli.flags import add_config_flags
    units = "\n".join(f"  {u.name:<14} {u.help}" for u in UNITS.values())
    p = sub.add_parser("emit", help="emit a unit's Verilog and JSON sidecar",
                       description="Emit synthesizable Verilog (deterministic, first line is "
                                   "the command that reproduces it) and a JSON sidecar with "
                                   "the config, ports, latency, ROM sizes and error bound.\n\n"
                                   f"units:\n{units}",
                       formatter_class=__import__("argparse").RawDescriptionHelpFormatter)
    p.add_argument("unit", choices=sorted(UNITS), metavar="UNIT", help="unit to emit (see above)")
    p.add_argument("--out", type=Path, default=Path("build/emit"), help="output directory (default: build/emit)")
    p.add_argument("--lint", action="store_true", help="run verilator --lint-only -Wall (DESIGN §5 waivers) afterwards")
    p.add_argument("--scene", default="default", metavar="FILE|NAME",
                   help="pipeline/fetch: a scene TOML file or built-in scene (default: default)")
    add_config_flags(p)
    p.set_defaults(func=run)
