"""``bumprtl render``: render a scene with one method; ``--compare`` against conventional."""

import time
from pathlib import Path

import numpy as np

from ..rtl.config import BumpError

ROWS_PER_CHUNK = 32


def shade_scene(scene, method, cfg, progress=True):
    """Per-pixel float intensity of ``scene`` by float64 model ``method``, rendered in row
    chunks with a progress bar (pixels per second) on long renders."""
    from ..sim.golden.models import FLOAT_MODELS
    if method not in FLOAT_MODELS:
        raise BumpError(f"method must be one of {', '.join(FLOAT_MODELS)}, got {method!r}")
    from tqdm import tqdm
    model = FLOAT_MODELS[method]
    size = scene.size
    out = np.zeros((size, size))
    bar = tqdm(total=size * size, unit="pix", unit_scale=True, desc=method, leave=False,
               disable=not progress or size * size < 2 ** 20)
    for r0 in range(0, size, ROWS_PER_CHUNK):
        rows = slice(r0, min(size, r0 + ROWS_PER_CHUNK))
        out[rows] = model(scene.px.subset(rows), cfg).color
        bar.update(out[rows].size)
    bar.close()
    return out


def run(args):
    from ..sim.scenes import load_scene
    from ..sim.scenes.imaging import compose, max_diff, panel, psnr, save_png
    from .cli import config_from_args
    cfg = config_from_args(args)
    scene = load_scene(args.scene, size=args.size, light_elevation=args.light_elevation,
                       light_azimuth=args.light_azimuth, light=args.light)
    t0 = time.perf_counter()
    img = compose(scene, shade_scene(scene, args.model, cfg))
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
    from ..sim.golden.models import FLOAT_MODELS
    from ..sim.scenes import SCENES
    from .cli import add_config_flags
    scenes = "\n".join(f"  {k:<12} {v[3]}" for k, v in SCENES.items())
    p = sub.add_parser("render", help="render a scene to PNG with one method",
                       description=f"Render a bump-mapped scene with a float64 golden model.\n\nscenes:\n{scenes}",
                       formatter_class=__import__("argparse").RawDescriptionHelpFormatter)
    p.add_argument("--scene", default="bricks", choices=list(SCENES), metavar="NAME",
                   help="scene name (default: bricks)")
    p.add_argument("--method", dest="model", default="exact", choices=list(FLOAT_MODELS), metavar="METHOD",
                   help=f"one of {', '.join(FLOAT_MODELS)} (default: exact)")
    p.add_argument("--size", type=int, default=512, help="image size, power of two in [16, 4096] (default: 512)")
    p.add_argument("--light-elevation", type=float, default=45.0, metavar="DEG",
                   help="light elevation above the screen plane, [-90, 90] (default: 45)")
    p.add_argument("--light-azimuth", type=float, default=30.0, metavar="DEG",
                   help="light azimuth in the screen plane, [-360, 360] (default: 30)")
    p.add_argument("--light", default="directional", choices=["directional", "point"])
    p.add_argument("--out", type=Path, default=Path("build/render/render.png"), help="output PNG")
    p.add_argument("--compare", action="store_true",
                   help="also write reference | method | |diff| x10 and print PSNR / max diff vs conventional")
    add_config_flags(p, fields=("spec_exponent", "ka", "kd", "ks", "specular"))
    p.set_defaults(func=run)
