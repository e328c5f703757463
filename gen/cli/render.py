"""``bumprtl render``: the flags, their refusals and the output lines; the pictures come from
gen/render/images.py (float64 and fixed-point models) and gen/render/rtl.py (``--rtl``)."""

import argparse
import time
from pathlib import Path

from bumprtl.gen.cli.flags import add_config_flags, add_map_flags, scene_from_args
from bumprtl.gen.flow.memories import DEFAULT_DEVICE, DEVICE_BRAM, LOADS
from bumprtl.gen.render.images import (
    FIXED_METHODS,
    MODELS,
    PALETTE,
    QUANTIZERS,
    fixed_image,
    palette_note,
    render_methods,
    shade_scene,
)
from bumprtl.gen.render.rtl import rtl_render_png, sim_scene
from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.methods import PER_PIXEL
from bumprtl.sim.scenes import SCENES
from bumprtl.sim.scenes.config import SceneConfig
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png

__all__ = ["render_scene", "run", "add_parser"]


def _palette_opts(args):
    opts = {k: getattr(args, k) for k in ("quantizer", "lighting") if getattr(args, k) is not None}
    if opts and (args.render_method != PALETTE or args.model != "float64" or args.rtl):
        raise BumpError(f"--{next(iter(opts))} applies to --method palette with --model float64 "
                        f"only, not {args.render_method} ({'rtl' if args.rtl else args.model})")
    return opts


def _light(args):
    return {"azimuth": args.light_azimuth, "light_elevation": args.light_elevation,
            "light": args.light}


def render_scene(args, rtl=False) -> SceneConfig:
    """The scene a render draws: ``--pipeline`` (a scene class or TOML) or ``--scene`` (an
    image name, or a TOML file), with the map, method and Config flags that were given; a
    flag that contradicts the TOML is an error naming both. Without ``rtl`` the map is
    image-sized unless the scene, the map or a flag says otherwise."""
    source, extra = args.pipeline, {}
    if args.scene is not None:
        if Path(args.scene).suffix.lower() == ".toml":
            if source is not None:
                raise BumpError(f"--scene {args.scene} and --pipeline {source}: give the scene "
                                f"TOML once")
            source = args.scene
        elif args.scene in SCENES:
            extra["image"] = args.scene
        elif Path(args.scene).suffix.lower() in (".png", ".npy"):
            raise BumpError(f"--scene {args.scene}: a map file goes to --height-map FILE "
                            f"(greyscale heights) or --normal-map FILE (RGB normals)")
        else:
            raise BumpError(f"--scene must be one of {', '.join(SCENES)} or a scene TOML file, "
                            f"got {args.scene!r}")
    if args.render_method is not None and (rtl or args.model == "fixed"):
        name = FIXED_METHODS.get(args.render_method)
        if name in PER_PIXEL:
            extra["method"] = name
        elif name == PALETTE:
            extra["shading"] = "palette"
        elif rtl:
            raise BumpError(f"--method {args.render_method} with --rtl: a scene pipeline is built for "
                            f"exact, lee_corrected (lee) or palette")
    defaults = None if rtl else {"texture_size": args.size}
    return scene_from_args(args, source or "default", extra, defaults,
                           {"image": "--scene", "method": "--method", "shading": "--method"})


def run(args):
    if args.rtl:                                   # through the emitted pipeline (gen/render/rtl.py)
        if args.model != "float64":
            raise BumpError("--rtl renders through the hardware; --model applies without --rtl")
        args.simulator = args.simulator or "verilator"
        return rtl_render_png(render_scene(args, rtl=True), args.size, args.out, args.simulator,
                              device=args.device or DEFAULT_DEVICE, per_cycle=args.per_cycle,
                              load=args.load or "initial", verbose=args.verbose, **_light(args))
    rtl_only = {"--load": args.load is not None, "--device": args.device is not None,
                "--per-cycle": args.per_cycle, "--simulator": args.simulator is not None,
                "--verbose": args.verbose}
    if any(rtl_only.values()):
        raise BumpError(f"{next(k for k, v in rtl_only.items() if v)} applies to --rtl only "
                        f"(as --load, --device, --per-cycle, --simulator and --verbose)")
    if args.pipeline is not None and args.model != "fixed":
        raise BumpError("--pipeline applies to --rtl and --model fixed (the scene class the "
                        "hardware builds); the float64 models draw --scene")
    if args.palette_size is not None and (args.render_method or "exact") != PALETTE:
        raise BumpError(f"--palette-size applies to --method palette, not "
                        f"{args.render_method or 'exact'}")
    palette_opts = _palette_opts(args)
    scene = render_scene(args)
    t0 = time.perf_counter()
    if args.model == "fixed":
        args.render_method = args.render_method or "exact"
        img = fixed_image(scene, args.render_method, args.size, **_light(args))
        base = sim_scene(scene, args.size, args.light_azimuth,
                         light_elevation=args.light_elevation, light=args.light)
    else:
        args.render_method = args.render_method or "exact"
        if args.render_method not in render_methods():
            raise BumpError(f"--method must be one of {', '.join(render_methods())}, got {args.render_method!r}")
        base = sim_scene(scene, args.size, args.light_azimuth,
                         light_elevation=args.light_elevation, light=args.light)
        img = compose(base, shade_scene(base, args.render_method, scene.config, **palette_opts))
    elapsed = time.perf_counter() - t0
    out = save_png(args.out, img)
    print(f"{args.render_method} ({args.model}): {args.size}x{args.size} {scene.picture} (map "
          f"{scene.map_label}, {base.geometry}) in {elapsed:.2f} s "
          f"({args.size ** 2 / elapsed / 1e6:.2f} Mpix/s) -> {out}")
    if args.render_method == PALETTE and (note := palette_note(base, scene.config)):
        print(note)
    if args.compare:
        ref = compose(base, shade_scene(base, "conventional", scene.config))
        cmp_path = save_png(out.with_name(out.stem + "_compare.png"), panel(ref, img))
        print(f"vs conventional (float64): PSNR {psnr(ref, img):.2f} dB, max difference "
              f"{max_diff(ref, img)} (8-bit); panel reference | {args.render_method} | |diff| x10 -> {cmp_path}")
    return 0


def add_parser(sub):
    methods = render_methods()
    scenes = "\n".join(f"  {k:<12} {v[3]}" for k, v in SCENES.items())
    p = sub.add_parser("render", help="render a scene or your own bump map to PNG",
                       description=f"Render a bump-mapped scene: a procedural image or your own "
                                   f"height or normal map (--height-map / --normal-map), by a "
                                   f"float64 model, by the bit-exact fixed-point model of the "
                                   f"hardware (--model fixed) or through the RTL (--rtl).\n\n"
                                   f"scenes:\n{scenes}",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default=None, metavar="NAME|FILE.toml",
                   help="procedural image (default: bricks) or a scene TOML file")
    p.add_argument("--method", dest="render_method", default=None, metavar="METHOD",
                   help=f"one of {', '.join(methods)} (default: exact); with --model fixed one "
                        f"of {', '.join(FIXED_METHODS)}")
    p.add_argument("--model", default="float64", choices=MODELS,
                   help="float64: the method's float64 reference (default); fixed: its bit-exact "
                        "fixed-point model, the picture the hardware makes (rtl/methods.py, "
                        "sim/golden/fixed/)")
    p.add_argument("--size", type=int, default=512, help="image size, power of two in [16, 4096] (default: 512)")
    p.add_argument("--texture-size", type=int, default=None, metavar="T",
                   help="bump map size, power of two in [16, 4096] (default: your map's size, "
                        "else the scene's with --rtl, else the image size)")
    p.add_argument("--light-elevation", type=float, default=45.0, metavar="DEG",
                   help="light elevation above the screen plane, [-90, 90] (default: 45)")
    p.add_argument("--light-azimuth", type=float, default=30.0, metavar="DEG",
                   help="light azimuth in the screen plane, [-360, 360] (default: 30)")
    p.add_argument("--light", default="directional", choices=["directional", "point"],
                   help="a light at infinity in the direction of --light-elevation and "
                        "--light-azimuth, or a point light 3 radii away in it (default: directional)")
    p.add_argument("--out", type=Path, default=Path("build/render/render.png"), help="output PNG")
    p.add_argument("--compare", action="store_true",
                   help="also write reference | method | |diff| x10 and print PSNR / max diff vs conventional")
    p.add_argument("--quantizer", default=None, choices=QUANTIZERS,
                   help="palette method only (default: the palette model's)")
    p.add_argument("--lighting", default=None, metavar="NAME",
                   help="palette method only: a lighting model of sim/golden/float/palette.py "
                        "(Tarini Sec. 5.1; a bad name lists them)")
    p.add_argument("--rtl", action="store_true",
                   help="render through the emitted BumpPipeline with cocotb; checks it equals the golden render")
    p.add_argument("--simulator", default=None, choices=["verilator", "icarus"],
                   help="with --rtl (default: verilator)")
    p.add_argument("--verbose", action="store_true",
                   help="with --rtl: print the simulator's build and run output (by default it "
                        "goes to build/render_rtl/<scene>/tools.log, shown in full on a failure)")
    p.add_argument("--per-cycle", action="store_true",
                   help="with --rtl: drive every pixel from cocotb, clock by clock, instead of the "
                        "bulk path (sim/tb/bulk.py: arrays in, arrays out, cached build)")
    p.add_argument("--pipeline", default=None, metavar="FILE|NAME",
                   help="the scene class (sim/scenes/config.py built-in or TOML) to build with --rtl and "
                        "to model with --model fixed (default: default)")
    p.add_argument("--load", default=None, choices=LOADS,
                   help="with --rtl: the map as the Verilog's initial contents, or written "
                        "through the host write port before the first pixel (default: initial)")
    p.add_argument("--device", default=None, choices=sorted(DEVICE_BRAM),
                   help=f"with --rtl: refuse a map that does not fit this ECP5's block RAM "
                        f"(default: {DEFAULT_DEVICE})")
    add_map_flags(p)
    add_config_flags(p, fields=("spec_exponent", "ka", "kd", "ks", "specular", "palette_size"))
    p.set_defaults(func=run)
