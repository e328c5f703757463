"""``bumprtl bench palette``: the palette method (Tarini et al.) against per-pixel shading.

``speed``: per-frame cost = colour table (sN shading evaluations) + per-pixel lookup,
against direct per-pixel shading with the same lighting function, side by side in one run
(the sizes of the paper's Table 1). ``accuracy``: PSNR / max difference of palette renders
against the conventional per-pixel reference. ``images``: palette renders of the demo scenes.
"""

import time
from pathlib import Path

import numpy as np

from bumprtl.rtl.config import Config
from bumprtl.sim.golden.common import to_8bit
from bumprtl.sim.golden.float.conventional import conventional
from bumprtl.sim.golden.float.palette import (
    color_table,
    distinct_normals,
    palette_rgb,
    render_palette,
)
from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png

SPEED_SIZES = (256, 512, 1024, 2048)
SPEED_PALETTES = (256, 2048, 16384)
ACC_PALETTES = (16, 64, 256, 1024, 4096, 16384)
ACC_SCENES = ("wood", "bumps", "gravel", "globe")


def _best(fn, repeats=3):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def speed(cfg, sizes, palettes):
    rng = np.random.default_rng(0)
    l, v = np.array([[0.4, -0.7, 0.6]]), np.array([[0.0, -1.0, 0.0]])
    shade8 = lambda normals: to_8bit(color_table(normals, "phong", l, v, cfg))
    print("| image | sN | colour table ms | lookup ms | palette frame ms | per-pixel ms | ratio |")
    print("|---|---|---|---|---|---|---|")
    for size in sizes:
        for sn in palettes:
            table = rng.normal(size=(sn, 3))
            table /= np.linalg.norm(table, axis=1, keepdims=True)
            idx = rng.integers(0, sn, (size, size))
            per_pixel_normals = table[idx]
            t_table = _best(lambda table=table: shade8(table))
            colors = shade8(table)
            t_lookup = _best(lambda colors=colors, idx=idx: colors[idx])
            t_direct = _best(lambda normals=per_pixel_normals: shade8(normals.reshape(-1, 3)))
            frame = t_table + t_lookup
            print(f"| {size}² | {sn} | {t_table * 1e3:.2f} | {t_lookup * 1e3:.2f} | {frame * 1e3:.2f} "
                  f"| {t_direct * 1e3:.1f} | {t_direct / frame:.1f}x |", flush=True)


def accuracy(cfg, scenes, palettes, size, plot=None):
    print("| scene | quantizer | " + " | ".join(f"sN={s}" for s in palettes) + " |")
    print("|---|---|" + "---|" * len(palettes))
    curves = {}
    for name in scenes:
        scene = load_scene(name, size=size)
        ref = compose(scene, conventional(scene.px, cfg).color)
        n_distinct = distinct_normals(scene)
        for quantizer in ("median-cut", "kmeans"):
            cells, curve = [], []
            for sn in palettes:
                img = compose(scene, render_palette(scene, cfg, sn, quantizer).color)
                p = psnr(ref, img)
                curve.append((sn, p))
                # sN >= the map's distinct normals: each normal its own entry, nothing quantized
                exact = f" (all {n_distinct} normals)" if sn >= n_distinct else ""
                cells.append(f"{p:.1f} dB / {max_diff(ref, img)}{exact}")
            curves[(name, quantizer)] = curve
            print(f"| {name} | {quantizer} | " + " | ".join(cells) + " |", flush=True)
    if plot:
        _plot(curves, plot, size)


def _plot(curves, path, size):
    import matplotlib  # optional dependency: [bench]

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # optional dependency: [bench]

    fig, ax = plt.subplots(figsize=(6, 3.6), dpi=80)
    for _n, ((name, quantizer), curve) in enumerate(sorted(curves.items())):
        if curve:
            xs, ys = zip(*curve, strict=False)
            ax.semilogx(xs, ys, "-o" if quantizer == "kmeans" else "--x", base=2,
                        color=f"C{sorted({k[0] for k in curves}).index(name)}", label=f"{name} {quantizer}")
    ax.set_xlabel("palette size sN")
    ax.set_ylabel("PSNR vs per-pixel (dB)")
    ax.set_title(f"Palette method accuracy, {size}x{size}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    print(f"plot -> {path}")


def images(cfg, out_dir, size):
    for name, sn, lighting, dither in (("bricks", 16, "phong", False), ("globe", 256, "phong", False),
                                       ("globe", 64, "phong", True), ("globe", 1024, "chrome", False),
                                       ("wood", 256, "toon", False)):
        scene = load_scene(name, size=size)
        rgb, _ = palette_rgb(scene, cfg, sn, "kmeans", lighting, dither)
        if lighting == "phong":
            ref = compose(scene, conventional(scene.px, cfg).color)
            img = panel(ref, compose(scene, rgb.mean(-1)))
        else:
            img = np.where(scene.mask[..., None], to_8bit(rgb), 0).astype(np.uint8)
        tag = f"{name}_{lighting}_{sn}" + ("_dither" if dither else "")
        print(f"{tag} -> {save_png(Path(out_dir) / f'palette_{tag}.png', img)}")


def palette_bench(*, what, sizes, palettes, scenes, size, plot, images_dir):
    """``bumprtl bench palette``: the arguments are its flags' (gen/cli/bench.py);
    returns the exit status."""
    cfg = Config()
    command = f"bumprtl bench palette --what {' '.join(what)}"
    if "accuracy" in what or "images" in what:
        command += f" --size {size}"
    if "accuracy" in what:
        command += f" --scenes {' '.join(scenes)}"
    print(command)                     # the command that reproduces the tables below
    if "speed" in what:
        print("\nPer-frame cost, numpy, best of 3 (Phong, one light):\n")
        speed(cfg, sizes, palettes)
    if "accuracy" in what:
        print(f"\nPSNR / max difference (8-bit) against conventional, {size}x{size}:\n")
        accuracy(cfg, scenes, ACC_PALETTES, size, plot)
    if "images" in what:
        images(cfg, images_dir, size)
    return 0
