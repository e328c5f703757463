"""``bumprtl render``: render a scene with one method; ``--compare`` against conventional."""

import argparse
import importlib
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from bumprtl.rtl.config import BumpError
from bumprtl.sim.golden.float.models import FLOAT_MODELS
from bumprtl.sim.scenes import load_scene, SCENES
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png
from bumprtl.gen.cli.flags import add_config_flags, config_from_args
from bumprtl.gen.render.rtl import cli_render

__all__ = ["PALETTE", "render_methods", "shade_scene", "add_parser"]

ROWS_PER_CHUNK = 32
PROGRESS_PIXELS = 1 << 20          # show a progress bar from 1024 x 1024 pixels on
PALETTE = "palette"                # Tarini et al.'s quantized normal map (sim/golden/float/palette.py)
QUANTIZERS = ("median-cut", "kmeans")


def render_methods():
    """Every method ``render`` accepts: the float64 golden models, then ``palette``."""
    return [*FLOAT_MODELS, PALETTE]


def _render_palette(scene, cfg, palette_opts):
    try:
        palette = importlib.import_module("bumprtl.sim.golden.float.palette")
    except ImportError as e:
        raise BumpError(f"method palette needs bumprtl.sim.golden.float.palette, which this "
                        f"checkout does not have ({e})") from None
    return np.asarray(palette.render_palette(scene, cfg, palette_size=cfg.palette_size,
                                             **palette_opts).color, dtype=np.float64)


def shade_scene(scene, method, cfg, progress=True, **palette_opts):
    """Per-pixel float intensity of ``scene`` by ``method``.

    A float64 model renders in row chunks of ``ROWS_PER_CHUNK`` with a progress bar on long
    renders; ``palette`` shades the whole bump map at once (``palette_opts``: ``quantizer``,
    ``lighting``, passed through to ``render_palette``).
    """
    if method == PALETTE:
        return _render_palette(scene, cfg, palette_opts)
    if method not in FLOAT_MODELS:
        raise BumpError(f"method must be one of {', '.join(render_methods())}, got {method!r}")
    model, size = FLOAT_MODELS[method], scene.size
    out = np.zeros((size, size))
    with tqdm(total=size * size, unit="pix", unit_scale=True, desc=method, leave=False,
              disable=not progress or size * size < PROGRESS_PIXELS) as bar:
        for r0 in range(0, size, ROWS_PER_CHUNK):
            rows = slice(r0, min(size, r0 + ROWS_PER_CHUNK))
            out[rows] = model(scene.px.subset(rows), cfg).color
            bar.update(out[rows].size)
    return out


def _palette_opts(args):
    opts = {k: getattr(args, k) for k in ("quantizer", "lighting") if getattr(args, k) is not None}
    if opts and args.model != PALETTE:
        raise BumpError(f"--{next(iter(opts))} applies to --method palette only, not {args.model}")
    return opts


def run(args):
    if args.rtl:                                   # through the emitted pipeline (gen/render/rtl.py)
        return cli_render(args)
    cfg, palette_opts = config_from_args(args), _palette_opts(args)
    scene = load_scene(args.scene, size=args.size, light_elevation=args.light_elevation,
                       light_azimuth=args.light_azimuth, light=args.light,
                       texture_size=args.texture_size)
    t0 = time.perf_counter()
    img = compose(scene, shade_scene(scene, args.model, cfg, **palette_opts))
    elapsed = time.perf_counter() - t0
    out = save_png(args.out, img)
    print(f"{args.model}: {args.size}x{args.size} {args.scene} in {elapsed:.2f} s "
          f"({args.size ** 2 / elapsed / 1e6:.2f} Mpix/s) -> {out}")
    if args.compare:
        ref = compose(scene, shade_scene(scene, "conventional", cfg))
        cmp_path = save_png(out.with_name(out.stem + "_compare.png"), panel(ref, img))
        print(f"vs conventional: PSNR {psnr(ref, img):.2f} dB, max difference "
              f"{max_diff(ref, img)} (8-bit); panel reference | {args.model} | |diff| x10 -> {cmp_path}")
    return 0


def add_parser(sub):
    methods = render_methods()
    scenes = "\n".join(f"  {k:<12} {v[3]}" for k, v in SCENES.items())
    p = sub.add_parser("render", help="render a scene to PNG with one method",
                       description=f"Render a bump-mapped scene with a golden model.\n\nscenes:\n{scenes}",
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default="bricks", choices=list(SCENES), metavar="NAME",
                   help="scene name (default: bricks)")
    p.add_argument("--method", dest="model", default="exact", choices=methods, metavar="METHOD",
                   help=f"one of {', '.join(methods)} (default: exact)")
    p.add_argument("--size", type=int, default=512, help="image size, power of two in [16, 4096] (default: 512)")
    p.add_argument("--texture-size", type=int, default=None, metavar="T",
                   help="bump map size, power of two in [16, 4096] (default: the image size)")
    p.add_argument("--light-elevation", type=float, default=45.0, metavar="DEG",
                   help="light elevation above the screen plane, [-90, 90] (default: 45)")
    p.add_argument("--light-azimuth", type=float, default=30.0, metavar="DEG",
                   help="light azimuth in the screen plane, [-360, 360] (default: 30)")
    p.add_argument("--light", default="directional", choices=["directional", "point"])
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
    p.add_argument("--simulator", default="verilator", choices=["verilator", "icarus"], help="with --rtl")
    p.add_argument("--per-cycle", action="store_true",
                   help="with --rtl: drive every pixel from cocotb, clock by clock, instead of the "
                        "bulk path (sim/tb/bulk.py: arrays in, arrays out, cached build)")
    p.add_argument("--pipeline", default="default", metavar="FILE|NAME",
                   help="with --rtl: the scene class (rtl/scene.py built-in or TOML) to build")
    add_config_flags(p, fields=("spec_exponent", "ka", "kd", "ks", "specular", "palette_size"))
    p.set_defaults(func=run)
