"""``bumprtl demo``: the main job on the default scene, PNGs plus a short text report."""

import importlib.util
import time
from pathlib import Path

DEMO_SCENES = ("bricks", "globe")
REFERENCE = "conventional"


def demo_methods():
    """The reference first, then every float64 model, then ``palette`` when this checkout
    has the palette model (sim/golden/palette.py)."""
    from .render import PALETTE, render_methods
    have_palette = importlib.util.find_spec("bumprtl.sim.golden.palette") is not None
    rest = [m for m in render_methods() if m != REFERENCE and (m != PALETTE or have_palette)]
    return [REFERENCE, *rest]


def _render_scene(name, size, methods, cfg, out):
    """Render one scene with every method; yields one report line per method."""
    from ..sim.scenes import load_scene
    from ..sim.scenes.imaging import compose, max_diff, panel, psnr, save_png
    from .render import shade_scene
    scene = load_scene(name, size=size)
    ref = None
    for method in methods:
        t0 = time.perf_counter()
        img = compose(scene, shade_scene(scene, method, cfg))
        seconds = time.perf_counter() - t0
        path = save_png(out / f"{name}_{method}.png", img)
        if ref is None:
            ref = img
        else:
            save_png(out / f"{name}_{method}_compare.png", panel(ref, img))
        yield (f"{name:<8} {method:<13} {psnr(ref, img):>8.2f} {max_diff(ref, img):>9d} "
               f"{seconds:>8.3f} {size * size / seconds / 1e6:>8.2f}  {path.name}")


def run(args):
    from ..rtl.config import Config
    from ..sim.scenes import load_scene
    load_scene(DEMO_SCENES[0], size=args.size)         # bad --size fails before any work
    cfg, out, methods = Config(), Path(args.out), demo_methods()
    start = time.perf_counter()
    lines = [f"bumprtl demo: {args.size}x{args.size} pixels, directional light at elevation "
             f"45 deg, azimuth 30 deg, default Config",
             f"command: bumprtl demo --out {out} --size {args.size}", "",
             f"{'scene':<8} {'method':<13} {'PSNR dB':>8} {'max diff':>9} {'seconds':>8} "
             f"{'Mpix/s':>8}  file"]
    for name in DEMO_SCENES:
        for line in _render_scene(name, args.size, methods, cfg, out):
            lines.append(line)
            print(line, flush=True)
    lines += ["", f"PSNR and max difference (8-bit RGB) are against '{REFERENCE}'; "
              f"*_compare.png panels: {REFERENCE} | method | |difference| x10.",
              f"total {time.perf_counter() - start:.1f} s"]
    report = out / "report.txt"
    report.write_text("\n".join(lines) + "\n")
    print(f"wrote {len(DEMO_SCENES) * (2 * len(methods) - 1)} PNGs and {report}")
    return 0


def add_parser(sub):
    p = sub.add_parser("demo", help="render the demo scenes with every method, write PNGs + report",
                       description="The main job on the default scene: renders the demo scenes "
                                   f"({', '.join(DEMO_SCENES)}) with every method, writes PNGs, "
                                   "comparison panels and report.txt (PSNR / max difference vs "
                                   "conventional, timings).")
    p.add_argument("--out", type=Path, default=Path("build/demo"), help="output directory (default: build/demo)")
    p.add_argument("--size", type=int, default=512,
                   help="image size, power of two in [16, 4096] (default: 512)")
    p.set_defaults(func=run)
