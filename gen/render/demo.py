"""``bumprtl demo``: the main job on the default scene, PNGs plus a short text report.

1. The demo scenes with every float64 model (and palette), PSNR against ``conventional``,
   and beside it the PSNR of the method's bit-exact fixed-point model (the picture the
   hardware makes; ``bumprtl render --model fixed``) where the method has hardware.
2. Unless ``--no-rtl``: the pipeline of the default scene class (sim/scenes/config.py) with the
   largest bump map (at most the image size) that fits the block RAM of DEMO_DEVICE, emitted
   to ``<out>/pipeline/pipeline.v`` + ``pipeline.json`` + ``pipeline_map.hex`` (the map's
   ``$readmemh`` file, written through the host write port before the first pixel),
   rendered through the simulator on the bulk path (gen/render/rtl.py), written as ``rtl.png``
   beside the fixed-point golden render ``golden.png`` and ``diff.png`` (|rtl - golden|
   x DIFF_GAIN); the report gets the RTL image's PSNR against float64 ``conventional``, the
   resource summary (Yosys, gen/flow/resources.py), the latency and the cycles per pixel
   measured in the simulation. A different RTL image fails the demo.
"""

import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

from bumprtl.gen.flow.memories import DEFAULT_DEVICE, check_scene_fits
from bumprtl.gen.flow.quiet import tool_log
from bumprtl.gen.flow.resources import count_verilog
from bumprtl.gen.render.images import (
    FIXED_METHODS,
    PALETTE,
    fixed_image,
    float_image,
    render_methods,
    shade_scene,
)
from bumprtl.gen.render.rtl import render_rtl, require_sim
from bumprtl.rtl.config import BumpError, Config
from bumprtl.rtl.sidecar import load as load_sidecar
from bumprtl.sim.scenes import load_scene
from bumprtl.sim.scenes.config import load_scene_config
from bumprtl.sim.scenes.imaging import compose, max_diff, panel, psnr, save_png

DEMO_SCENES = ("bricks", "globe")
REFERENCE = "conventional"
DEMO_PIPELINE = "default"          # the scene class rendered through the RTL
DEMO_DEVICE = DEFAULT_DEVICE       # its bump map must fit this FPGA's block RAM
DEMO_LOAD = "port"                 # the map goes in through the host write port
DIFF_GAIN = 64


def demo_methods():
    """The reference first, then every float64 model, then ``palette`` when this checkout
    has the palette model (sim/golden/float/palette.py)."""
    have_palette = importlib.util.find_spec("bumprtl.sim.golden.float.palette") is not None
    rest = [m for m in render_methods() if m != REFERENCE and (m != PALETTE or have_palette)]
    return [REFERENCE, *rest]


def _render_scene(name, size, methods, cfg, out):
    """Render one scene with every method, by its float64 model and by its fixed-point
    model; yields one report line per method (fixed-point columns '-' without hardware)."""
    scene = load_scene(name, size=size)
    fixed_scene = load_scene_config({"name": name, "image": name, "texture_size": size})
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
        fixed = "-", "-"
        if method in FIXED_METHODS:
            f = fixed_image(fixed_scene, method, size)
            save_png(out / f"{name}_{method}_fixed.png", f)
            fixed = f"{psnr(ref, f):.2f}", str(max_diff(ref, f))
        yield (f"{name:<8} {method:<13} {psnr(ref, img):>8.2f} {max_diff(ref, img):>9d} "
               f"{fixed[0]:>9} {fixed[1]:>9} {seconds:>8.3f} {size * size / seconds / 1e6:>8.2f}  "
               f"{path.name}")


def demo_map_size(size, device=DEMO_DEVICE, scene=DEMO_PIPELINE):
    """The largest power-of-two map side, at most ``size``, whose pipeline fits ``device``'s
    block RAM (gen/flow/memories.check_scene_fits)."""
    t = size
    while True:
        candidate = load_scene_config(scene).replace(texture_size=t)
        try:
            check_scene_fits(candidate, device)
            return t
        except BumpError:
            if t <= 16:
                raise
            t //= 2


def side_by_side(left, right, width=256, gap=8):
    """``left | right`` (8-bit RGB), each scaled to ``width`` pixels (nearest), on white: the
    README's picture (float64 conventional beside the RTL render, ``make docs`` copies it)."""
    def scaled(img):
        img = np.asarray(img)
        idx = (np.arange(width) * img.shape[0]) // width
        return img[idx][:, idx]
    pad = np.full((width, gap, 3), 255, np.uint8)
    return np.concatenate([scaled(left), pad, scaled(right)], axis=1).astype(np.uint8)


def rtl_mismatch(rtl, golden):
    """None when the two 8-bit images are equal byte for byte, else a one-line message."""
    rtl, golden = np.asarray(rtl), np.asarray(golden)
    if rtl.shape == golden.shape and rtl.tobytes() == golden.tobytes():
        return None
    if rtl.shape != golden.shape:
        return f"RTL image is {rtl.shape}, the golden image {golden.shape}"
    diff = np.abs(rtl.astype(int) - golden.astype(int))
    return (f"RTL image differs from the fixed-point golden image in "
            f"{int(np.count_nonzero(diff.max(axis=-1)))} pixels (max |difference| {int(diff.max())})")


def _rtl_section(out, size, simulator, verbose):
    """Emit, render through the simulator, compare, count. Returns (report lines, error)."""
    t = demo_map_size(size)
    scene = load_scene_config(DEMO_PIPELINE).replace(texture_size=t)
    blocks, have = check_scene_fits(scene, DEMO_DEVICE)
    n = size * size
    require_sim()
    label = (f"rtl: {size}x{size} {scene.image} ({t}^2 map) through the emitted "
             f"pipeline of scene {scene.name!r} on {simulator}")
    if verbose:
        print(label, flush=True)
    with tool_log(out / "sim" / "tools.log", label, verbose):
        r = render_rtl(scene, size, simulator, out / "sim", progress=verbose,
                       rtl_dir=out / "pipeline", load=DEMO_LOAD)
    reference, _ = float_image(scene, "conventional", size, progress=False)
    save_png(out / "rtl.png", r.image)
    save_png(out / "golden.png", r.golden)
    save_png(out / "rtl_vs_float64.png", side_by_side(reference, r.image))
    diff = np.abs(r.image.astype(int) - r.golden.astype(int))
    save_png(out / "diff.png", np.clip(diff * DIFF_GAIN, 0, 255))
    error = rtl_mismatch(r.image, r.golden)
    meta = load_sidecar(out / "pipeline" / "pipeline.json")
    counts = count_verilog(out / "pipeline" / "pipeline.v", "pipeline", out / "pipeline" / "yosys")
    c = counts.summary()
    lines = ["", f"RTL render: scene class {scene.name!r} (`{meta.command}`, the "
                 f"{scene.image} bump map at {t}x{t} texels written through the host write port "
                 f"from pipeline_map.hex) -> {out / 'pipeline' / 'pipeline.v'} + pipeline.json",
             f"  map {t}x{t} x {2 * scene.angle_bits} bits: {blocks} of {have} DP16KD on "
             f"{DEMO_DEVICE} with the pipeline's tables (the largest power-of-two map up to the "
             f"image size that fits)",
             f"  image {scene.image} {size}x{size}, simulator {simulator} (cocotb, bulk path), "
             f"same stimulus as the fixed-point golden render (sim/golden/fixed/pipeline.py)",
             "  units built: " + "; ".join(f"{b['unit']} ({b['class']}, latency {b['latency']})"
                                          for b in meta.built),
             "  units skipped: " + ("; ".join(f"{k['unit']} ({k['why']})" for k in meta.skipped)
                                    or "none"),
             f"  resources (Yosys coarse netlist, gen/flow/resources.py): multipliers {c['multipliers']}, "
             f"adders {c['adders']}, ROM bits {c['table_bits']}, "
             f"RAM bits {sum(x['bits'] for x in counts.rams)}, register bits {c['register_bits']}",
             f"  latency {meta.latency} cycles; {n} pixels in {r.cycles} cycles without stalls "
             f"= {r.cycles / n:.4f} cycles per pixel (the pipe fills once, then 1 pixel per clock)",
             f"  simulation {r.seconds:.1f} s = {n / r.seconds:.0f} pixels/s on {simulator}, "
             f"streaming {r.stream_seconds:.2f} s = {n / r.stream_seconds:.0f} pixels/s "
             f"(build {r.build_seconds:.1f} s{', cached' if r.cached else ''})",
             "  rtl.png vs golden.png: " + ("identical bytes, max |difference| 0" if error is None
                                             else error) +
             f"; diff.png = |rtl - golden| x {DIFF_GAIN}",
             f"  rtl.png vs float64 conventional (same scene and map): PSNR "
             f"{psnr(reference, r.image):.2f} dB, max difference {max_diff(reference, r.image)}"]
    # the terminal: units and latency, resources, speed and the two comparisons (all of it
    # in report.txt; every line with --verbose)
    for line in (lines if verbose else [lines[4], *lines[6:]]):
        print(line, flush=True)
    return lines, error


def run_demo(out, size=512, rtl=True, simulator="verilator", verbose=False):
    """``bumprtl demo``: writes the PNGs and ``report.txt`` under ``out`` (the render through
    the pipeline on ``simulator`` unless not ``rtl``; every line of its section printed with
    ``verbose``). Returns 0, or 1 when the RTL image differs from the golden one."""
    load_scene(DEMO_SCENES[0], size=size)         # bad --size fails before any work
    if rtl:
        require_sim(simulator)                     # no [sim] extra: one line, before any work
    cfg, out, methods = Config(), Path(out), demo_methods()
    start = time.perf_counter()
    lines = [f"bumprtl demo: {size}x{size} pixels, directional light at elevation "
             f"45 deg, azimuth 30 deg, default Config",
             f"command: bumprtl demo --out {out} --size {size}"
             + ("" if rtl else " --no-rtl") +
             (f" --simulator {simulator}" if rtl and simulator != "verilator" else ""),
             "",
             f"{'scene':<8} {'method':<13} {'PSNR dB':>8} {'max diff':>9} {'fixed dB':>9} "
             f"{'fixed max':>9} {'seconds':>8} {'Mpix/s':>8}  file"]
    print(lines[-1], flush=True)                      # the table's header, then its rows
    for name in DEMO_SCENES:
        for line in _render_scene(name, size, methods, cfg, out):
            lines.append(line)
            print(line, flush=True)
    fixed = [m for m in methods if m in FIXED_METHODS]
    lines += ["", f"PSNR and max difference (8-bit RGB) are against float64 '{REFERENCE}': "
              f"'PSNR dB' of the method's float64 model, 'fixed dB' of its bit-exact fixed-point "
              f"model (`bumprtl render --model fixed`, the picture the hardware makes; '-': no "
              f"hardware); *_compare.png panels: {REFERENCE} | method | |difference| x10; "
              f"*_fixed.png the fixed-point renders."]
    error, pngs = None, len(DEMO_SCENES) * (2 * len(methods) - 1 + len(fixed))
    if rtl:
        rtl_lines, error = _rtl_section(out, size, simulator, verbose)
        lines += rtl_lines
        pngs += 4
    lines.append(f"total {time.perf_counter() - start:.1f} s")
    report = out / "report.txt"
    report.write_text("\n".join(lines) + "\n")
    print(f"wrote {pngs} PNGs and {report}")
    if error is not None:
        print(f"bumprtl demo: error: {error} (see {out / 'diff.png'})", file=sys.stderr)
        return 1
    return 0
