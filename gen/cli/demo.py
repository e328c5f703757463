"""``bumprtl demo``: the flags; the job is gen/render/demo.py's :func:`run_demo`."""

from pathlib import Path

from bumprtl.gen.render.demo import DEMO_SCENES, run_demo

__all__ = ["run", "add_parser"]


def run(args):
    return run_demo(args.out, args.size, args.rtl, args.simulator, args.verbose)


def add_parser(sub):
    p = sub.add_parser("demo", help="render the demo scenes with every method, write PNGs + report",
                       description="The main job on the default scene: renders the demo scenes "
                                   f"({', '.join(DEMO_SCENES)}) with every method, writes PNGs, "
                                   "comparison panels and report.txt (PSNR / max difference vs "
                                   "conventional, timings), then renders the default scene "
                                   "through its emitted pipeline on a simulator and checks the "
                                   "image equals the fixed-point golden one byte for byte.")
    p.add_argument("--out", type=Path, default=Path("build/demo"), help="output directory (default: build/demo)")
    p.add_argument("--size", type=int, default=512,
                   help="image size, power of two in [16, 4096] (default: 512)")
    p.add_argument("--no-rtl", dest="rtl", action="store_false",
                   help="skip the render through the emitted pipeline")
    p.add_argument("--simulator", default="verilator", choices=["verilator", "icarus"],
                   help="simulator of the RTL render (default: verilator)")
    p.add_argument("--verbose", action="store_true",
                   help="print the simulator's build and run output (by default it goes to "
                        "OUT/sim/tools.log, shown in full only on a failure) and the whole "
                        "RTL section of the report")
    p.set_defaults(func=run)
