"""``bumprtl demo``: the main job on the default scene, PNGs plus a short text report."""

import time
from pathlib import Path

DEMO_METHODS = ("conventional", "exact", "peercy", "kim", "lee_fixed", "lee_printed")
DEMO_SCENES = ("bricks", "globe")


def run(args):
    from ..rtl.config import Config
    from ..sim.scenes import load_scene
    from ..sim.scenes.imaging import compose, max_diff, panel, psnr, save_png
    from .render import shade_scene
    cfg = Config()
    out = Path(args.out)
    lines = [f"bumprtl demo: {args.size}x{args.size}, light elevation 45 deg, azimuth 30 deg,",
             f"command: bumprtl demo --out {out} --size {args.size}", "",
             f"{'scene':<8} {'method':<13} {'PSNR dB':>8} {'max diff':>9} {'Mpix/s':>8}  file"]
    for name in DEMO_SCENES:
        scene = load_scene(name, size=args.size)
        ref = None
        for method in DEMO_METHODS:
            t0 = time.perf_counter()
            img = compose(scene, shade_scene(scene, method, cfg))
            rate = args.size ** 2 / (time.perf_counter() - t0) / 1e6
            path = save_png(out / f"{name}_{method}.png", img)
            if ref is None:
                ref = img
            else:
                save_png(out / f"{name}_{method}_compare.png", panel(ref, img))
            lines.append(f"{name:<8} {method:<13} {psnr(ref, img):>8.2f} {max_diff(ref, img):>9d} "
                         f"{rate:>8.2f}  {path.name}")
            print(lines[-1], flush=True)
    lines += ["", "PSNR and max difference are against 'conventional' (8-bit RGB);",
              "*_compare.png panels: conventional | method | |difference| x10."]
    report = out / "report.txt"
    report.write_text("\n".join(lines) + "\n")
    print(f"wrote {len(DEMO_SCENES) * (2 * len(DEMO_METHODS) - 1)} PNGs and {report}")
    return 0


def add_parser(sub):
    p = sub.add_parser("demo", help="render the demo scenes with every method, write PNGs + report",
                       description="The main job on the default scene: renders the demo scenes "
                                   "with every float64 method, writes PNGs, comparison panels "
                                   "and a short text report (PSNR / max difference vs conventional).")
    p.add_argument("--out", type=Path, default=Path("build/demo"), help="output directory (default: build/demo)")
    p.add_argument("--size", type=int, default=512, help="image size, power of two (default: 512)")
    p.set_defaults(func=run)
