"""``bumprtl report KIND``: reports recounted from our netlists and placements.

Each kind is a function here adding its sub-parser, registered in REPORTS; the reports
themselves are gen/report/'s, called with typed arguments.
"""

import argparse
import os
from pathlib import Path

from bumprtl.gen.cli.flags import add_config_flags, config_from_args
from bumprtl.gen.cli.quiet import quiet_commands
from bumprtl.gen.report.fpga import FpgaRun, fpga_run
from bumprtl.gen.report.integration import DOC, NAME, integration_report
from bumprtl.gen.report.table1 import check_samples, table1_report
from bumprtl.gen.report.timing import timing_report
from bumprtl.gen.tools.jobs import add_arguments as add_job_arguments
from bumprtl.gen.tools.jobs import scheduler_address


def run_table1(args):
    check_samples(args.samples)
    scheduler_address(getattr(args, "scheduler", None))   # a malformed address: exit 2
    return table1_report(config_from_args(args), args.out, args.work, args.samples,
                         args.jobs, args.scheduler)


def fpga_run_of(args):
    """The FpgaRun ``report fpga``'s parsed flags ask for."""
    return FpgaRun(device=args.device, out=args.out, work=args.work, samples=args.samples,
                   unit=tuple(args.unit or ()), seeds=tuple(args.seeds or (1,)),
                   scene_seeds=tuple(args.scene_seeds or ()), jobs=args.jobs,
                   job_timeout=args.job_timeout, scheduler=args.scheduler)


def run_fpga(args):
    return fpga_run(config_from_args(args), fpga_run_of(args))


def run_timing(args):
    return timing_report(args.out, args.doc)


def run_integration(args):
    return integration_report(args.scene, args.out, args.doc, args.name)


def add_table1(kinds):
    t = kinds.add_parser("table1", help="recount Lee et al. Table 1 -> docs/table1.md")
    t.add_argument("--out", type=Path, default=Path("docs/table1.md"),
                   help="the page written (default: docs/table1.md)")
    t.add_argument("--work", type=Path, default=Path("build/report/table1"),
                   help="the netlists counted (default: build/report/table1)")
    t.add_argument("--samples", type=int, default=100_000,
                   help="random inputs of each design's error column (default: 10^5)")
    t.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="local worker processes, one Yosys count each at a time (default: the "
                        "number of cores; ignored with --scheduler)")
    add_job_arguments(t)
    add_config_flags(t, ("angle_bits", "frac_bits", "specular"))
    t.set_defaults(func=run_table1)


def _seeds(text):
    try:
        seeds = [int(s) for s in text.split(",")]
    except ValueError:
        seeds = []
    if not seeds or any(s < 1 for s in seeds):
        raise argparse.ArgumentTypeError(f"must be comma-separated positive integers, got {text!r}")
    return seeds


def add_fpga(kinds):
    f = kinds.add_parser("fpga", help="ECP5 place and route of every design -> docs/report.md")
    f.add_argument("--device", default="LFE5U-85F", help="LFE5U-25F, LFE5U-45F or LFE5U-85F")
    f.add_argument("--unit", action="append", help="place only this unit (repeatable)")
    f.add_argument("--out", type=Path, default=Path("docs/report.md"),
                   help="the page written (default: docs/report.md)")
    f.add_argument("--work", type=Path, default=Path("build/fpga_cache"),
                   help="placements, cached by Verilog digest (shared with bench sweep --fpga; "
                        "default: build/fpga_cache)")
    f.add_argument("--samples", type=int, default=100_000,
                   help="random inputs of each design's error column (default: 10^5)")
    f.add_argument("--seeds", type=_seeds, default=[1],
                   help="nextpnr seeds, comma-separated (default 1); Fmax is their minimum")
    f.add_argument("--scene-seeds", type=_seeds, default=None,
                   help="nextpnr seeds of the rows with the 200 MHz goal: the scene pipelines "
                        "and the default method's pipeline (default: --seeds)")
    f.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="local worker processes, one placement each at a time (default: the "
                        "number of cores; ignored with --scheduler)")
    f.add_argument("--job-timeout", type=float, default=None, metavar="SECONDS",
                   help="a placement running longer fails with a timeout on its row (default: none)")
    add_job_arguments(f)
    add_config_flags(f, ("angle_bits", "frac_bits", "specular"))
    f.set_defaults(func=run_fpga)


def add_timing(kinds):
    t = kinds.add_parser("timing", help="WaveDrom handshake/stall/latency diagrams of the "
                                        "default pipeline -> docs/timing/")
    t.add_argument("--out", type=Path, default=Path("docs/timing"),
                   help="the diagrams' directory, WaveDrom JSON and SVG (default: docs/timing)")
    t.add_argument("--doc", type=Path, default=Path("docs/timing.md"),
                   help="the page whose Made-at record is rewritten (when it exists)")
    t.set_defaults(func=run_timing)


def add_integration(kinds):
    p = kinds.add_parser("integration", help="the generated parts of docs/integration.md",
                       description="Emit the scene's pipeline with named ports (--load port --name "
                                   f"{NAME} --ports named) and "
                                   "write docs/integration.md's generated blocks from its "
                                   "sidecar: block diagram, port table, latency, memory images, "
                                   "instantiation template.")
    p.add_argument("--scene", default="default", metavar="FILE|NAME",
                   help="scene whose pipeline the page describes (default: default)")
    p.add_argument("--out", type=Path, default=Path("build/integration"),
                   help="where the pipeline is emitted (default: build/integration)")
    p.add_argument("--doc", type=Path, default=DOC, help=f"the page (default: {DOC})")
    p.add_argument("--name", default=NAME, metavar="PREFIX",
                   help=f"the --name the page's pipeline is emitted under (default: {NAME})")
    p.set_defaults(func=run_integration)


# kind -> the function adding its sub-parser, in `--help` order.
REPORTS = {
    "table1": add_table1,
    "fpga": add_fpga,
    "timing": add_timing,
    "integration": add_integration,
}


def add_parser(sub):
    p = sub.add_parser("report", help="Table 1 recount and FPGA cost reports",
                       description="Reports: `table1` (Lee et al. Table 1 recounted from Yosys "
                                   "netlists, docs/table1.md) and `fpga` (ECP5 LUT/FF/DSP/BRAM/Fmax, "
                                   "docs/report.md), `timing` (docs/timing.md) and `integration` "
                                   "(docs/integration.md's generated blocks).")
    kinds = p.add_subparsers(dest="kind", metavar="KIND")
    kinds.required = True
    for add in REPORTS.values():
        add(kinds)
    quiet_commands(kinds, "build/report")     # Yosys', nextpnr's output to build/report/KIND.log
