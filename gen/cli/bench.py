"""``bumprtl bench KIND``: benchmarks (speed is measured here, never asserted in tests).

Each kind's sub-parser is added by a function here, registered in BENCHES; the benchmark
itself is a function of gen/bench/ with the flags as keyword arguments.
"""

import os
from pathlib import Path

from bumprtl.gen.bench import (
    accuracy,
    float64,
    golden,
    lee_widths,
    memory,
    palette,
    rtl_sim,
    skip,
    specular,
    stress,
    sweep,
)
from bumprtl.gen.bench.palette import ACC_SCENES, SPEED_PALETTES, SPEED_SIZES
from bumprtl.gen.bench.rtl_sim import build_label
from bumprtl.gen.bench.sweep import DEFAULT_MAPS, FPGA_POINTS, MAP_SIZES, METHOD_CHOICES
from bumprtl.gen.cli.quiet import quiet_commands
from bumprtl.gen.render.rtl import require_sim
from bumprtl.gen.tools.jobs import add_arguments as add_job_arguments
from bumprtl.rtl.config import BumpError, Config
from bumprtl.sim.golden.methods import METHODS, PER_PIXEL
from bumprtl.sim.tb.bulk import SIMULATORS, build_options


def at_least(low, **flags):
    """Refuse a flag's value (or any of its values) below ``low``, before any work: one
    line naming the flag, a BumpError (exit 2)."""
    for name, given in flags.items():
        for v in given if isinstance(given, (list, tuple)) else [given]:
            if v < low:
                raise BumpError(f"--{name.replace('_', '-')} must be >= {low}, got {v}", name)


def run_float64(args):
    at_least(1, samples=args.samples)
    return float64.float64_bench(samples=args.samples, seed=args.seed)


def run_accuracy(args):
    return accuracy.accuracy_bench(accuracy.AccuracyOptions(
        method=args.method, samples=args.samples, angle_bits=tuple(args.angle_bits),
        frac_bits=tuple(args.frac_bits), spec_exponent=tuple(args.spec_exponent),
        spec_index_bits=args.spec_index_bits, faithful_widths=args.faithful_widths,
        scene_size=args.scene_size,
        scene_widths=None if args.scene_widths is None else tuple(args.scene_widths)))


def run_sweep(args):
    return sweep.sweep_bench(sweep.SweepOptions(
        quick=args.quick, methods=tuple(args.methods),
        maps=None if args.maps is None else tuple(args.maps), fpga=args.fpga,
        device=args.device, fpga_points=args.fpga_points, sim=args.sim, jobs=args.jobs,
        scheduler=args.scheduler, out=args.out, work=args.work, docs=args.docs,
        data_copy=args.data_copy, no_progress=args.no_progress))


def run_lee_widths(args):
    at_least(1, samples=args.samples)
    return lee_widths.lee_widths_bench(samples=args.samples, seed=args.seed)


def run_golden(args):
    at_least(1, pixels=args.pixels)
    at_least(0, sim_samples=args.sim_samples)
    if args.sim_samples:            # the simulations need [sim]'s cocotb: refuse before any work
        require_sim()
    return golden.golden_bench(methods=args.methods, pixels=args.pixels, sim_samples=args.sim_samples)


def run_stress(args):
    return stress.stress_bench(samples=args.samples, seed=args.seed, out=args.out)


def run_specular(args):
    at_least(1, samples=args.samples)
    for n in args.spec_exponent:            # the Config's range, before the table's header
        Config(spec_exponent=n)
    return specular.specular_bench(spec_exponent=args.spec_exponent, samples=args.samples, work=args.work)


def run_skip(args):
    return skip.skip_bench(docs=args.docs, size=args.size, work=args.work, scenes=args.scenes)


def run_rtl_sim(args):
    return rtl_sim.rtl_sim_bench(simulators=args.simulators, docs=args.docs, repeat=args.repeat, scene=args.scene, size=args.size, work=args.work, quick=args.quick)


def run_palette(args):
    at_least(1, sizes=args.sizes, palettes=args.palettes)
    return palette.palette_bench(what=args.what, sizes=args.sizes, palettes=args.palettes, scenes=args.scenes, size=args.size, plot=args.plot, images_dir=args.images_dir)


def run_memory(args):
    return memory.memory_bench(scenes=args.scenes, sizes=args.sizes, caches=args.caches,
                               methods=args.methods, latencies=args.latencies, rows=args.rows,
                               doc=args.doc, plot=args.plot)


def add_memory(kinds):
    p = kinds.add_parser("memory", help="texel cache: hit rate, bytes and cycles per pixel",
                         description="The texel cache of map_memory = axi on the demo scenes' "
                                     "texel streams: hit rate, bytes fetched and cycles per "
                                     "pixel, throughput against a zero-wait memory.")
    p.add_argument("--scenes", nargs="+", default=list(memory.MEMORY_SCENES),
                   help="demo scenes (their geometry decides the texel stream)")
    p.add_argument("--sizes", nargs="+", type=int, default=list(memory.MAP_SIZES),
                   help="map sides T (a T x T frame at one texel per pixel)")
    p.add_argument("--caches", nargs="+", default=list(memory.CACHES), choices=list(memory.CACHES),
                   help="cache geometries measured (default: all of them)")
    p.add_argument("--methods", nargs="+", default=list(memory.METHODS), choices=list(memory.METHODS),
                   help="methods whose texel stream is measured (default: all of them)")
    p.add_argument("--latencies", nargs="+", type=int, default=list(memory.LATENCIES),
                   help="memory latencies (cycles from the AR handshake to the first beat)")
    p.add_argument("--rows", type=int, default=memory.BAND_ROWS,
                   help="frame rows run through the cache (centred)")
    p.add_argument("--doc", type=Path, default=None, help="write this page (docs/memory.md)")
    p.add_argument("--plot", type=Path, default=None,
                   help="the plot (default: img/memory.png beside --doc)")
    p.set_defaults(func=run_memory)


def add_lee_widths(kinds):
    p = kinds.add_parser("lee-widths", help="lee datapath error against width",
                       description="Diffuse error of the bit-exact lee datapath against the exact "
                                   "reference for a range of widths, beside the exact datapath at "
                                   "the same widths: the lee error is in the geometry, not the bits.")
    p.add_argument("--samples", type=int, default=100_000, help="random valid inputs (default: 100000)")
    p.add_argument("--seed", type=int, default=1, help="seed of the random inputs (default: 1)")
    p.set_defaults(func=run_lee_widths)


def add_float64(kinds):
    p = kinds.add_parser("float64", help="error and speed of the float64 golden models",
                       description="Mean, p99 and max of the L' angle error (degrees) and of the "
                                   "diffuse error (8-bit LSB) of every float64 model against the "
                                   "Cartesian reference, and each model's speed, in one run; "
                                   "then lee_corrected's errors binned by theta_N.")
    p.add_argument("--samples", type=int, default=100_000, help="random valid inputs (default: 100000)")
    p.add_argument("--seed", type=int, default=1, help="seed of the random inputs (default: 1)")
    p.set_defaults(func=run_float64)


def add_accuracy(kinds):
    p = kinds.add_parser("accuracy", help="fixed-point error against float64 per channel, over widths",
                       description="Max and mean error (8-bit LSB) of the diffuse, specular and "
                                   "colour outputs of the bit-exact golden model against float64 "
                                   "on random inputs and on adversarial searches aimed at each, "
                                   "beside the proven bound of each. Exits 1, printing the "
                                   "offending input, if an error exceeds its bound.")
    p.add_argument("--method", default="exact", choices=tuple(METHODS),
                   help="the datapath measured (default: exact)")
    p.add_argument("--samples", type=int, default=1_000_000,
                   help="random valid inputs per width point (default: 10^6)")
    p.add_argument("--angle-bits", type=int, nargs="+", default=[12, 13, 14, 15],
                   help="angle widths of the grid (default: 12 13 14 15)")
    p.add_argument("--frac-bits", type=int, nargs="+", default=[13, 15, 16],
                   help="value widths of the grid (default: 13 15 16)")
    p.add_argument("--spec-exponent", type=int, nargs="+", default=[16],
                   help="Phong exponents n (default: 16)")
    p.add_argument("--spec-index-bits", type=int, default=10, help="specular table address bits (default: 10)")
    p.add_argument("--faithful-widths", action="store_true",
                   help="measure each --spec-exponent at the narrowest widths the bound proves "
                        "within 1 LSB on every channel (the sidecar's faithful_widths) instead of "
                        "the --angle-bits x --frac-bits grid")
    p.add_argument("--scene-size", type=int, default=128,
                   help="also shade every built-in scene at this size, default widths (0: no scenes)")
    p.add_argument("--scene-widths", type=int, nargs=2, metavar=("ANGLE_BITS", "FRAC_BITS"),
                   help="widths of the light-sum, blend and scene tables (default: Config's)")
    p.set_defaults(func=run_accuracy)


def add_sweep(kinds):
    p = kinds.add_parser("sweep", help="error against cost against run time over widths and methods",
                       description="For exact/lee over angle and value widths, the palette over "
                                   "palette sizes, and the baselines: error vs float64, Yosys cost "
                                   "(optionally ECP5), golden/simulation/hardware speed. JSON, "
                                   "Pareto plot, markdown table.")
    p.add_argument("--quick", action="store_true", help="small grid (angle 10,12 x frac 11,13; sN 16,256)")
    p.add_argument("--methods", nargs="+", default=list(METHOD_CHOICES), choices=METHOD_CHOICES,
                   help="methods swept (default: all of them)")
    p.add_argument("--maps", nargs="+", default=None, metavar="NAME:SIZE",
                   help="the maps the scene errors are measured on, each a scene of `bumprtl render "
                        f"--help` at SIZE x SIZE texels (a power of two in [{MAP_SIZES[0]}, "
                        f"{MAP_SIZES[1]}]), one pixel per texel (default: "
                        f"{' '.join(f'{n}:{z}' for n, z in DEFAULT_MAPS)}; --quick: bricks:64)")
    p.add_argument("--fpga", action="store_true", help="also place each point on an ECP5 (slow)")
    p.add_argument("--device", default="LFE5U-85F", help="ECP5 device for --fpga")
    p.add_argument("--fpga-points", default="default", choices=FPGA_POINTS,
                   help="with --fpga: which width points to place: the default widths of every "
                        "method (default), the i-th angle width with the i-th value width "
                        "(diagonal; baselines at the default widths), or all; palette sizes always")
    p.add_argument("--sim", action="store_true",
                   help="cocotb/Verilator pixels/s for the points at the default widths")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="with --fpga: local worker processes, one placement each at a time "
                        "(default: the number of cores; ignored with --scheduler)")
    add_job_arguments(p)
    p.add_argument("--out", type=Path, default=Path("build/bench/sweep.json"),
                   help="the sweep's JSON (default: build/bench/sweep.json)")
    p.add_argument("--work", type=Path, default=Path("build/bench/sweep"),
                   help="netlists and cached cost per config")
    p.add_argument("--docs", type=Path, default=None, help="write the sweep section of this markdown file "
                                                           "(docs/bench.md) and docs/img/bench_pareto.png")
    p.add_argument("--data-copy", type=Path, default=None, help="also copy the JSON here (docs/data/)")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress line per finished point on the terminal")
    p.set_defaults(func=run_sweep)


def add_golden(kinds):
    p = kinds.add_parser("golden", help="fixed-point golden model and cocotb simulation throughput",
                       description="Pixels per second of the bit-exact golden model per method, "
                                   "and of cocotb simulation under Icarus and Verilator, in one run.")
    p.add_argument("--pixels", type=int, default=1_000_000, help="golden-model batch (default: 10^6)")
    p.add_argument("--sim-samples", type=int, default=5000,
                   help="random vectors per traffic pattern in the simulations (default: 5000; "
                        "0: no simulations)")
    p.add_argument("--methods", nargs="+", default=list(PER_PIXEL), choices=PER_PIXEL,
                   help="per-pixel methods timed (default: all of them)")
    p.set_defaults(func=run_golden)


def add_stress(kinds):
    p = kinds.add_parser("stress", help="golden models on degenerate inputs and extreme configs",
                       description="Every golden model on the stress cases of sim/golden/stress.py "
                                   "at the narrowest/widest widths and extreme specular exponents: "
                                   "max error, NaN and overflow counts -> docs/stability.md.")
    p.add_argument("--samples", type=int, default=20_000, help="pixels per case (default: 20000)")
    p.add_argument("--seed", type=int, default=1, help="seed of the random pixels (default: 1)")
    p.add_argument("--out", type=Path, default=Path("docs/stability.md"),
                   help="the page written (default: docs/stability.md)")
    p.set_defaults(func=run_stress)


def add_specular(kinds):
    p = kinds.add_parser("specular", help="the specular-term candidates side by side",
                       description="cos^n by a nearest-entry table, an interpolated table, an "
                                   "interpolated table finer near 1 and repeated squaring: error "
                                   "against float64 and cost per exponent.")
    p.add_argument("--samples", type=int, default=1_000_000,
                   help="random cosines per exponent (default: 10^6)")
    p.add_argument("--spec-exponent", type=int, nargs="+", default=[1, 2, 16, 64, 256, 1024],
                   help="Phong exponents n (default: 1 2 16 64 256 1024)")
    p.add_argument("--work", type=Path, default=Path("build/bench/specular"),
                   help="netlist of the Illumination unit counted at the end")
    p.set_defaults(func=run_specular)


def add_skip(kinds):
    p = kinds.add_parser("skip", help="scene skipping: golden time and cost with skipping on and off",
                       description="Per scene class, the generated pipeline beside the same scene "
                                   "with nothing skipped: golden-model time and Yosys cost, one run.")
    p.add_argument("--size", type=int, default=128, help="frame size for the golden model (default: 128)")
    p.add_argument("--scenes", nargs="+", default=None, help="scene classes (default: all built-in)")
    p.add_argument("--work", type=Path, default=Path("build/bench/skip"),
                   help="netlists of the pipelines counted (default: build/bench/skip)")
    p.add_argument("--docs", type=Path, default=None, help="write the section into this markdown file")
    p.set_defaults(func=run_skip)


def add_rtl_sim(kinds):
    p = kinds.add_parser("rtl-sim", help="RTL simulation speed: bulk path against per-cycle cocotb",
                       description="Renders one frame through the emitted pipeline with the bulk "
                                   "path (several Verilator builds) and the per-cycle cocotb "
                                   "path on Icarus and Verilator, side by side in one run: "
                                   "pixels per second and the ratios.")
    p.add_argument("--size", type=int, default=256, help="frame size (default: 256)")
    p.add_argument("--scene", default="default", help="scene class (default: default)")
    p.add_argument("--simulators", nargs="+", default=list(SIMULATORS), choices=SIMULATORS,
                   help="simulators timed (default: both)")
    p.add_argument("--quick", action="store_true",
                   help="only the default bulk build of each simulator "
                        f"(Verilator: {build_label(build_options('verilator'))})")
    p.add_argument("--repeat", type=int, default=3,
                   help="bulk runs per build, the best (least streaming CPU) reported (default: 3)")
    p.add_argument("--work", type=Path, default=Path("build/bench/rtl_sim"),
                   help="the simulator builds (default: build/bench/rtl_sim)")
    p.add_argument("--docs", type=Path, default=None, help="write the section into this markdown file")
    p.set_defaults(func=run_rtl_sim)


def add_palette(kinds):
    p = kinds.add_parser("palette", help="palette method: per-frame cost and accuracy vs per-pixel",
                       description="Palette method of Tarini et al.: colour table + lookup against "
                                   "per-pixel shading (speed), PSNR vs sN (accuracy), demo renders.")
    p.add_argument("--what", nargs="+", default=["speed", "accuracy"], choices=["speed", "accuracy", "images"],
                   help="the parts run (default: speed accuracy)")
    p.add_argument("--sizes", nargs="+", type=int, default=list(SPEED_SIZES),
                   help=f"speed: image sizes (default: {' '.join(map(str, SPEED_SIZES))})")
    p.add_argument("--palettes", nargs="+", type=int, default=list(SPEED_PALETTES),
                   help=f"speed: sN values (default: {' '.join(map(str, SPEED_PALETTES))})")
    p.add_argument("--scenes", nargs="+", default=list(ACC_SCENES), help="accuracy: scenes")
    p.add_argument("--size", type=int, default=256, help="accuracy/images: image size (default 256)")
    p.add_argument("--plot", type=Path, default=None, help="accuracy: write the PSNR plot here")
    p.add_argument("--images-dir", type=Path, default=Path("build/palette"), help="images: output dir")
    p.set_defaults(func=run_palette)


# kind -> the function adding its sub-parser, in `--help` order.
BENCHES = {
    "float64": add_float64,
    "golden": add_golden,
    "accuracy": add_accuracy,
    "specular": add_specular,
    "lee-widths": add_lee_widths,
    "palette": add_palette,
    "memory": add_memory,
    "sweep": add_sweep,
    "stress": add_stress,
    "skip": add_skip,
    "rtl-sim": add_rtl_sim,
}


def add_parser(sub):
    p = sub.add_parser("bench", help="benchmarks: speed against error",
                       description="Benchmarks. Ratios are measured side by side in one run.")
    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for add in BENCHES.values():
        add(kinds)
    quiet_commands(kinds, "build/bench")      # the tools' output to build/bench/KIND.log
